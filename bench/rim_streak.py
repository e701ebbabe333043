"""Streak indices of a DSM with its valid area eroded by 0 to 8 cells: how much of them is the rim.

Not a test. ``source scripts/env.sh && python -P bench/rim_streak.py DSM.tif`` (for instance a
``dsm.tif`` kept by ``bench/real_blocks.py --keep DIR``). Prints the streak and grid streak indices
(:mod:`truortho.core.surface.quality`) of the DSM with its valid area eroded by 0, 1, 2, 4 and 8
cells, of white noise on the same valid area (the outline's own share), and of the largest square
of valid cells.
"""

import sys

import numpy as np
from scipy.ndimage import binary_erosion

from truortho.core.rasterio_io import read_raster
from truortho.core.surface.quality import grid_streak_index, streak_index

if len(sys.argv) != 2:
    sys.exit(__doc__)
path = sys.argv[1]
a, g, _ = read_raster(path)
f = np.isfinite(a)
for e in (0, 1, 2, 4, 8):
    m = binary_erosion(f, iterations=e) if e else f
    b = np.where(m, a, np.nan)
    si, gi = streak_index(b), grid_streak_index(b)
    print(f"eroded {e}: cells {m.sum()}, streak {si:.2f}, grid streak {gi:.2f}")
noise = np.random.default_rng(0).normal(0, 0.01, a.shape)
print(f"white noise on the same mask: {streak_index(np.where(f, noise, np.nan)):.2f}")


def largest_square(valid):
    """(side, row, col) of the largest all-valid square (dynamic programming over the cells)."""
    side = np.zeros(valid.shape, np.int32)
    best = (0, 0, 0)
    for r in range(valid.shape[0]):
        for c in range(valid.shape[1]):
            if valid[r, c]:
                up = 0 if r == 0 or c == 0 else min(side[r - 1, c], side[r, c - 1], side[r - 1, c - 1])
                side[r, c] = 1 + up
                if side[r, c] > best[0]:
                    best = (int(side[r, c]), r - side[r, c] + 1, c - side[r, c] + 1)
    return best


s, r, c = largest_square(f)
if s:
    cr = a[r : r + s, c : c + s]
    si, gi = streak_index(cr), grid_streak_index(cr)
    print(f"largest valid square {s}x{s}: streak {si:.2f}, grid streak {gi:.2f}")
