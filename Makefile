# TruOrtho developer entry points. Every target installs what it needs first.
#   make demo   install everything, run the main job on the bundled sample
#   make test   install everything, lint, run all tests
SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := test

VENV := .venv
PY := $(VENV)/bin/python
ENV := source scripts/env.sh &&

.PHONY: setup test lint pytest demo bench zip

setup:
	bash scripts/setup.sh

test: setup lint pytest

lint: setup
	$(ENV) $(PY) -m ruff check .
	$(ENV) $(PY) -m mypy

# -P: never put the current directory (the repo root) on sys.path, or our
# processing/ would shadow QGIS's `processing`.
# Extra pytest arguments: make pytest PYTEST_ARGS="-k provider -x"
pytest: setup
	$(ENV) QT_QPA_PLATFORM=offscreen $(PY) -P -m pytest --import-mode=importlib -p no:cacheprovider $(PYTEST_ARGS)

demo: setup
	bash scripts/demo.sh

bench: setup
	@if $(PY) -c 'import importlib.util as u, sys; sys.exit(u.find_spec("truortho.bench") is None)' 2>/dev/null; then \
		$(ENV) $(PY) -P -m truortho.bench; \
	else \
		echo "bench: truortho.bench does not exist yet"; \
	fi

zip:
	@echo "zip: TODO (plugin zip for plugins.qgis.org)"; exit 1
