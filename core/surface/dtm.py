"""Digital terrain model (DTM) by SMRF-style ground filtering of a DSM.

The simple morphological filter of Pingel, Clarke and McBride (2013), on a
raster:

1. The DSM is reduced to a *minimum surface* on a coarser working grid
   (``resolution``, default 1 m; each working cell holds the lowest valid
   DSM cell inside it), its nodata is filled with the nearest value and its
   low outliers (more than ``2 elevation_threshold`` below the median of
   their 8 neighbours) are raised to that median.
2. **Progressive opening**: for window radii ``k = 1 .. ceil(max_window /
   resolution)`` cells, the surface is opened (erosion then dilation by
   ``k`` steps of alternating 3 x 3 square and cross elements, an octagon of
   radius ``k``); a cell is an *object* when the opening at radius ``k``
   lowers it, relative to the opening at ``k - 1``, by more than
   ``slope * k * resolution``.
3. A provisional terrain is interpolated (harmonic, exact sparse solve) over
   the object cells from the ground cells; working cells within
   ``elevation_threshold + elevation_scaler * local slope`` of it are ground
   again (SMRF's final classification) and it is interpolated once more.
4. **Refinement on the DSM cells** (twice): DSM cells within that tolerance of
   the terrain (above or below: pits are not ground) are ground; the terrain
   becomes their mean per working cell (the minimum surface is biased low on
   slopes), harmonic-filled where a working cell has no ground cell.
5. The terrain is resampled bilinearly onto the DSM grid, tile by tile, and
   kept where the DSM is valid.

``max_window`` must exceed half the width of the largest building; ``slope``
is the largest terrain slope (rise over run) kept as ground.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import InputError
from ..grid import RasterGrid
from ..progress import Progress, Steps, as_progress, check


@dataclass
class DtmConfig:
    """Parameters of :func:`dtm_from_dsm` (metres unless stated).

    Attributes
    ----------
    resolution : float or None
        Working cell size of the ground filter; None = max(1 m, DSM resolution).
    max_window : float
        Largest opening radius; more than half the width of the largest building.
    slope : float
        Terrain slope threshold (rise over run) of the progressive opening.
    elevation_threshold : float
        Final classification: largest height above the provisional terrain of ground.
    elevation_scaler : float
        Final classification: additional tolerance per unit of terrain slope.
    tile : int
        Tile side (DSM cells) of the reading and writing passes.
    """

    resolution: float | None = None
    max_window: float = 18.0
    slope: float = 0.15
    elevation_threshold: float = 0.5
    elevation_scaler: float = 1.25
    tile: int = 2048

    def validate(self) -> None:
        for name in ("max_window", "slope", "elevation_threshold"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not (math.isfinite(v) and v > 0):
                raise InputError(f"{name}: expected a positive number, got {v!r}")
        if not (math.isfinite(self.elevation_scaler) and self.elevation_scaler >= 0):
            raise InputError(
                f"elevation_scaler: expected a non-negative number, got {self.elevation_scaler!r}"
            )
        if self.resolution is not None and not (math.isfinite(self.resolution) and self.resolution > 0):
            raise InputError(f"resolution: expected a positive cell size in metres, got {self.resolution!r}")
        if isinstance(self.tile, bool) or not isinstance(self.tile, int) or self.tile < 32:
            raise InputError(f"tile: expected an integer of at least 32 cells, got {self.tile!r}")


@dataclass
class DtmStats:
    """What :func:`dtm_from_dsm` found.

    Attributes
    ----------
    working_resolution : float
        Cell size of the ground filter, metres.
    working_cells : int
        Valid cells of the working grid.
    ground_fraction : float
        Share of the valid DSM cells classified as ground.
    """

    working_resolution: float = 0.0
    working_cells: int = 0
    ground_fraction: float = 0.0

    def as_dict(self) -> dict:
        return asdict(self)


# ------------------------------------------------------------------ kernels (OpenCV / scipy)


def _open(z: np.ndarray, k: int) -> np.ndarray:
    """Opening by an octagon of radius ``k`` cells (alternating square/cross 3 x 3 steps)."""
    import cv2

    sq = np.ones((3, 3), np.uint8)
    cr = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
    e = z
    for i in range(k):
        e = cv2.erode(e, sq if i % 2 == 0 else cr, borderType=cv2.BORDER_REPLICATE)
    for i in range(k):
        e = cv2.dilate(e, sq if i % 2 == 0 else cr, borderType=cv2.BORDER_REPLICATE)
    return e


def _harmonic(z: np.ndarray, known: np.ndarray) -> np.ndarray:
    """Fill the unknown cells of ``z`` by harmonic interpolation from the ``known`` cells."""
    from scipy import ndimage

    from .filter.holes import _FOUR, _solve

    fill = ~known
    if not fill.any():
        return z.copy()
    if not known.any():
        raise InputError("ground filter: no ground cell found; check max_window and slope")
    out = np.where(known, z, np.nan)
    labels, _ = ndimage.label(fill, structure=_FOUR)
    return _solve(out, fill, labels, known, known)


def _smrf(
    zmin: np.ndarray, res: float, cfg: DtmConfig, progress: Progress | None
) -> tuple[np.ndarray, float]:
    """SMRF on a filled minimum surface: returns (terrain, ground fraction)."""
    z = zmin.astype(np.float32)
    kmax = max(1, int(math.ceil(cfg.max_window / res)))
    obj = np.zeros(z.shape, bool)
    prev = z
    for k in range(1, kmax + 1):
        check(progress)
        cur = _open(z, k)
        obj |= (prev - cur) > cfg.slope * k * res
        prev = cur
        if progress is not None:
            progress.update(0.7 * k / kmax, f"ground filter: opening radius {k * res:.1f} m")
    ground = ~obj
    prov = _harmonic(z.astype(np.float64), ground)
    gy, gx = np.gradient(prov, res)
    slope = np.hypot(gx, gy)
    ground = (z - prov) <= cfg.elevation_threshold + cfg.elevation_scaler * slope
    terrain = _harmonic(z.astype(np.float64), ground)
    return terrain, float(ground.mean())


# ------------------------------------------------------------------ pipeline


def _working_factor(grid: RasterGrid, cfg: DtmConfig) -> int:
    target = cfg.resolution if cfg.resolution is not None else max(1.0, grid.res)
    return max(1, int(round(target / grid.res)))


def _min_pool(z: np.ndarray, f: int) -> np.ndarray:
    """Minimum of valid cells over f x f blocks (NaN where a block has none); shape ceil(/f)."""
    nr, nc = z.shape
    pr, pc = -(-nr // f) * f, -(-nc // f) * f
    a = np.full((pr, pc), np.inf)
    a[:nr, :nc] = np.where(np.isfinite(z), z, np.inf)
    m = a.reshape(pr // f, f, pc // f, f).min(axis=(1, 3))
    return np.where(np.isfinite(m), m, np.nan)


def _drop_low_outliers(z: np.ndarray, depth: float) -> np.ndarray:
    """Raise cells more than ``depth`` below the median of their 3 x 3 neighbours to it (twice)."""
    from scipy import ndimage

    fp = np.ones((3, 3), bool)
    fp[1, 1] = False
    out = z.copy()
    for _ in range(2):
        med = ndimage.median_filter(out, footprint=fp, mode="nearest")
        low = out < med - depth
        if not low.any():
            break
        out[low] = med[low]
    return out


def _fill_nearest(z: np.ndarray) -> np.ndarray:
    from scipy import ndimage

    bad = ~np.isfinite(z)
    if not bad.any():
        return z
    idx = ndimage.distance_transform_edt(bad, return_distances=False, return_indices=True)
    return z[tuple(idx)]


def terrain_on_working_grid(read, grid: RasterGrid, cfg: DtmConfig, progress: Progress | None = None):
    """Minimum surface on the working grid and its SMRF terrain.

    ``read(r0, c0, nr, nc)`` returns DSM heights (NaN = nodata) of a window.
    Returns ``(terrain (R, C) float64, factor, DtmStats)``.
    """
    steps = Steps(as_progress(progress), [1, 4, 1, 1])
    f = _working_factor(grid, cfg)
    tile = max(f, (cfg.tile // f) * f)
    wr, wc = -(-grid.rows // f), -(-grid.cols // f)
    zmin = np.full((wr, wc), np.nan)
    tiles = grid.tiles(tile, 0)
    for n, t in enumerate(tiles):
        check(steps.parent)
        r0, c0, nr, nc = t.core
        z = np.asarray(read(r0, c0, nr, nc), dtype=np.float64)
        zmin[r0 // f : r0 // f + -(-nr // f), c0 // f : c0 // f + -(-nc // f)] = _min_pool(z, f)
        steps[0].update((n + 1) / len(tiles), "ground filter: minimum surface")
    valid = np.isfinite(zmin)
    if not valid.any():
        raise InputError("the DSM has no valid cells (all nodata): no terrain can be computed")
    terrain, _ = _smrf(
        _drop_low_outliers(_fill_nearest(zmin), 2.0 * cfg.elevation_threshold), grid.res * f, cfg, steps[1]
    )
    terrain, _ = _refine(read, grid, f, terrain, cfg, tile, steps[2])
    terrain, gfrac = _refine(read, grid, f, terrain, cfg, tile, steps[3])
    return terrain, f, DtmStats(grid.res * f, int(valid.sum()), gfrac)


def _refine(
    read, grid: RasterGrid, f: int, terrain: np.ndarray, cfg: DtmConfig, tile: int, progress: Progress | None
) -> tuple[np.ndarray, float]:
    """One refinement: DSM cells within the elevation tolerance of ``terrain`` (absolute) are
    ground; the terrain is their mean per working cell, harmonic-filled elsewhere.

    Returns ``(terrain, share of valid DSM cells that are ground)``.
    """
    res_w = grid.res * f
    gy, gx = np.gradient(terrain, res_w)
    slope = np.hypot(gx, gy)
    tol = cfg.elevation_threshold + cfg.elevation_scaler * slope
    sums = np.zeros(terrain.shape)
    counts = np.zeros(terrain.shape)
    n_valid = 0
    tiles = grid.tiles(tile, 0)
    for n, t in enumerate(tiles):
        check(progress)
        r0, c0, nr, nc = t.core
        z = np.asarray(read(r0, c0, nr, nc), dtype=np.float64)
        ter = _upsample(terrain, f, t.core)
        tol_up = _upsample(tol, f, t.core)
        ground = np.isfinite(z) & (np.abs(z - ter) <= tol_up)
        n_valid += int(np.isfinite(z).sum())
        pr, pc = -(-nr // f) * f, -(-nc // f) * f
        zz = np.zeros((pr, pc))
        gg = np.zeros((pr, pc))
        zz[:nr, :nc] = np.where(ground, z, 0.0)
        gg[:nr, :nc] = ground
        a0, b0 = r0 // f, c0 // f
        sums[a0 : a0 + pr // f, b0 : b0 + pc // f] += zz.reshape(pr // f, f, pc // f, f).sum(axis=(1, 3))
        counts[a0 : a0 + pr // f, b0 : b0 + pc // f] += gg.reshape(pr // f, f, pc // f, f).sum(axis=(1, 3))
        if progress is not None:
            progress.update((n + 1) / len(tiles), "ground filter: ground cells")
    known = counts > 0
    mean = np.where(known, sums / np.maximum(counts, 1), np.nan)
    return _harmonic(mean, known), float(counts.sum() / max(n_valid, 1))


def _upsample(terrain: np.ndarray, f: int, core: tuple[int, int, int, int]) -> np.ndarray:
    """Bilinear values of the working-grid terrain at the DSM cell centres of a window."""
    from scipy import ndimage

    r0, c0, nr, nc = core
    rr = (np.arange(r0, r0 + nr) + 0.5) / f - 0.5
    cc = (np.arange(c0, c0 + nc) + 0.5) / f - 0.5
    R, C = np.meshgrid(rr, cc, indexing="ij")
    return ndimage.map_coordinates(terrain, [R, C], order=1, mode="nearest")


def dtm_from_dsm_array(
    z: np.ndarray, grid: RasterGrid, config: DtmConfig | None = None, progress: Progress | None = None
) -> tuple[np.ndarray, DtmStats]:
    """Terrain heights on the DSM grid (NaN where the DSM is nodata).

    Parameters
    ----------
    z : (rows, cols) float
        DSM heights in metres, NaN = nodata (filter it first: outliers below the
        terrain pull the terrain down).
    grid : RasterGrid

    Returns
    -------
    (dtm (rows, cols) float32, DtmStats)
    """
    cfg = config or DtmConfig()
    cfg.validate()
    a = np.asarray(z, dtype=np.float64)
    if a.shape != grid.shape:
        raise InputError(f"DSM: expected an array of the grid's shape {grid.shape}, got {a.shape}")
    terrain, f, stats = terrain_on_working_grid(
        lambda r0, c0, nr, nc: a[r0 : r0 + nr, c0 : c0 + nc], grid, cfg, progress
    )
    out = _upsample(terrain, f, (0, 0, grid.rows, grid.cols)).astype(np.float32)
    out[~np.isfinite(a)] = np.nan
    return out, stats


def dtm_from_dsm(
    input_path, output_path, config: DtmConfig | None = None, ndsm_path=None, progress: Progress | None = None
) -> DtmStats:
    """Write the DTM (and optionally the normalised DSM, DSM - DTM) of a DSM GeoTIFF.

    Outputs are float32 GeoTIFFs on the DSM's grid with its CRS and nodata
    (-9999 when it has none), written atomically by tiles.

    Raises
    ------
    CRSError
        The DSM has no CRS or a geographic one.
    InputError
        Every DSM cell is nodata, or a bad parameter.
    """
    import contextlib

    from ..geometry.frame import parse_crs, require_metric
    from ..rasterio_io import RasterWriter, raster_grid, read_raster

    cfg = config or DtmConfig()
    cfg.validate()
    grid = raster_grid(input_path, require_crs=True)
    require_metric(parse_crs(grid.crs), f"DSM {input_path}")
    _, _, nodata = read_raster(input_path, 1, (0, 0, 1, 1))
    out_nodata = -9999.0 if nodata is None or (isinstance(nodata, float) and math.isnan(nodata)) else nodata

    def read(r0, c0, nr, nc):
        d, _, _ = read_raster(input_path, 1, (r0, c0, nr, nc))
        d = d.astype(np.float64)
        if nodata is not None and not (isinstance(nodata, float) and math.isnan(nodata)):
            d[d == nodata] = np.nan
        return d

    steps = Steps(as_progress(progress), [4, 1])
    terrain, f, stats = terrain_on_working_grid(read, grid, cfg, steps[0])
    with contextlib.ExitStack() as stack:
        w_dtm = stack.enter_context(
            RasterWriter(output_path, grid, 1, "float32", out_nodata, descriptions=["terrain height (DTM)"])
        )
        w_ndsm = None
        if ndsm_path is not None:
            w_ndsm = stack.enter_context(
                RasterWriter(
                    ndsm_path,
                    grid,
                    1,
                    "float32",
                    out_nodata,
                    descriptions=["height above terrain (DSM - DTM)"],
                )
            )
        tiles = grid.tiles(cfg.tile, 0)
        for n, t in enumerate(tiles):
            check(steps.parent)
            d = read(*t.core)
            ter = _upsample(terrain, f, t.core)
            ok = np.isfinite(d)
            w_dtm.write(np.where(ok, ter, out_nodata).astype(np.float32), t.core)
            if w_ndsm is not None:
                w_ndsm.write(np.where(ok, d - ter, out_nodata).astype(np.float32), t.core)
            steps[1].update((n + 1) / len(tiles), "DTM: writing")
    return stats
