"""DSM post-processing: outlier removal, edge sharpening, hole filling, smoothing.

A package: :mod:`.config` (:class:`DsmFilterConfig`, :class:`FilterStats`), :mod:`.kernels`
(numba), :mod:`.stages` (the stages on one window), :mod:`.holes` (hole widths, gaps, Laplace
filling), :mod:`.tiles` (union-find over tiles, readers, the two passes' tile tasks) and
:mod:`.pipeline` (:func:`filter_dsm`, :func:`filter_dsm_array`). Every name is importable from
here.

:func:`filter_dsm` (files, by tiles) and :func:`filter_dsm_array` (in memory)
run these stages on a raw DSM (e.g. OSGM's), optionally with its confidence
raster (float in [0, 1]):

1. **Confidence**: cells with ``c < min_confidence`` are removed.
2. **Edge sharpening** (optional, on by default): a cell lying between the two
   levels (20th and 80th percentiles) of its 5 x 5 window, when these differ
   by more than ``max(step, 2 res tan 70 deg)`` (a blurred wall, never a roof
   slope), is snapped to the nearer level.
3. **Outliers** (median-based). For every cell, the median of its valid
   neighbours in a ``w x w`` window (weighted by confidence when given) and
   its *support*, the number of neighbours within ``t`` of its own height,
   are computed; the cell is removed when it departs from the median by more
   than ``t`` **and** has fewer than ``min_support`` supporters. The support
   test keeps true edges and corners of roofs (a roof corner cell has many
   supporters on its roof although the median lies on the ground) and thin
   structures one cell wide, and removes isolated spikes and pits and small
   blobs; a second pass with a window twice as wide and three times the
   support removes blobs up to about 3 x 3 cells. With a confidence raster,
   ``t`` is scaled by ``0.5 + 0.5 c`` (a less confident cell must agree better).
   Islands (valid components of fewer than ``3 min_support`` cells alone in
   nodata, which the median tests cannot judge: they are their own median and
   support) are removed when their median departs by more than ``t`` from the
   valid cells within 7 cells around them (:func:`_islands`).
4. **Holes** (connected nodata regions, 4-connected, after the above) whose
   width (twice the largest distance of a hole cell to valid data, minus one
   cell) is at most ``max_hole`` metres are filled by harmonic (Laplace)
   interpolation from their boundary cells, solved exactly as a sparse linear
   system. Boundary cells more than ``step`` above the lowest boundary cell
   within ``max_hole`` (the top of a wall beside an occlusion hole, where
   matching fails at the foot of walls) are not used (zero flux), so such
   holes are filled with the ground and walls stay sharp. Of a larger hole
   (in particular the nodata around the data, to which every gap open to the
   outside belongs), the cells inside the morphological closing of the valid
   cells by a disc of diameter ``max_hole`` and reach farther than a quarter of
   ``max_hole`` from its wide part (not the rounded-off corners of a wide hole)
   are filled the same way (zero flux towards the rest of the hole): bays and
   gaps narrower than ``max_hole`` that open onto a wide hole or onto the
   outside, which the width test alone
   left empty (on a block whose vegetated border lost its low-confidence cells
   most gaps are such open bays); beyond the raster's border counts as
   nodata, so nothing is extrapolated outward. The rest stays nodata and is
   counted in the statistics.
5. **Smoothing** (optional, edge-preserving): every cell is replaced by the
   value at its centre of the least-squares plane through the neighbours
   within ``smooth_radius`` cells whose heights are within
   ``smooth_tolerance`` of its own, when that plane fits them to RMS
   ``smooth_tolerance / 2`` (a planar patch: flat or pitched roof, street);
   steps, never within tolerance of both sides, stay sharp.

Tiling: each tile is computed on its core plus a margin (windows, hole widths,
interpolation reach, the closing's reach of twice its radius, smoothing
radius). Hole decisions are global: a first pass labels the holes of every
tile core and finds whether each contains a cell farther than ``max_hole / 2``
from valid data, labels are merged across tile borders (union-find), and the
second pass fills the holes whose merged component is small enough and the
narrow gaps of the others. Results do not depend on the tile size, except
for interpolated values of holes longer than the margin (truncated there,
with differences far below the noise for enclosed holes; a long bay open onto
a wide hole is a zero-flux boundary where a window cuts it, and on the demo
block tiles of 64 cells changed 773 of 21,607 filled cells by more than
1 cm against tiles of 1024).

Parallel execution
------------------
Each pass is a :meth:`~truortho.core.parallel.Executor.map_tiles` call over
the tiles (:func:`filter_pass1_task`, :func:`filter_pass2_task`; the tiles of
a pass are independent given the merge), so :func:`filter_dsm` runs them in
this process (default), on a local Dask cluster or on a Dask scheduler
(``executor``); the files are read by every task itself through a
:class:`FileReader`. The union-find merge, the statistics (summed from the
task results, in tile order) and the writing of the cores stay in this
process; pass 2 is submitted in batches of at most :data:`WRITE_BATCH_BYTES`
(256 MiB) of float32 cores (64 tiles of 1024 x 1024 cells, a raster of
8192 x 8192 cells, per call) so that this process never holds more of the
output than that. The tile logic is the same everywhere, so the result is
bit-identical whichever executor runs it. With ``cache_dir``, finished tile
tasks are kept in a content-addressed :class:`~truortho.core.parallel.TileCache`
keyed by :data:`CACHE_VERSION`, the input files (path, size, mtime), the
band, the grid, every :class:`DsmFilterConfig` field, the tile's windows and,
in pass 2, which of its holes the merge declared small.

Memory of one task (:func:`task_memory`, passed as ``memory=`` to the
executor): about :data:`TASK_BYTES_PER_CELL` = 96 bytes per cell of the outer
window (core + margin): up to eight float64 arrays live at once (heights,
confidence, the cleaned heights, the sharpened copy, the hole widths or the
filled and re-solved copies, the smoothed copy, the solver's int64 cell index)
plus about 32 bytes of int32 labels and boolean masks. The margin is
``outlier_margin + max_hole / 2 res + 2`` cells in pass 1 and up to
``outlier_margin + 2.5 max_hole / res + smooth_radius + 7`` in pass 2; with
the defaults (tile 1024, max_hole 10 m) at 0.25 m, pass 1 tasks have
1100 x 1100 cells (116 MB) and pass 2 tasks at most 1274 x 1274 (156 MB). The
sparse Laplace solve of a tile's small holes comes on top (proportional to the
hole cells, a small share of the tile).
"""

