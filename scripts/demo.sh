#!/usr/bin/env bash
# The main job on the bundled sample, run through qgis_process as a user would:
#
#   1. truortho:importgcps  sample/copr/gcp_list.txt -> GCP layer + observation table
#                           (gcp06 and gcp08 are check points: they never enter the adjustment)
#   2. truortho:pipeline    17 photos + GCPs -> orientation, OSGM DSM, point cloud, mesh,
#                           true orthophoto, occlusion mask, seamlines and the HTML report
#
# TRUORTHO_DEMO_OUT overrides the output folder, TRUORTHO_DEMO_RES the resolution (metres).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SAMPLE="$ROOT/sample/copr"
OUT="${TRUORTHO_DEMO_OUT:-$ROOT/build/demo}"
RES="${TRUORTHO_DEMO_RES:-0.1}"
QP="$ROOT/scripts/qgis_process"
rm -rf "$OUT"
mkdir -p "$OUT"
start=$(date +%s)

echo "demo: 1/2 importing GCPs from $SAMPLE/gcp_list.txt (check points gcp06, gcp08)"
"$QP" run truortho:importgcps -- INPUT="$SAMPLE/gcp_list.txt" CHECK_POINTS="gcp06,gcp08" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" >"$OUT/importgcps.log"

echo "demo: 2/2 photos -> true orthophoto (truortho:pipeline at $RES m; several minutes)"
/usr/bin/time -v "$QP" run truortho:pipeline -- IMAGES="$SAMPLE/images" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" RESOLUTION="$RES" \
    OUTPUT_FOLDER="$OUT/products" >"$OUT/pipeline.log" 2>"$OUT/pipeline.time" || {
    cat "$OUT/pipeline.log" "$OUT/pipeline.time" >&2
    exit 1
}
peak=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$OUT/pipeline.time")

echo "demo: done in $(($(date +%s) - start)) s (pipeline peak memory ${peak} MB); products in $OUT/products:"
(cd "$OUT/products" && find . -maxdepth 1 -type f ! -name '*.log' | sort | sed 's/^\.\//  /')
echo "open $OUT/products/report.html for the quality report"
