# Source this file (bash) for the TruOrtho development environment:
#
#   source scripts/env.sh
#
# It puts .venv/bin first on PATH, runs Qt headless, points QGIS at the
# isolated profile in .venv/qgis-config and at .venv/qgis-plugins (where
# `truortho` links to this repository), and makes the venv's pip packages
# (numba, opencv, ...) visible to the Python that qgis_process.bin embeds.
# Run scripts/setup.sh first.

TRUORTHO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export TRUORTHO_ROOT
export TRUORTHO_VENV="$TRUORTHO_ROOT/.venv"

export QT_QPA_PLATFORM="${QT_QPA_PLATFORM:-offscreen}"
export QGIS_PLUGINPATH="$TRUORTHO_VENV/qgis-plugins"
export QGIS_CUSTOM_CONFIG_PATH="$TRUORTHO_VENV/qgis-config"

# Quiet Qt's "XDG_RUNTIME_DIR not set" warning.
if [[ -z "${XDG_RUNTIME_DIR:-}" ]]; then
    export XDG_RUNTIME_DIR="/tmp/runtime-$(id -u)"
    mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fi

for _site in "$TRUORTHO_VENV"/lib/python3*/site-packages; do
    if [[ -d "$_site" && ":${PYTHONPATH:-}:" != *":$_site:"* ]]; then
        export PYTHONPATH="$_site${PYTHONPATH:+:$PYTHONPATH}"
    fi
done
unset _site

if [[ ":$PATH:" != *":$TRUORTHO_VENV/bin:"* ]]; then
    export PATH="$TRUORTHO_VENV/bin:$PATH"
fi
