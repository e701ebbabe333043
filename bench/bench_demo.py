"""What `make demo` costs a new user: a first run with empty caches, then a second run.

    make bench BENCH=demo

Runs ``scripts/demo.sh`` twice with a fresh, temporary ``TRUORTHO_CACHE_DIR`` (so your own
caches are neither used nor touched): the first run compiles the numba kernels and extracts the
SIFT features into it, the second reuses both. Prints wall time and peak memory of each run (as
``demo.sh`` reports them) and the pipeline's stages from the products' ``report.json``. The peer of
the first run is the second: their ratio is what the caches save.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run_demo(out: str, cache: str) -> dict:
    env = dict(os.environ, TRUORTHO_CACHE_DIR=cache, TRUORTHO_DEMO_OUT=out)
    env.pop("NUMBA_CACHE_DIR", None)  # the kernels' cache follows TRUORTHO_CACHE_DIR
    t0 = time.perf_counter()
    proc = subprocess.run(
        ["bash", os.path.join(ROOT, "scripts", "demo.sh")], env=env, capture_output=True, text=True
    )
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-4000:] + proc.stderr[-4000:])
        raise SystemExit(f"demo.sh failed ({proc.returncode})")
    m = re.search(r"done in (\d+) s wall time, pipeline peak memory (\d+) MB", proc.stdout)
    caches = re.search(r"numba kernel cache (\S+).*image feature cache (\S+)", proc.stdout)
    report = json.load(open(os.path.join(out, "products", "report.json"), encoding="utf-8"))
    stages = next((t for t in report.get("tables", []) if t.get("title") == "Stages"), None)
    return {
        "wall_s": float(m.group(1)) if m else wall,
        "peak_mb": float(m.group(2)) if m else float("nan"),
        "kernels": caches.group(1) if caches else "?",
        "features": caches.group(2).rstrip(";") if caches else "?",
        "stages": [(r[0], float(r[1])) for r in stages["rows"]] if stages else [],
        "summary": report.get("summary", {}),
    }


def main() -> int:
    work = tempfile.mkdtemp(prefix="bench-demo-")
    try:
        cache = os.path.join(work, "cache")
        runs = [run_demo(os.path.join(work, f"demo{k}"), cache) for k in (1, 2)]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    names = [s for s, _ in runs[0]["stages"]]
    print(
        "| run | caches (kernels, features) | wall [s] | peak [MB] | "
        + " | ".join(f"{s} [s]" for s in names)
        + " |"
    )
    print("|---|---|---|---|" + "---|" * len(names))
    for label, r in zip(("first (empty caches)", "second"), runs, strict=True):
        st = dict(r["stages"])
        cells = " | ".join(f"{st.get(s, float('nan')):.1f}" for s in names)
        caches = f"{r['kernels']}, {r['features']}"
        print(f"| {label} | {caches} | {r['wall_s']:.0f} | {r['peak_mb']:.0f} | {cells} |")
    print(f"\nsecond / first run: wall time x{runs[1]['wall_s'] / runs[0]['wall_s']:.2f}, "
          f"peak memory x{runs[1]['peak_mb'] / runs[0]['peak_mb']:.2f}")  # fmt: skip
    s = runs[1]["summary"]
    keys = (
        "images oriented",
        "sigma0 [px]",
        "check points RMSE X / Y / Z / 3D [m]",
        "true ortho coverage [%]",
    )
    print("products: " + "; ".join(f"{k} {s[k]}" for k in keys if k in s))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, HERE)
    from _docs import run_main

    sys.exit(run_main(main, "demo", "The demo: first and second run", peers=()))
