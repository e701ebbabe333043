#!/usr/bin/env bash
# The main job on the bundled sample (placeholder until the pipeline lands).
#
# For now it reports the environment through the real Processing algorithm,
# run by qgis_process exactly as a user would from a shell.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$ROOT/build/demo"
mkdir -p "$OUT"

echo "demo: TODO the main job (orientation -> dense matching -> true orthophoto) is not wired yet."
echo "demo: running truortho:environment -> $OUT/environment.json"
"$ROOT/scripts/qgis_process" run truortho:environment -- OUTPUT="$OUT/environment.json"
echo "demo: done"
cat "$OUT/environment.json"
