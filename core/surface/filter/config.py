"""Configuration and statistics of the DSM filter (:mod:`truortho.core.surface.filter`)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ...errors import InputError

#: half side of the window of the confidence pass (15 x 15 cells)
CONFIDENCE_HALF = 7


@dataclass
class DsmFilterConfig:
    """Parameters of :func:`filter_dsm` (lengths in metres, windows in cells).

    Attributes
    ----------
    outlier_threshold : float or None
        ``t``: largest departure from the neighbourhood median (metres) before a
        cell with little support is removed; None = 4 x the resolution.
    outlier_window : int
        Side of the median window, cells (odd, 3 to 15).
    min_support : int
        Neighbours within ``t`` that keep a cell although it departs from the median.
    min_confidence : float
        With a confidence raster: cells below it are removed (0 = none).
    confident : float
        With a confidence raster: cells below it are removed when they depart by more than
        ``t`` from the median of the cells at least this confident in their 15 x 15 window
        (0 = off).
    max_hole : float
        Largest width of a hole that is filled, metres (0 = no filling).
    step : float
        Height difference between two surfaces (a wall), metres: hole boundary cells
        more than ``step`` above nearby boundary cells are not interpolated from, and
        steps of more than ``max(step, 2 res tan 70 deg)`` are sharpened.
    sharpen : bool
        Snap the cells of blurred height steps to the nearer side (see the module docstring).
    smooth : bool
        Apply the edge-preserving plane smoothing.
    smooth_radius : int
        Radius of the smoothing neighbourhood, cells (1 to 7).
    smooth_tolerance : float or None
        Height tolerance of the smoothing neighbourhood, metres; None = 2.5 x resolution.
    tile : int
        Tile core side, cells.
    """

    outlier_threshold: float | None = None
    outlier_window: int = 5
    min_support: int = 4
    min_confidence: float = 0.05
    confident: float = 0.4
    max_hole: float = 10.0
    step: float = 1.0
    sharpen: bool = True
    smooth: bool = False
    smooth_radius: int = 2
    smooth_tolerance: float | None = None
    tile: int = 1024

    def validate(self) -> None:
        def positive(name: str, allow_zero: bool = False) -> None:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise InputError(f"{name}: expected a number, got {v!r}")
            if v < 0 or (v == 0 and not allow_zero):
                raise InputError(
                    f"{name}: expected a {'non-negative' if allow_zero else 'positive'} number, got {v!r}"
                )

        if self.outlier_threshold is not None:
            positive("outlier_threshold")
        w = self.outlier_window
        if isinstance(w, bool) or not isinstance(w, int) or w % 2 == 0 or not 3 <= w <= 15:
            raise InputError(f"outlier_window: expected an odd number of cells from 3 to 15, got {w!r}")
        if (
            isinstance(self.min_support, bool)
            or not isinstance(self.min_support, int)
            or not (0 <= self.min_support < w * w)
        ):
            raise InputError(
                f"min_support: expected an integer from 0 to {w * w - 1}, got {self.min_support!r}"
            )
        if not 0.0 <= self.confident <= 1.0:
            raise InputError(f"confident: expected a value in [0, 1], got {self.confident!r}")
        if not 0.0 <= self.min_confidence <= 1.0:
            raise InputError(f"min_confidence: expected a value in [0, 1], got {self.min_confidence!r}")
        positive("max_hole", allow_zero=True)
        positive("step")
        r = self.smooth_radius
        if isinstance(r, bool) or not isinstance(r, int) or not 1 <= r <= 7:
            raise InputError(f"smooth_radius: expected an integer from 1 to 7 cells, got {r!r}")
        if self.smooth_tolerance is not None:
            positive("smooth_tolerance")
        if isinstance(self.tile, bool) or not isinstance(self.tile, int) or self.tile < 32:
            raise InputError(f"tile: expected an integer of at least 32 cells, got {self.tile!r}")

    def threshold(self, res: float) -> float:
        return float(self.outlier_threshold) if self.outlier_threshold is not None else 4.0 * res

    def tolerance(self, res: float) -> float:
        return float(self.smooth_tolerance) if self.smooth_tolerance is not None else 2.5 * res

    def outlier_margin(self) -> int:
        # confidence pass, sharpening (2), both outlier passes, islands (their extent and ring)
        return CONFIDENCE_HALF + 2 + 3 * (self.outlier_window // 2) + 1 + self.island_cells() + ISLAND_RING

    def island_cells(self) -> int:
        """Valid components smaller than this are judged as islands (the second pass's support)."""
        return 3 * self.min_support

    def sharpen_step(self, res: float) -> float:
        return max(self.step, 2.0 * res * math.tan(math.radians(70.0)))

    def hole_cells(self, res: float) -> int:
        return int(math.ceil(self.max_hole / res))


@dataclass
class FilterStats:
    """What :func:`filter_dsm` did (cell counts unless stated).

    Attributes
    ----------
    cells : int
        Cells of the raster.
    valid_input : int
        Valid cells of the input.
    outliers_removed : int
        Cells removed by the median/support test.
    low_confidence_removed : int
        Cells removed for confidence below ``min_confidence``.
    holes_filled, cells_filled : int
        Holes filled and their cells (``cells_filled`` also counts the narrow gaps filled in wide
        holes, which stay counted in ``holes_remaining``).
    holes_remaining, cells_remaining : int
        Holes left as nodata (wider than ``max_hole``) and their cells.
    largest_remaining_hole_m : float
        Width (metres) of the widest remaining hole (0 if none).
    sharpened : int
        Cells of blurred steps snapped to the nearer level.
    smoothed : int
        Cells changed by the smoothing.
    valid_output : int
    """

    cells: int = 0
    valid_input: int = 0
    outliers_removed: int = 0
    low_confidence_removed: int = 0
    holes_filled: int = 0
    cells_filled: int = 0
    holes_remaining: int = 0
    cells_remaining: int = 0
    largest_remaining_hole_m: float = 0.0
    sharpened: int = 0
    smoothed: int = 0
    valid_output: int = 0

    def as_dict(self) -> dict:
        return asdict(self)

    def summary(self) -> str:
        return (
            f"{self.outliers_removed} outliers and {self.low_confidence_removed} low-confidence cells "
            f"removed; {self.sharpened} cells of blurred steps sharpened; "
            f"{self.holes_filled} holes ({self.cells_filled} cells) filled; {self.holes_remaining} holes "
            f"({self.cells_remaining} cells, widest {self.largest_remaining_hole_m:.2f} m) remain nodata; "
            f"{self.smoothed} cells smoothed; {self.valid_output} of {self.cells} cells valid "
            f"({self.valid_input} before)"
        )


#: width (cells) of the ring around an island whose valid cells give its reference height
ISLAND_RING = CONFIDENCE_HALF
