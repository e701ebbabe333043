#!/usr/bin/env bash
# The main job on the bundled sample, run through qgis_process as a user would:
#
#   1. truortho:importgcps  sample/copr/gcp_list.txt -> GCP layer + observation table
#                           (gcp06 and gcp08 are check points: they never enter the adjustment)
#   2. truortho:pipeline    17 photos + GCPs -> orientation, OSGM DSM, point cloud, mesh,
#                           true orthophoto, occlusion mask, seamlines and the HTML report
#
# TRUORTHO_DEMO_OUT overrides the output folder, TRUORTHO_DEMO_RES the resolution (metres).
# The stages and their progress are shown on the terminal (and kept in build/demo/pipeline.log);
# at the end: wall time, peak memory and whether the compiled-kernel (numba) and feature caches
# were cold or warm. The caches are in the per-user cache folder (TRUORTHO_CACHE_DIR moves it;
# a first run compiles the kernels, later runs reuse them).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SAMPLE="$ROOT/sample/copr"
OUT="${TRUORTHO_DEMO_OUT:-$ROOT/build/demo}"
RES="${TRUORTHO_DEMO_RES:-0.1}"
QP="$ROOT/scripts/qgis_process"
rm -rf "$OUT"
mkdir -p "$OUT"
start=$(date +%s)

# cache state before the run: number of compiled-kernel index files and cached feature files
cache_counts() {
    (cd "$ROOT" && source scripts/env.sh && "$TRUORTHO_VENV/bin/python" -P -c '
import os, sys
from truortho.core.cache import cache_dir
numba_dir = os.environ.get("NUMBA_CACHE_DIR") or str(cache_dir("numba"))
def count(d, ext):
    return sum(f.endswith(ext) for _, _, fs in os.walk(d) for f in fs)
print(count(numba_dir, ".nbi"), count(str(cache_dir("features")), ".npz"), numba_dir)
')
}
read -r nbi_before npz_before numba_dir <<<"$(cache_counts)"

# qgis_process prints the stage messages and a 0...10...100 progress bar on stdout: the log keeps all,
# the terminal shows every stage message but only about every tenth of a run of "k of n" messages
# (and the progress bar's digits and dots are dropped from the start of a message line).
show() {
    awk '
    /DeprecationWarning|setapi/ { next }
    {
        line = $0
        if (match(line, /^[0-9.]+[A-Za-z]/)) line = substr(line, RLENGTH)
        sub(/^[.]+/, "", line)
        if (match(line, /[0-9]+ of [0-9]+/)) {
            split(substr(line, RSTART, RLENGTH), kn, " of ")
            key = substr(line, 1, RSTART - 1)
            step = int(kn[2] / 10); if (step < 1) step = 1
            if (key == last && kn[1] % step != 0 && kn[1] != kn[2]) next
            last = key
        } else last = ""
        print line; fflush()
    }'
}

echo "demo: 1/2 importing GCPs from $SAMPLE/gcp_list.txt (check points gcp06, gcp08)"
"$QP" run truortho:importgcps -- INPUT="$SAMPLE/gcp_list.txt" CHECK_POINTS="gcp06,gcp08" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" >"$OUT/importgcps.log" 2>&1 || {
    cat "$OUT/importgcps.log" >&2
    exit 1
}

echo "demo: 2/2 photos -> true orthophoto (truortho:pipeline at $RES m; a few minutes)"
if ! /usr/bin/time -v -o "$OUT/pipeline.time" "$QP" run truortho:pipeline -- IMAGES="$SAMPLE/images" \
    GCPS="$OUT/gcps.gpkg" OBSERVATIONS="$OUT/gcp_observations.gpkg" RESOLUTION="$RES" \
    OUTPUT_FOLDER="$OUT/products" 2>&1 | tee "$OUT/pipeline.log" | show; then
    echo "demo: truortho:pipeline failed (log: $OUT/pipeline.log)" >&2
    exit 1
fi
wall=$(($(date +%s) - start))
peak=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2 / 1024}' "$OUT/pipeline.time")
read -r nbi_after npz_after _ <<<"$(cache_counts)"
if [[ "$nbi_before" -eq 0 ]]; then
    kernels="cold (no compiled kernels in $numba_dir: this run compiled $nbi_after)"
elif [[ "$nbi_after" -gt "$nbi_before" ]]; then
    kernels="partly warm ($nbi_before compiled kernels found, $((nbi_after - nbi_before)) compiled by this run)"
else
    kernels="warm ($nbi_before compiled kernels reused from $numba_dir)"
fi
if [[ "$npz_before" -eq 0 ]]; then features="cold"; else features="warm ($npz_before files)"; fi

echo
echo "demo: done in ${wall} s wall time, pipeline peak memory ${peak} MB"
echo "demo: numba kernel cache ${kernels}; image feature cache ${features}"
echo "demo: products in $OUT/products:"
(cd "$OUT/products" && find . -maxdepth 1 -type f ! -name '*.log' | sort | sed 's/^\.\//  /')
echo "open $OUT/products/report.html for the quality report"
