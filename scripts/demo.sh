#!/usr/bin/env bash
# The main job on the bundled sample, run through qgis_process as a user would.
#
# Today's chain (later issues extend it to dense matching and the true orthophoto):
#   1. truortho:importgcps        sample/synthetic/gcp_list.txt -> GCP layer + observation table
#   2. truortho:importorientation COLMAP model + the GCP layers -> orientation JSON, cameras, footprints
#   3. truortho:exportorientation orientation JSON -> Orthority OPK CSV + interior file
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SAMPLE="$ROOT/sample/synthetic"
OUT="${TRUORTHO_DEMO_OUT:-$ROOT/build/demo}"
QP="$ROOT/scripts/qgis_process"
rm -rf "$OUT"
mkdir -p "$OUT"
start=$(date +%s)

echo "demo: 1/3 importing GCPs from $SAMPLE/gcp_list.txt"
"$QP" run truortho:importgcps -- INPUT="$SAMPLE/gcp_list.txt" CHECK_POINTS="gcp_07,gcp_08" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" >"$OUT/importgcps.log"

echo "demo: 2/3 importing the COLMAP orientation with its ground control"
"$QP" run truortho:importorientation -- INPUT="$SAMPLE/colmap/images.txt" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" \
    OUTPUT="$OUT/orientation.json" CAMERAS="$OUT/cameras.gpkg" FOOTPRINTS="$OUT/footprints.gpkg" \
    >"$OUT/importorientation.log"

echo "demo: 3/3 exporting it as Orthority OPK files"
"$QP" run truortho:exportorientation -- INPUT="$OUT/orientation.json" FORMAT=1 OUTPUT="$OUT/opk" \
    >"$OUT/exportorientation.log"

echo "demo: done in $(($(date +%s) - start)) s; products in $OUT:"
(cd "$OUT" && find . -type f ! -name '*.log' | sort | sed 's/^\.\//  /')