from __future__ import annotations

from .config import CONFIDENCE_HALF, ISLAND_RING, DsmFilterConfig, FilterStats
from .holes import _FOUR, _solve
from .kernels import _confidence_pass, _outlier_pass, _plane_smooth, _sharpen_pass
from .pipeline import WRITE_BATCH_BYTES, filter_dsm, filter_dsm_array
from .stages import _islands
from .tiles import (
    CACHE_VERSION,
    GAP_REACH,
    TASK_BYTES_PER_CELL,
    ArrayReader,
    FileReader,
    FilterContext,
    Pass1Task,
    Pass2Task,
    filter_pass1_task,
    filter_pass2_task,
    task_memory,
)

__all__ = [
    "CACHE_VERSION",
    "CONFIDENCE_HALF",
    "GAP_REACH",
    "ISLAND_RING",
    "TASK_BYTES_PER_CELL",
    "WRITE_BATCH_BYTES",
    "ArrayReader",
    "DsmFilterConfig",
    "FileReader",
    "FilterContext",
    "FilterStats",
    "Pass1Task",
    "Pass2Task",
    "_FOUR",
    "_confidence_pass",
    "_islands",
    "_outlier_pass",
    "_plane_smooth",
    "_sharpen_pass",
    "_solve",
    "filter_dsm",
    "filter_dsm_array",
    "filter_pass1_task",
    "filter_pass2_task",
    "task_memory",
]
