#!/usr/bin/env bash
# Install everything TruOrtho needs on Debian 12, idempotently.
#
#   1. Debian packages (QGIS 3.22, GDAL and the GDAL-linked Python packages),
#      only those missing; `apt-get update` runs only when something is missing.
#   2. .venv made by Debian's /usr/bin/python3 with --system-site-packages, and
#      the pinned pip packages of requirements.txt under constraints.txt
#      (skipped when a stamp keyed by their hash is current).
#   3. .venv/qgis-plugins/truortho -> repository root, and a .pth file so that
#      `import truortho` works in the venv python.
#   4. An isolated QGIS profile (.venv/qgis-config) with the plugin enabled.
#   5. i18n/*.qm compiled from i18n/*.ts (when a .ts is newer) for the plugin in the tree.
#
# Re-running it when nothing changed does nothing and takes a few seconds.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

log() { printf 'setup: %s\n' "$*" >&2; }

APT_PACKAGES=(
    qgis python3-qgis qgis-providers
    gdal-bin python3-gdal
    python3-venv python3-rasterio python3-pyproj python3-shapely
    python3-scipy python3-matplotlib python3-pil
    xvfb qttools5-dev-tools time
)

# --- 1. Debian packages ------------------------------------------------------
missing=()
for pkg in "${APT_PACKAGES[@]}"; do
    status="$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)"
    [[ "$status" == "install ok installed" ]] || missing+=("$pkg")
done
if ((${#missing[@]})); then
    log "installing Debian packages: ${missing[*]}"
    SUDO=()
    if [[ "$(id -u)" != 0 ]]; then SUDO=(sudo); fi
    export DEBIAN_FRONTEND=noninteractive
    "${SUDO[@]}" apt-get update -q
    "${SUDO[@]}" apt-get install -y -q "${missing[@]}"
fi

# --- 2. virtual environment --------------------------------------------------
PY=/usr/bin/python3   # the Python QGIS embeds; never the pyenv python on PATH
VENV="$ROOT/.venv"
if [[ ! -x "$VENV/bin/python" ]] || ! "$VENV/bin/python" -c 'import qgis.core' 2>/dev/null; then
    log "creating $VENV"
    rm -rf "$VENV"
    "$PY" -m venv --system-site-packages "$VENV"
fi
# pyproj looks for PROJ data under sys.prefix/share/proj: point the venv at Debian's.
mkdir -p "$VENV/share"
[[ -e "$VENV/share/proj" ]] || ln -s /usr/share/proj "$VENV/share/proj"
SITE="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"

STAMP="$VENV/.requirements.sha256"
want="$(cat requirements.txt constraints.txt <("$PY" -VV) | sha256sum | cut -d' ' -f1)"
if [[ "$(cat "$STAMP" 2>/dev/null || true)" != "$want" ]]; then
    log "pip installing requirements.txt (constraints.txt)"
    PIP_DISABLE_PIP_VERSION_CHECK=1 "$VENV/bin/python" -m pip install -q \
        -r requirements.txt -c constraints.txt
    # Fail loudly if pip replaced a Debian package it must not touch.
    "$VENV/bin/python" - <<'EOF'
import numpy, rasterio, pyproj
from osgeo import gdal
bad = [m.__name__ for m in (numpy, rasterio, pyproj) if not m.__file__.startswith("/usr/lib/python3/")]
if bad or not numpy.__version__.startswith("1."):
    raise SystemExit(f"setup: pip shadowed Debian packages {bad} (numpy {numpy.__version__})")
if rasterio.__gdal_version__ != gdal.__version__:
    raise SystemExit(f"setup: rasterio GDAL {rasterio.__gdal_version__} != GDAL {gdal.__version__}")
EOF
    echo "$want" >"$STAMP"
fi

# --- 3. plugin folder and import path ----------------------------------------
mkdir -p "$VENV/qgis-plugins"
if [[ "$(readlink "$VENV/qgis-plugins/truortho" 2>/dev/null || true)" != "$ROOT" ]]; then
    ln -sfn "$ROOT" "$VENV/qgis-plugins/truortho"
fi
pth="$SITE/truortho-dev.pth"
if [[ "$(cat "$pth" 2>/dev/null || true)" != "$VENV/qgis-plugins" ]]; then
    echo "$VENV/qgis-plugins" >"$pth"
fi

# --- 4. isolated QGIS profile with the plugin enabled ------------------------
# shellcheck source=env.sh
source "$ROOT/scripts/env.sh"
ini="$QGIS_CUSTOM_CONFIG_PATH/profiles/default/QGIS/QGIS3.ini"
if ! grep -qs '^truortho=true' "$ini"; then
    log "enabling the plugin in $QGIS_CUSTOM_CONFIG_PATH"
    mkdir -p "$QGIS_CUSTOM_CONFIG_PATH"
    qgis_process.bin plugins enable truortho >/dev/null 2>"$VENV/qgis-enable.log" || {
        cat "$VENV/qgis-enable.log" >&2
        exit 1
    }
    grep -qs '^truortho=true' "$ini" || { log "plugin not enabled in $ini"; exit 1; }
fi

# --- 5. translations for the plugin running from this tree -------------------
# i18n/*.ts -> i18n/*.qm (build products, git-ignored) when the .ts is newer than its .qm.
LRELEASE=/usr/lib/qt5/bin/lrelease
[[ -x "$LRELEASE" ]] || LRELEASE="$(command -v lrelease || command -v lrelease-qt5 || true)"
for ts in "$ROOT"/i18n/*.ts; do
    [[ -e "$ts" ]] || continue
    qm="${ts%.ts}.qm"
    [[ -e "$qm" && ! "$ts" -nt "$qm" ]] && continue
    if [[ -z "$LRELEASE" ]]; then log "lrelease not found: $(basename "$ts") not compiled"; continue; fi
    "$LRELEASE" -silent "$ts" -qm "$qm"
done

log "ok ($(cd "$ROOT" && "$VENV/bin/python" -c 'import truortho, sys; print(truortho.__file__)'))"
