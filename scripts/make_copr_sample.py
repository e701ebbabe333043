"""Build the bundled real sample ``sample/copr`` from the copr data set (deterministic).

    .venv/bin/python -P scripts/make_copr_sample.py [--source DIR]

Source: ``$TRUORTHO_DATA/copr`` (default ``../shared/data/copr``), itself a 2x downscale of
OpenDroneMap's ``odm_data_copr`` (CC BY-SA 4.0, Michele M. Tobias & Alex Mandel). The sample
keeps the images listed in ``IMAGES`` (two overlapping strips over five of the ten targets),
downscales them by exactly 2 again (Lanczos, pixel-centre aligned: ``x' = (x + 0.5) / 2 - 0.5``),
saves them as JPEG quality 90 with their EXIF (image-size and focal-plane-resolution tags
updated so that the sensor size derived from EXIF is unchanged), and rewrites ``gcp_list.txt``
for the kept images with the same pixel mapping. The licence and attribution go with it
(``sample/copr/README.md``): CC BY-SA 4.0 requires that modified versions keep the licence.
"""

from __future__ import annotations

import argparse
import os
import sys
from fractions import Fraction
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_SOURCE = Path(os.environ.get("TRUORTHO_DATA", ROOT.parent / "shared" / "data")) / "copr"
OUT = ROOT / "sample" / "copr"

#: Two strips of the flight over targets gcp05 ... gcp09 (file names of the source).
IMAGES = tuple(f"IMG_{n:04d}.jpg" for n in range(64, 113, 3))
SCALE = 0.5
QUALITY = 90

# EXIF tags (Exif IFD 0x8769)
EXIF_IFD = 0x8769
PIXEL_X, PIXEL_Y = 0xA002, 0xA003
FOCAL_PLANE_X, FOCAL_PLANE_Y = 0xA20E, 0xA20F

README = """# copr sample — Coal Oil Point Reserve (Goleta, CA), 2009

A small real block for TruOrtho's main job (`make demo`): {n} nadir photos of a dune area with
5 ground targets, a subset of OpenDroneMap's `odm_data_copr`.

## Licence and attribution

**CC BY-SA 4.0** (https://creativecommons.org/licenses/by-sa/4.0/). Photos and target coordinates:
2009-2015 Michele M. Tobias & Alex Mandel (contact: mmtobias [at] ucdavis.edu); "Location: Coal
Oil Point Reserve, Goleta, CA / Year: 2009 / Credits: Michele M. Tobias & Alex Mandel".
Source repository: https://github.com/OpenDroneMap/odm_data_copr (commit
`97cd18478ca1885f5713a11bf98d4bf96308b399`). These modified files are distributed under the
same licence, CC BY-SA 4.0 (the rest of TruOrtho is GPL-2.0-or-later; this folder is data, not code).

## Changes from the source

- Images: {names}; downscaled by 4 from the original 4272x2848 (by 2 twice, Lanczos, pixel-centre
  aligned) to {w}x{h}; JPEG quality {q}; EXIF kept, with `PixelXDimension`/`PixelYDimension` set to
  the new size and `FocalPlaneXResolution`/`FocalPlaneYResolution` scaled alike, so the sensor size
  derived from EXIF stays 22.3 x 14.8 mm.
- `gcp_list.txt`: the observations on these images, pixel coordinates mapped with
  `x' = (x + 0.5) / 2 - 0.5` from the 2136x1424 frame (pixel centres as in TruOrtho); coordinates
  (UTM 11N, WGS84) unchanged. **Heights are all 0**: the control is plan-only (averaged hand-held
  GNSS positions), so product heights are relative to a horizontal plane through the targets.

Built by `scripts/make_copr_sample.py`.
"""


def _scale_rational(value, factor: float):
    if isinstance(value, tuple):
        num, den = value
        return (int(round(num * factor)), int(den))
    fr = Fraction(float(value) * factor).limit_denominator(1_000_000)
    from PIL.TiffImagePlugin import IFDRational

    return IFDRational(fr.numerator, fr.denominator)


def convert_image(src: Path, dst: Path) -> tuple[int, int]:
    from PIL import Image

    with Image.open(src) as im:
        im.load()
        exif = im.getexif()
        w, h = im.size
        nw, nh = int(round(w * SCALE)), int(round(h * SCALE))
        small = im.resize((nw, nh), Image.LANCZOS)
    ifd = exif.get_ifd(EXIF_IFD)
    ifd[PIXEL_X] = nw
    ifd[PIXEL_Y] = nh
    for tag in (FOCAL_PLANE_X, FOCAL_PLANE_Y):
        if tag in ifd:
            ifd[tag] = _scale_rational(ifd[tag], SCALE)
    tmp = dst.with_name(f".{dst.name}.tmp")
    small.save(tmp, "JPEG", quality=QUALITY, optimize=True, exif=exif.tobytes())
    os.replace(tmp, dst)
    return nw, nh


def convert_gcps(src: Path, dst: Path, keep: set[str]) -> int:
    lines = src.read_text(encoding="utf-8").splitlines()
    out = [lines[0].strip()]
    for line in lines[1:]:
        parts = line.split()
        if len(parts) < 6 or parts[5] not in keep:
            continue
        x = (float(parts[3]) + 0.5) * SCALE - 0.5
        y = (float(parts[4]) + 0.5) * SCALE - 0.5
        out.append("\t".join(parts[:3] + [f"{x:.2f}", f"{y:.2f}"] + parts[5:]))
    dst.write_text("\n".join(out) + "\n", encoding="utf-8")
    return len(out) - 1


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", default=str(DEFAULT_SOURCE), help="the copr data set folder")
    args = ap.parse_args(argv)
    src = Path(args.source)
    if not (src / "images").is_dir():
        print(f"make_copr_sample: {src}/images not found (set TRUORTHO_DATA)", file=sys.stderr)
        return 2
    (OUT / "images").mkdir(parents=True, exist_ok=True)
    for old in (OUT / "images").glob("*.jpg"):
        if old.name not in IMAGES:
            old.unlink()
    size = (0, 0)
    for name in IMAGES:
        size = convert_image(src / "images" / name, OUT / "images" / name)
    n_obs = convert_gcps(src / "gcp_list.txt", OUT / "gcp_list.txt", set(IMAGES))
    names = f"`{IMAGES[0]}` ... `{IMAGES[-1]}` (every third photo of the flight, {len(IMAGES)} files)"
    (OUT / "README.md").write_text(
        README.format(n=len(IMAGES), names=names, w=size[0], h=size[1], q=QUALITY), encoding="utf-8"
    )
    total = sum(p.stat().st_size for p in OUT.rglob("*") if p.is_file())
    print(f"wrote {OUT}: {len(IMAGES)} images {size[0]}x{size[1]}, {n_obs} GCP observations, "
          f"{total / 1e6:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
