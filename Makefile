# TruOrtho developer entry points. Every target installs what it needs first.
#   make demo   install everything, run the main job on the bundled sample
#   make test   install everything, lint, run all tests
SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := test

VENV := .venv
PY := $(VENV)/bin/python
ENV := source scripts/env.sh &&

.PHONY: setup test lint pytest demo bench acceptance acceptance-ablation acceptance-real acceptance-fountain acceptance-colours zip docs

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

# Benchmarks (not tests): each bench/bench_*.py prints its numbers and ratios against a peer
# (pycolmap, OpenCV, Orthority) measured in the same run. make bench BENCH=bundle runs one.
# The scale bench (hours at its defaults: 50 to 400 photos of 12 MP) runs only when named:
# make bench BENCH=scale BENCH_ARGS="--sizes 25,50,100 --megapixels 3 --resolution 0.25 --write-docs"
# Each bench writes what it printed into its section of docs/benchmarks.md (BENCH_DOCS= to skip).
BENCH ?= *
BENCH_DOCS ?= --write-docs
bench: setup
	$(ENV) $(PY) -m pip install -q -r requirements-bench.txt -c constraints.txt
	@for f in bench/bench_$(BENCH).py; do \
	  case "$$f" in *bench_scale.py) [ "$(BENCH)" = scale ] || continue;; esac; \
	  echo "== $$f"; $(ENV) $(PY) -P $$f $(BENCH_ARGS) $(BENCH_DOCS) || exit 1; done

# Randomized acceptance battery (not a test; about half an hour on 2 cores): DSM and true ortho on 12
# synthetic cities drawn from wide ranges, against their truth and a pairwise OpenCV SGBM baseline.
# make acceptance ACCEPTANCE_ARGS="--only 3,7 --no-sgbm"; --write-docs updates docs/acceptance.md.
acceptance: setup
	$(ENV) $(PY) -P bench/acceptance.py $(ACCEPTANCE_ARGS)

# The battery's true-ortho goals against the images' own defects: the same scenes re-rendered without
# JPEG, noise and radiometric jitter (ACCEPTANCE_ARGS as above; about 10 minutes).
acceptance-ablation: setup
	$(ENV) $(PY) -P bench/acceptance_ablation.py $(ACCEPTANCE_ARGS)

# Colour models on held-out cells of the battery's scenes and of real blocks kept by a real-blocks run:
# make acceptance-colours COLOUR_ARGS="--real sample=DIR/sample/products --write-docs"
acceptance-colours: setup
	$(ENV) $(PY) -P bench/colour_models.py $(COLOUR_ARGS)

# Real photo blocks through the whole pipeline (no truth DSM): make acceptance-real REAL_ARGS="--blocks sample,brighton"
acceptance-real: setup
	$(ENV) $(PY) -P bench/real_blocks.py $(REAL_ARGS)

# fountain-P11 (close range, ground-truth cameras) through truortho:osgm with OBLIQUE=auto (about 2 minutes):
# make acceptance-fountain FOUNTAIN_ARGS="--write-docs"
acceptance-fountain: setup
	$(ENV) $(PY) -P bench/fountain.py $(FOUNTAIN_ARGS)

# docs/algorithms.md from the algorithms and their help (tests/qgis/test_docs.py checks it is fresh).
docs: setup
	$(ENV) $(PY) -P scripts/make_docs.py

# The installable plugin zip (truortho/ at its root; no tests, benchmarks or data beyond the demo sample).
zip: setup
	$(ENV) $(PY) -P scripts/build_zip.py --output dist
