"""Raster grids in the world frame and the tile plan shared by every raster stage.

A :class:`RasterGrid` is a north-up grid of square cells in the orientation's
world CRS, described like a GDAL geotransform ``(x_min, res, 0, y_max, 0, -res)``.
The value of cell ``(row, col)`` belongs to its **centre**

    X = x_min + (col + 0.5) * res,   Y = y_max - (row + 0.5) * res

(row 0 is the northern edge). OSGM, DSM filtering and the true orthophoto all
work on such grids and cut them with :meth:`RasterGrid.tiles` into
:class:`Tile` objects: a *core* window that the tile owns (the core windows
partition the grid) and an *outer* window that adds an overlap margin on every
side (clipped at the grid border) so that filters and path aggregation near a
tile edge see their neighbourhood. A tile computes on its outer window and
writes only its core window, so the assembled raster has no seams.

Windows are ``(row0, col0, rows, cols)`` in cells of the parent grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import InputError

#: Largest grid accepted (cells); beyond it a coarser resolution or a smaller extent is needed.
MAX_GRID_CELLS = 4_000_000_000


def _positive(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a positive number, got {value!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{name}: expected a positive number, got {value!r}")
    return v


@dataclass(frozen=True)
class RasterGrid:
    """A north-up grid of square cells in the world frame.

    Attributes
    ----------
    x_min, y_max : float
        World coordinates of the outer corner of cell (0, 0) (north-west).
    res : float
        Cell size in CRS units (metres).
    rows, cols : int
    crs : str or None
        The CRS as stored in the orientation (``AUTH:CODE`` or WKT).
    """

    x_min: float
    y_max: float
    res: float
    rows: int
    cols: int
    crs: str | None = None

    def __post_init__(self) -> None:
        _positive(self.res, "resolution")
        for name in ("x_min", "y_max"):
            if not math.isfinite(float(getattr(self, name))):
                raise InputError(f"grid {name} must be finite, got {getattr(self, name)!r}")
        for name in ("rows", "cols"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 1:
                raise InputError(f"grid {name} must be a positive integer, got {v!r}")
        if self.rows * self.cols > MAX_GRID_CELLS:
            raise InputError(
                f"grid of {self.rows} x {self.cols} cells exceeds {MAX_GRID_CELLS:,} cells; "
                "use a coarser resolution or a smaller extent"
            )

    # ------------------------------------------------------------ construction
    @classmethod
    def from_extent(cls, extent, resolution, crs: str | None = None) -> RasterGrid:
        """The grid covering ``extent = (xmin, ymin, xmax, ymax)`` (world) at ``resolution``.

        The grid starts at ``(xmin, ymax)``; rows and columns are rounded up so
        the whole extent is covered (the synthetic truth rasters use the same rule).
        """
        res = _positive(resolution, "resolution")
        try:
            x0, y0, x1, y1 = (float(v) for v in extent)
        except (TypeError, ValueError):
            raise InputError(f"extent: expected (xmin, ymin, xmax, ymax), got {extent!r}") from None
        if not all(math.isfinite(v) for v in (x0, y0, x1, y1)) or not (x1 > x0 and y1 > y0):
            raise InputError(
                f"extent must be (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax, got {extent!r}"
            )
        cols = max(1, int(math.ceil((x1 - x0) / res - 1e-9)))
        rows = max(1, int(math.ceil((y1 - y0) / res - 1e-9)))
        if rows * cols > MAX_GRID_CELLS:
            raise InputError(
                f"extent {extent!r} at resolution {res} gives {rows} x {cols} cells "
                f"(more than {MAX_GRID_CELLS:,}); use a coarser resolution or a smaller extent"
            )
        return cls(x0, y1, res, rows, cols, crs)

    @classmethod
    def from_geotransform(cls, gt, rows: int, cols: int, crs: str | None = None) -> RasterGrid:
        """From a GDAL geotransform of a north-up raster with square cells."""
        x0, rx, sx, y1, sy, ry = (float(v) for v in gt)
        if sx != 0 or sy != 0 or not rx > 0 or not math.isclose(-ry, rx, rel_tol=1e-6):
            raise InputError(
                f"raster must be north-up with square cells (geotransform {tuple(gt)}); warp it first"
            )
        return cls(x0, y1, rx, int(rows), int(cols), crs)

    # ------------------------------------------------------------ properties
    @property
    def shape(self) -> tuple[int, int]:
        return (self.rows, self.cols)

    @property
    def geotransform(self) -> tuple[float, float, float, float, float, float]:
        return (self.x_min, self.res, 0.0, self.y_max, 0.0, -self.res)

    @property
    def transform(self):
        """The rasterio ``Affine`` of the grid."""
        from affine import Affine

        return Affine.from_gdal(*self.geotransform)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the cell edges."""
        return (self.x_min, self.y_max - self.rows * self.res, self.x_min + self.cols * self.res, self.y_max)

    # ------------------------------------------------------------ coordinates
    def x_centres(self) -> np.ndarray:
        """World X of the column centres, (cols,)."""
        return self.x_min + (np.arange(self.cols) + 0.5) * self.res

    def y_centres(self) -> np.ndarray:
        """World Y of the row centres, (rows,), decreasing."""
        return self.y_max - (np.arange(self.rows) + 0.5) * self.res

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """World ``(X, Y)`` of every cell centre, each (rows, cols)."""
        X, Y = np.meshgrid(self.x_centres(), self.y_centres())
        return X, Y

    def cell_of(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Fractional ``(row, col)`` of world points (cell centres are integers)."""
        col = (np.asarray(x, dtype=np.float64) - self.x_min) / self.res - 0.5
        row = (self.y_max - np.asarray(y, dtype=np.float64)) / self.res - 0.5
        return row, col

    # ------------------------------------------------------------ sub-grids and tiles
    def window(self, row0: int, col0: int, rows: int, cols: int) -> RasterGrid:
        """The sub-grid of a window ``(row0, col0, rows, cols)`` (may extend beyond this grid)."""
        return RasterGrid(
            self.x_min + col0 * self.res,
            self.y_max - row0 * self.res,
            self.res,
            int(rows),
            int(cols),
            self.crs,
        )

    def scaled(self, factor: int) -> RasterGrid:
        """The coarser grid with cells ``factor`` times larger, covering at least this grid."""
        f = int(factor)
        if f < 1:
            raise InputError(f"grid scale factor must be a positive integer, got {factor!r}")
        return RasterGrid(
            self.x_min, self.y_max, self.res * f, -(-self.rows // f), -(-self.cols // f), self.crs
        )

    def tiles(self, tile_cells: int, overlap: int = 0) -> list[Tile]:
        """Cut the grid into tiles of ``tile_cells`` x ``tile_cells`` core cells.

        Parameters
        ----------
        tile_cells : int
            Side of a tile's core window in cells (the last row/column of tiles is smaller).
        overlap : int
            Margin in cells added on every side of the core window for the outer window.

        Returns
        -------
        list of Tile, row-major, ``index = (tile_row, tile_col)``.
        """
        t = int(tile_cells)
        ov = int(overlap)
        if t < 1:
            raise InputError(f"tile size must be a positive number of cells, got {tile_cells!r}")
        if ov < 0:
            raise InputError(f"tile overlap must not be negative, got {overlap!r}")
        out = []
        for i, r0 in enumerate(range(0, self.rows, t)):
            for j, c0 in enumerate(range(0, self.cols, t)):
                nr = min(t, self.rows - r0)
                nc = min(t, self.cols - c0)
                orow0 = max(0, r0 - ov)
                ocol0 = max(0, c0 - ov)
                orow1 = min(self.rows, r0 + nr + ov)
                ocol1 = min(self.cols, c0 + nc + ov)
                out.append(Tile((i, j), (r0, c0, nr, nc), (orow0, ocol0, orow1 - orow0, ocol1 - ocol0)))
        return out


@dataclass(frozen=True)
class Tile:
    """One tile of a :class:`RasterGrid` (windows in cells of the parent grid).

    Attributes
    ----------
    index : (tile_row, tile_col)
    core : (row0, col0, rows, cols)
        The cells this tile owns and writes.
    outer : (row0, col0, rows, cols)
        The core plus the overlap margin, clipped to the grid: the cells it computes.
    """

    index: tuple[int, int]
    core: tuple[int, int, int, int]
    outer: tuple[int, int, int, int]

    @property
    def inner_slices(self) -> tuple[slice, slice]:
        """Slices of the core window inside an array of the outer window."""
        r = self.core[0] - self.outer[0]
        c = self.core[1] - self.outer[1]
        return slice(r, r + self.core[2]), slice(c, c + self.core[3])

    @property
    def core_slices(self) -> tuple[slice, slice]:
        """Slices of the core window inside an array of the whole grid."""
        return slice(self.core[0], self.core[0] + self.core[2]), slice(
            self.core[1], self.core[1] + self.core[3]
        )

    @property
    def outer_slices(self) -> tuple[slice, slice]:
        """Slices of the outer window inside an array of the whole grid."""
        return (
            slice(self.outer[0], self.outer[0] + self.outer[2]),
            slice(self.outer[1], self.outer[1] + self.outer[3]),
        )

    def core_grid(self, grid: RasterGrid) -> RasterGrid:
        return grid.window(*self.core)

    def outer_grid(self, grid: RasterGrid) -> RasterGrid:
        return grid.window(*self.outer)
