"""Semi-global matching machinery shared by OSGM and the rectified-stereo matcher.

The pipeline on a cost volume ``(rows, cols, nd)``:

1. :func:`multi_image_cost` per level (an OSGM Z plane, or a disparity):
   slices of n images resampled onto one grid -> ``uint16`` cost in
   ``[0, COST_MAX]`` and the number of valid views (:func:`window_ncc` is its
   pairwise NCC);
2. :func:`aggregate` along 8 or 16 paths with penalties ``P1``/``P2``
   (per-cell ``P2`` from :func:`adaptive_p2`; per-cell level offsets ``z0``
   for variable search ranges) -> ``S`` (``uint16``);
3. :func:`select`: winner-take-all, equiangular sub-level fit, uniqueness,
   confidence; :func:`median_filter` (NaN-aware).

:func:`match_rectified` runs exactly these kernels in disparity space.
Cost units, the valid-sample rule and the integer bounds are documented in
:mod:`.cost` and :mod:`.aggregation`.
"""

from .aggregation import DEFAULT_P1, DEFAULT_P2, P2_MAX, TREND_NONE, adaptive_p2, aggregate
from .cost import (
    COST_MAX,
    DEFAULT_MEASURE,
    DEFAULT_MIN_VALID,
    DEFAULT_RADIUS,
    MEASURES,
    multi_image_cost,
    window_ncc,
)
from .rectified import disparity_costs, match_rectified
from .selection import DEFAULT_UNIQUENESS, median_filter, select, valid_cells

__all__ = [
    "TREND_NONE",
    "COST_MAX",
    "DEFAULT_MEASURE",
    "DEFAULT_MIN_VALID",
    "DEFAULT_P1",
    "DEFAULT_P2",
    "DEFAULT_RADIUS",
    "DEFAULT_UNIQUENESS",
    "MEASURES",
    "P2_MAX",
    "adaptive_p2",
    "aggregate",
    "disparity_costs",
    "match_rectified",
    "median_filter",
    "multi_image_cost",
    "select",
    "valid_cells",
    "window_ncc",
]
