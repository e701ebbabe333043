"""Regenerate the bundled synthetic sample in sample/synthetic (deterministic).

The sample is the ground-truth orientation of the synthetic generator's
default scene exported as a COLMAP text model with georef.json, plus its GCP
list in ODM format: small text files that `make demo` imports.

    .venv/bin/python -P scripts/make_sample.py
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from truortho.core.exchange import write_orientation
from truortho.core.synthetic import SceneConfig, make_scene


def main() -> int:
    out = Path(__file__).resolve().parent.parent / "sample" / "synthetic"
    scene = make_scene(SceneConfig(image_size=(160, 120), focal_px=200.0, seed=0))
    with tempfile.TemporaryDirectory() as tmp:
        scene.write(tmp)
        out.mkdir(parents=True, exist_ok=True)
        write_orientation(scene.orientation, "colmap", out / "colmap")
        shutil.copy(Path(tmp) / "gcp_list.txt", out / "gcp_list.txt")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
