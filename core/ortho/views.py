"""Per-tile visibility of the output cells in every image that may see them.

For one tile (:class:`~truortho.core.grid.Tile`, computed on its outer window):

1. the surface heights of the outer window plus a *margin* (cells outside the
   tile that may occlude it: a cell at horizontal distance ``d`` from the window
   can hide a window cell only if it stands more than ``d / tan(max_view_angle)``
   above the window's lowest cell; the margin is the largest such ``d`` for the
   surface's height range, and margin cells failing the test are left out of
   the depth buffer);
2. the candidate images: those whose footprint (the frame cast onto the
   planes of the lowest and highest surface height) meets the window;
3. per candidate: a depth buffer over the image window the tile's cells project
   into, at ``scale = min(1, oversample * gsd / res)`` buffer pixels per image
   pixel (so a buffer pixel is the image pixel or, for a coarse output, about
   one output cell), and the depth test of every cell (:mod:`.zbuffer`);
4. per candidate and cell: viewing angle, incidence on the surface (normal from
   the heights, the smaller one-sided difference on each axis so a cell next to
   a wall keeps the slope of its own roof or ground) and the effective ground
   resolution of :mod:`.select`.

Cells are usable in an image when visible, in front of the surface (incidence
below 90 degrees) and seen at most ``max_view_angle`` off nadir. Without
visibility (``visibility=False``, the conventional orthorectification) a cell
is usable in every image whose frame contains its projection.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..grid import RasterGrid, Tile
from ..jit import njit
from .surface import PlanTransform
from .zbuffer import frame_cells, height_noise, near_step_mask, project, render_depth, view_cells_into

#: Cells around a tile's window that :func:`~.zbuffer.height_noise` reads (9 x 9 median surface,
#: 7 x 7 window median).
NOISE_REACH = 9 // 2 + 3

#: Largest reach (cells) of the near-field test of :func:`~.zbuffer.view_cells_into` (2 covers the
#: depth tolerance without the noise term; the noise term adds cells up to this bound).
NEAR_FIELD_MAX = 8


def near_field_reach(noise, max_view: float, res: float) -> np.ndarray:
    """Cells (int64, shaped like ``noise``) the near-field test of :func:`~.zbuffer.view_cells_into`
    must reach for cells with the height tolerances ``noise`` (metres, the noise term).

    Two cells cover the depth tolerance without the noise term. The noise term lengthens a cell's
    tolerance by up to ``noise / cos(max_view)`` along its ray, so a wall entered that far from the
    cell passes the depth test: the near field must reach as far, or a ray through the wall's
    building hides nothing where the depth buffer misses the building's far side (seed 7's scene 3:
    ground cells 3 cells behind a building, seen through it from an oblique view past a sloped
    roof's omitted risers, where the noise estimate next to the wall read 8 cm). At most
    :data:`NEAR_FIELD_MAX`. Per cell, so the result does not depend on the tiling.
    """
    def number(v) -> bool:
        return isinstance(v, int | float | np.number) and not isinstance(v, bool) and math.isfinite(float(v))

    if not (number(max_view) and 0.0 < float(max_view) < math.pi / 2):
        raise InputError(f"near_field_reach: max_view must be in (0, pi/2) radians, got {max_view!r}")
    if not (number(res) and float(res) > 0.0):
        raise InputError(f"near_field_reach: res must be a cell size > 0 (metres), got {res!r}")
    a = np.asarray(noise, dtype=np.float64)
    if (a < 0).any():
        raise InputError("near_field_reach: noise must be heights >= 0 (metres)")
    extra = np.ceil(np.nan_to_num(a, nan=0.0) / (math.cos(max_view) * res))
    return (2 + np.clip(extra, 0, NEAR_FIELD_MAX - 2)).astype(np.int64)


#: Candidates evaluated between two checks of the cells' clean views (``views_per_cell``).
LAZY_BATCH = 2


@dataclass
class ViewSetup:
    """What every tile needs, prepared once (:func:`prepare_views`)."""

    images: list  # orientation Image objects (all of the orientation)
    cameras: list[Camera]  # camera of each image
    boxes: np.ndarray  # (n, 4) local xy bounding boxes of the footprints
    zmin: float  # local heights
    zmax: float
    max_view: float  # radians
    margin_cells: int
    visibility: bool
    tol_factor: float
    oversample: float
    wall_min: float
    discontinuity: float = 1.0  # height step (m) of a building outline for the edge shift
    edge_shift: float = 0.75  # cells
    views_per_cell: int = 0  # clean views after which a cell takes no further candidate (0 = all)
    blocks: HeightBlocks | None = None  # block maxima/minima of the surface: a margin per tile
    top_views: int = 0  # keep the candidates among the best this many of some cell (0 = all)
    noise_tolerance: float = 0.0  # factor of the surface's height noise in the depth tolerance


@dataclass
class HeightBlocks:
    """Highest and lowest surface height (world) of every ``block x block`` cells of a grid.

    Lets a tile's occluder margin follow the heights around it instead of the whole surface's
    range (:meth:`margin`): next to a tower the margin is the tower's reach, in open country a few
    cells; the depth buffers hold the same occluders either way (a cell beyond the margin cannot
    pass the test of :func:`tile_views`).
    """

    grid: RasterGrid
    block: int
    hmax: np.ndarray  # (rows, cols) of blocks, -inf where no data
    hmin: np.ndarray  # +inf where no data

    @classmethod
    def of(
        cls, surface, grid: RasterGrid, block: int = 32, strip_cells: int = 4_000_000, progress=None
    ) -> HeightBlocks:
        """Read the surface on ``grid`` by strips of whole block rows (bounded memory); ``progress``
        (optional) is checked for a cancel before every strip."""
        from ..progress import check

        if not (isinstance(block, int) and block > 0):
            raise InputError(f"HeightBlocks: block must be a positive integer, got {block!r}")
        nbr, nbc = -(-grid.rows // block), -(-grid.cols // block)
        hmax = np.full((nbr, nbc), -np.inf)
        hmin = np.full((nbr, nbc), np.inf)
        rows_per = max(1, strip_cells // max(grid.cols * block, 1)) * block
        for r0 in range(0, grid.rows, rows_per):
            check(progress)
            nr = min(rows_per, grid.rows - r0)
            h = surface.heights_on(grid.window(r0, 0, nr, grid.cols))
            pr, pc = -(-nr // block) * block, nbc * block
            a = np.full((pr, pc), np.nan)
            a[:nr, : grid.cols] = h
            a = a.reshape(pr // block, block, nbc, block)
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks
                mx = np.nanmax(a, axis=(1, 3))
                mn = np.nanmin(a, axis=(1, 3))
            b0 = r0 // block
            hmax[b0 : b0 + len(mx)] = np.where(np.isfinite(mx), mx, -np.inf)
            hmin[b0 : b0 + len(mn)] = np.where(np.isfinite(mn), mn, np.inf)
        return cls(grid, block, hmax, hmin)

    def _blocks(self, x0: float, y0: float, x1: float, y1: float) -> tuple[slice, slice]:
        g, b = self.grid, self.block * self.grid.res
        c0 = max(int(math.floor((x0 - g.x_min) / b)), 0)
        c1 = min(int(math.floor((x1 - g.x_min) / b)) + 1, self.hmax.shape[1])
        r0 = max(int(math.floor((g.y_max - y1) / b)), 0)
        r1 = min(int(math.floor((g.y_max - y0) / b)) + 1, self.hmax.shape[0])
        return slice(r0, max(r1, r0)), slice(c0, max(c1, c0))

    def margin(self, window: RasterGrid, max_margin: int, tan_view: float) -> int:
        """Occluder margin (cells of ``window``) of a window: at most ``max_margin``."""
        x0, y0, x1, y1 = window.extent
        inner = self._blocks(x0, y0, x1, y1)
        low = self.hmin[inner]
        if not low.size or not np.isfinite(low).any():
            return max_margin
        zlow = float(np.min(low))
        d = max_margin * window.res
        high = self.hmax[self._blocks(x0 - d, y0 - d, x1 + d, y1 + d)]
        if not high.size:
            return max_margin
        top = float(np.max(high))
        if not np.isfinite(top):
            return max_margin
        # a cell d cells away enters the depth buffer when h - zlow > d res / tan - res
        need = int(math.ceil((max(top - zlow, 0.0) + window.res) * tan_view / window.res)) + 2
        return min(max_margin, need)


def image_boxes(images, cameras, zmin: float, zmax: float) -> np.ndarray:
    """Local plan bounding boxes (n, 4) of every image's footprint between heights zmin and zmax.

    The frame outline (8 samples per edge) is cast onto both planes; rays above
    the horizon are cut at 20 times the height above the plane (as
    :func:`~truortho.core.geometry.footprint.footprint_on_plane`). NaN rows: the
    image sees neither plane.
    """
    from ..geometry.camera import undistort_points
    from ..geometry.footprint import frame_outline

    rays: dict[int, np.ndarray] = {}
    out = np.full((len(images), 4), np.nan)
    for k, (im, cam) in enumerate(zip(images, cameras, strict=True)):
        key = id(cam)
        if key not in rays:
            xy = undistort_points(frame_outline(cam, 8), cam)
            rays[key] = np.column_stack([xy, np.ones(len(xy))])[np.all(np.isfinite(xy), axis=1)]
        d = rays[key] @ im.R  # R^T d_cam, row-wise
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        pts = []
        for z in (zmin, zmax):
            hgt = im.C[2] - z
            reach = 20.0 * max(abs(hgt), 1.0)
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (z - im.C[2]) / d[:, 2]
            hit = t > 0
            horiz = d[:, :2] / np.maximum(np.linalg.norm(d[:, :2], axis=1, keepdims=True), 1e-12)
            p = np.where(hit[:, None], d[:, :2] * np.where(hit, t, 0.0)[:, None], horiz * reach)
            r = np.linalg.norm(p, axis=1, keepdims=True)
            p = np.where(r > reach, p / np.maximum(r, 1e-12) * reach, p)
            if hit.any():
                pts.append(p + im.C[:2])
        if pts:
            q = np.vstack(pts)
            out[k] = [q[:, 0].min(), q[:, 1].min(), q[:, 0].max(), q[:, 1].max()]
    return out


def prepare_views(
    orientation,
    surface,
    to_local: PlanTransform,
    res: float,
    max_view_deg: float,
    visibility: bool,
    tol_factor: float,
    oversample: float,
    wall_min: float,
    discontinuity: float = 0.5,
    edge_shift: float = 0.75,
    max_margin_cells: int = 1024,
    views_per_cell: int = 0,
    top_views: int = 0,
    noise_tolerance: float = 0.0,
) -> ViewSetup:
    images = list(orientation.images)
    cams = [orientation.camera_of(im) for im in images]
    lo, hi = surface.height_range()
    zmin, zmax = lo - to_local.offset[2], hi - to_local.offset[2]
    max_view = math.radians(max_view_deg)
    margin = 0
    if visibility:
        margin = int(math.ceil((zmax - zmin) * math.tan(max_view) / res)) + 2
        margin = min(margin, max_margin_cells)
    boxes = image_boxes(images, cams, zmin, zmax)
    return ViewSetup(
        images,
        cams,
        boxes,
        zmin,
        zmax,
        max_view,
        margin,
        visibility,
        tol_factor,
        oversample,
        wall_min,
        max(float(discontinuity), 2.0 * res),
        float(edge_shift),
        int(views_per_cell),
        None,
        int(top_views),
        float(noise_tolerance),
    )


@dataclass
class TileViews:
    """Visibility of the outer-window cells of one tile in its candidate images.

    Attributes
    ----------
    grid : RasterGrid
        The outer window.
    heights : (rows, cols) float64, world heights (NaN = no surface)
    cands : (K,) int, indices into the orientation's images
    usable, near_edge : (K, rows, cols) bool
    uv : (K, rows, cols, 2) float32 full-resolution pixel coordinates
    eff_res : (K, rows, cols) float32 effective ground resolution (metres)
    gsd : (K,) float, median pixel footprint (metres) of each candidate over the tile
    """

    grid: RasterGrid
    heights: np.ndarray
    cands: np.ndarray
    usable: np.ndarray
    near_edge: np.ndarray
    uv: np.ndarray
    eff_res: np.ndarray
    gsd: np.ndarray
    triangles: int = 0
    #: (K,) bool from :func:`all_tile_views`: among the ``top_views`` best of some cell (None after
    #: :func:`prune_views`, or when every candidate stays)
    top: np.ndarray | None = None


def _normals(h: np.ndarray, res: float, noise: np.ndarray | None = None) -> np.ndarray:
    """Unit normals (rows, cols, 3) from the smaller one-sided differences (the fwd one on a tie,
    the other one where a neighbour has no height, flat where neither has).

    ``noise`` (rows, cols), metres, optional: each difference is first shrunk towards 0 by the
    cell's noise term (what the depth test allows for the surface's own noise), so the bumps and
    pits of a rough matched surface do not tilt its cells away from every camera. Without it, or
    where it is 0 (a truth DSM, except sloped ground next to a wall, see :func:`height_noise`), the
    differences are used as they are.
    """
    hh = np.ascontiguousarray(h, np.float64)
    nz = np.zeros(hh.shape) if noise is None else np.ascontiguousarray(noise, np.float64)
    if nz.shape != hh.shape or not (nz >= 0).all():
        raise InputError(f"_normals: noise must be heights >= 0 shaped {hh.shape}, got {nz.shape}")
    out = np.empty(h.shape + (3,))
    _normals_into(hh, float(res), nz, out)
    return out


@njit
def _slope(hm, h0, hp):
    """The smaller of the one-sided differences ``hp - h0`` (forward) and ``h0 - hm``; 0 when
    neither is finite."""
    f = hp - h0
    b = h0 - hm
    if not math.isfinite(f):
        f = b
    if not math.isfinite(b):
        b = f
    d = f if abs(f) <= abs(b) else b
    return d if math.isfinite(d) else 0.0


@njit
def _shrink(d, t):
    """``d`` moved towards 0 by ``t >= 0`` (0 within ``t``)."""
    if d > t:
        return d - t
    if d < -t:
        return d + t
    return 0.0


@njit
def _normals_into(h, res, noise, out):
    rows, cols = h.shape
    for r in range(rows):
        for c in range(cols):
            t = noise[r, c]
            hm = h[r, c - 1] if c > 0 else np.nan
            hp = h[r, c + 1] if c + 1 < cols else np.nan
            dzdx = _shrink(_slope(hm, h[r, c], hp), t) / res
            hm = h[r - 1, c] if r > 0 else np.nan
            hp = h[r + 1, c] if r + 1 < rows else np.nan
            dzdy = -(_shrink(_slope(hm, h[r, c], hp), t) / res)  # rows go south
            nx, ny = -dzdx, -dzdy
            norm = math.sqrt(nx * nx + ny * ny + 1.0)
            out[r, c, 0] = nx / norm
            out[r, c, 1] = ny / norm
            out[r, c, 2] = 1.0 / norm


def edge_shift(h: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit plan vectors (rows, cols) ``(dx, dy)`` pointing away from neighbouring height discontinuities.

    A cell whose 4-neighbour differs in height by more than ``step`` gets the
    (normalised) sum of the unit vectors from such neighbours towards itself;
    other cells get 0. x is east, y north.
    """
    hz = np.where(np.isfinite(h), h, np.nan)
    dx = np.zeros(h.shape)
    dy = np.zeros(h.shape)
    with np.errstate(invalid="ignore"):
        jump_e = np.zeros(h.shape, bool)
        jump_e[:, :-1] = ~(np.abs(hz[:, 1:] - hz[:, :-1]) <= step)  # neighbour to the east differs
        jump_w = np.zeros(h.shape, bool)
        jump_w[:, 1:] = jump_e[:, :-1]
        jump_s = np.zeros(h.shape, bool)
        jump_s[:-1, :] = ~(np.abs(hz[1:, :] - hz[:-1, :]) <= step)  # neighbour to the south (next row)
        jump_n = np.zeros(h.shape, bool)
        jump_n[1:, :] = jump_s[:-1, :]
    dx -= jump_e
    dx += jump_w
    dy += jump_s
    dy -= jump_n
    n = np.hypot(dx, dy)
    ok = n > 0
    dx[ok] /= n[ok]
    dy[ok] /= n[ok]
    return dx, dy


@njit
def _include_mask(hreg, M, rows, cols, zlow, inv_tan, res, out):
    """Cells of the region that may occlude the window: inside it, or higher than ``zlow`` by more
    than their plan distance to it over tan(max view angle), less a cell (NaN: no)."""
    for r in range(hreg.shape[0]):
        dr = max(M - r, r - (M + rows - 1), 0)
        for c in range(hreg.shape[1]):
            dc = max(M - c, c - (M + cols - 1), 0)
            if dr == 0 and dc == 0:
                out[r, c] = True
            else:
                d = math.sqrt(dr * dr + dc * dc) * res
                out[r, c] = hreg[r, c] - zlow > d * inv_tan - res


def _tile_scores(setup: ViewSetup, cands: np.ndarray, vidx: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Predicted effective resolution of each candidate over a tile (smaller is better).

    The pixel footprint at the tile's central surface point over the cosine of the off-nadir
    angle there (flat ground); times 10 when that point is outside the image frame, so images
    seeing only a corner of the tile come after those seeing its centre.
    """
    c = P[vidx].mean(axis=0)
    out = np.empty(len(cands))
    for n, k in enumerate(cands):
        im, cam = setup.images[k], setup.cameras[k]
        d = c - np.asarray(im.C, float)
        dist = float(np.linalg.norm(d))
        cosv = max(abs(float(d[2])) / max(dist, 1e-12), 1e-3)
        out[n] = dist / cam.fx / cosv
        u, v, z = project(c[None], im.R, im.C, cam)[0]
        if not (z > 0 and -0.5 <= u < cam.width - 0.5 and -0.5 <= v < cam.height - 0.5):
            out[n] *= 10.0
    return out


def tile_views(
    setup: ViewSetup,
    surface,
    grid: RasterGrid,
    tile: Tile,
    to_local: PlanTransform,
    workers: int = 1,
    prefer=None,
) -> TileViews:
    """Visibility and view quality of the outer window of ``tile`` (module docstring).

    ``prefer``: image indices evaluated first on every cell (the images neighbouring tiles
    already chose inside this window, so their roofs can continue here); they stay candidates.

    The same as :func:`prune_views` of :func:`all_tile_views`: the two halves can run apart
    (the visibility before the neighbours' labels are known).
    """
    return prune_views(all_tile_views(setup, surface, grid, tile, to_local, workers, prefer), setup, prefer)


def views_need_prefer(setup: ViewSetup) -> bool:
    """Whether :func:`all_tile_views` depends on ``prefer`` (the lazy ``views_per_cell`` order)."""
    return setup.views_per_cell > 0


def prune_views(views: TileViews, setup: ViewSetup, prefer=None) -> TileViews:
    """Drop the candidates of :func:`all_tile_views` among the ``top_views`` best of no cell,
    except the ``prefer`` images (their roofs continue from neighbouring tiles)."""
    top = views.top
    if top is not None and np.shape(top) != np.shape(views.cands):
        raise InputError(
            f"prune_views: top has shape {np.shape(top)}, the candidates {np.shape(views.cands)}"
        )
    if top is None or setup.top_views <= 0 or len(views.cands) <= setup.top_views:
        return dataclasses.replace(views, top=None)
    best = top.copy()
    if prefer is not None and len(prefer):
        best |= np.isin(views.cands, np.asarray(prefer))
    if best.all():
        return dataclasses.replace(views, top=None)
    sel = np.flatnonzero(best)
    return dataclasses.replace(
        views,
        cands=views.cands[sel],
        usable=views.usable[sel],
        near_edge=views.near_edge[sel],
        uv=views.uv[sel],
        eff_res=views.eff_res[sel],
        gsd=views.gsd[sel],
        top=None,
    )


def all_tile_views(
    setup: ViewSetup,
    surface,
    grid: RasterGrid,
    tile: Tile,
    to_local: PlanTransform,
    workers: int = 1,
    prefer=None,
) -> TileViews:
    """:func:`tile_views` before :func:`prune_views`: every candidate that sees a cell, with
    ``top`` marking those among the ``top_views`` best of some cell. ``prefer`` matters here only
    for the lazy order of ``views_per_cell`` (:func:`views_need_prefer`)."""
    res = grid.res
    outer = tile.outer_grid(grid)
    M = setup.margin_cells
    if setup.blocks is not None and M > 0:
        M = setup.blocks.margin(outer, M, math.tan(setup.max_view))
    region = grid.window(tile.outer[0] - M, tile.outer[1] - M, tile.outer[2] + 2 * M, tile.outer[3] + 2 * M)
    hreg = surface.heights_on(region)
    h = hreg[M : M + outer.rows, M : M + outer.cols]
    rows, cols = h.shape
    valid = np.isfinite(h)
    X, Y = outer.centres()
    lx, ly = to_local.xy(X, Y)
    lz = h - to_local.offset[2]
    P = np.column_stack([lx.ravel(), ly.ravel(), np.where(valid, lz, 0.0).ravel()])
    vflat = valid.ravel()
    empty = TileViews(
        outer,
        h,
        np.zeros(0, np.int64),
        np.zeros((0, rows, cols), bool),
        np.zeros((0, rows, cols), bool),
        np.zeros((0, rows, cols, 2), np.float32),
        np.zeros((0, rows, cols), np.float32),
        np.zeros(0),
    )
    if not vflat.any():
        return empty
    bx0, by0 = float(lx[valid].min()), float(ly[valid].min())
    bx1, by1 = float(lx[valid].max()), float(ly[valid].max())
    b = setup.boxes
    with np.errstate(invalid="ignore"):
        hit = (b[:, 0] <= bx1) & (b[:, 2] >= bx0) & (b[:, 1] <= by1) & (b[:, 3] >= by0)
    cand_all = np.flatnonzero(hit)
    if not len(cand_all):
        return empty
    tris = None
    if setup.visibility:
        zlow = float(np.nanmin(h))
        include = np.empty(hreg.shape, np.bool_)
        _include_mask(hreg, M, rows, cols, zlow, 1.0 / math.tan(setup.max_view), res, include)
        tris = surface.triangles(region, hreg, include, to_local, setup.wall_min)
    noise = None
    if setup.noise_tolerance > 0:
        # a rough matched surface (low-texture fields, canopies) hides its own cells from
        # oblique views behind its noise: bumps within the noise level do not occlude (computed
        # on the region with its margin, so cells at the window's border see their neighbours)
        # the median surface and the window median read 4 + 3 cells around a cell: no farther
        k = min(M, NOISE_REACH)
        sig = height_noise(hreg[M - k : M + rows + k, M - k : M + cols + k])[k : k + rows, k : k + cols]
        noise = np.ascontiguousarray((setup.noise_tolerance * math.sqrt(2.0) * sig).ravel())
    # nor do they tilt its cells away from every camera (the incidence test): boruszyn's fields
    # lost 20,700 isolated cells that way, with visibility tests or without
    normals3 = _normals(h, res, None if noise is None else noise.reshape(h.shape))
    normals = np.ascontiguousarray(normals3.reshape(-1, 3))
    # next to a much higher cell the raster geometry itself decides the visibility (a ray past a
    # building's corner: within the depth tolerance, or between two buffer pixel centres)
    near_field = None
    ray_grid = None
    if setup.visibility:
        reach = np.full(rows * cols, 2, np.int64)
        if noise is not None:
            reach = near_field_reach(noise, setup.max_view, res)
        step = near_step_mask(h, res, reach=reach.reshape(h.shape)).ravel()
        near_field = (np.where(valid, lz, np.nan).ravel(), step, cols, reach)
        ray_grid = _ray_grid(hreg, M, lx, ly, res, to_local.offset[2])
    # colour sample points: cells next to a height discontinuity are sampled a little inside their own
    # side, so the bilinear sample does not mix in the other side of a building outline
    S = P
    moved_flat = np.zeros(len(P), np.bool_)
    if setup.edge_shift > 0:
        ex, ey = edge_shift(h, setup.discontinuity)
        moved = ((ex != 0) | (ey != 0)) & valid
        if moved.any():
            delta = setup.edge_shift * res
            sx, sy = X + delta * ex, Y + delta * ey
            slx, sly = to_local.xy(sx[moved], sy[moved])
            # height along the cell's own slope
            nz = normals3[..., 2][moved]
            sz = (
                lz[moved]
                - delta * (normals3[..., 0][moved] * ex[moved] + normals3[..., 1][moved] * ey[moved]) / nz
            )
            S = P.copy()
            mi = np.flatnonzero(moved.ravel())
            S[mi, 0], S[mi, 1], S[mi, 2] = slx, sly, sz
            moved_flat[mi] = True

    vidx = np.flatnonzero(vflat)
    # candidates in order of their resolution over the tile; with ``views_per_cell`` a cell stops
    # taking further candidates once that many see it cleanly (the later ones run only on the rest)
    order = cand_all[np.argsort(_tile_scores(setup, cand_all, vidx, P), kind="stable")]
    if prefer is not None and len(prefer):
        first = np.isin(order, np.asarray(prefer))
        order = np.concatenate([order[first], order[~first]])
    # one row per candidate (in image order) of the per-cell results, written by the fused passes
    cand_sorted = np.sort(order)
    row_of = {int(k): r for r, k in enumerate(cand_sorted)}
    Kc, n = len(cand_sorted), rows * cols
    usable = np.zeros((Kc, n), np.bool_)
    edge = np.zeros((Kc, n), np.bool_)
    uv = np.full((Kc, n, 2), np.nan, np.float32)
    eff = np.full((Kc, n), np.inf, np.float32)
    counts = np.zeros(Kc, np.int64)
    gsd_all = np.zeros(Kc)
    # footprint boxes (from frame samples) padded by 5 % and two cells: a cheap first test per cell
    bxs = setup.boxes[cand_sorted]
    pad = 0.05 * np.maximum(bxs[:, 2] - bxs[:, 0], bxs[:, 3] - bxs[:, 1]) + 2.0 * res
    padded = np.column_stack([bxs[:, 0] - pad, bxs[:, 1] - pad, bxs[:, 2] + pad, bxs[:, 3] + pad])

    def one(k, cells):
        im = setup.images[k]
        cam = setup.cameras[k]
        r = row_of[int(k)]
        fc = frame_cells(P, im.R, im.C, cam, setup.max_view, index=cells, box=padded[r])
        if not len(fc):
            return
        # median distance from a regular subsample (the buffer scale and image level need no more)
        gsd = float(np.median(fc.dist[:: max(1, len(fc) // 4096)])) / cam.fx
        scale = min(1.0, setup.oversample * gsd / res) if setup.visibility else 1.0
        zb = win = None
        if setup.visibility:
            bw = max(1, int(round(cam.width * scale)))
            bh = max(1, int(round(cam.height * scale)))
            x0 = max(int(math.floor((float(fc.u.min()) + 0.5) * scale - 0.5)) - 2, 0)
            y0 = max(int(math.floor((float(fc.v.min()) + 0.5) * scale - 0.5)) - 2, 0)
            x1 = min(int(math.ceil((float(fc.u.max()) + 0.5) * scale - 0.5)) + 2, bw - 1)
            y1 = min(int(math.ceil((float(fc.v.max()) + 0.5) * scale - 0.5)) + 2, bh - 1)
            win = (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
            zb = render_depth(tris, im.R, im.C, cam, win, scale)
        # one fused pass: depth test, near-occluder test, incidence, effective resolution, sample
        # coordinates (the nearest pixel next to an occluder instead of a bilinear mix with it)
        counts[r] = view_cells_into(
            fc,
            P,
            S,
            moved_flat,
            normals,
            im.R,
            im.C,
            cam,
            zb,
            win,
            scale,
            res,
            (usable[r], edge[r], uv[r], eff[r]),
            setup.tol_factor,
            setup.visibility,
            near_field=near_field,
            noise=noise,
            ray_grid=ray_grid,
        )
        gsd_all[r] = gsd

    clean_count = np.zeros(n, np.int32)
    cells = vidx
    # lazy: fixed batches, so the result does not depend on the threads; else all in one batch
    batch = LAZY_BATCH if setup.views_per_cell > 0 else max(len(order), 1)
    pool = None
    if workers > 1 and len(order) > 1:
        from concurrent.futures import ThreadPoolExecutor

        pool = ThreadPoolExecutor(max_workers=workers)
    try:
        for b0 in range(0, len(order), batch):
            ks = order[b0 : b0 + batch]
            if pool is not None and len(ks) > 1:
                list(pool.map(one, ks, [cells] * len(ks)))
            else:
                for k in ks:
                    one(k, cells)
            if setup.views_per_cell > 0:
                for k in ks:
                    r = row_of[int(k)]
                    if counts[r]:
                        clean_count += usable[r] & ~edge[r]
                cells = cells[clean_count[cells] < setup.views_per_cell]
                if not len(cells):
                    break
    finally:
        if pool is not None:
            pool.shutdown()
    keep = np.flatnonzero(counts > 0)
    if not len(keep):
        return empty
    if len(keep) < Kc:
        usable, edge, uv, eff = usable[keep], edge[keep], uv[keep], eff[keep]
    K = len(keep)
    usable = usable.reshape(K, rows, cols)
    edge = edge.reshape(K, rows, cols)
    uv = uv.reshape(K, rows, cols, 2)
    eff = eff.reshape(K, rows, cols)
    gsd = gsd_all[keep]
    cands = cand_sorted[keep]
    top = None
    if setup.top_views > 0 and K > setup.top_views:
        # candidates among the best ``top_views`` of no cell are dropped (by prune_views): a cell
        # starts from its best image (or its roof's), and a seam move only takes a neighbour's label
        top = np.zeros(K, np.bool_)
        _mark_top(eff, usable, int(setup.top_views), top)
    return TileViews(outer, h, cands, usable, edge, uv, eff, gsd, 0 if tris is None else len(tris), top)


def _ray_grid(hreg: np.ndarray, margin: int, lx: np.ndarray, ly: np.ndarray, res: float, z_off: float):
    """The ``ray_grid`` of :func:`~.zbuffer.view_cells_into` for a tile: the region's heights in the
    local frame, the tile's offset in it, and the turn of local plan directions into columns and rows
    (the local steps of one column and one row, from the tile's corners; exact when the output CRS is
    the orientation's)."""
    rows, cols = lx.shape
    step_c = np.array([res, 0.0])
    step_r = np.array([0.0, -res])
    if cols > 1:
        step_c = np.array([lx[0, -1] - lx[0, 0], ly[0, -1] - ly[0, 0]]) / (cols - 1)
    if rows > 1:
        step_r = np.array([lx[-1, 0] - lx[0, 0], ly[-1, 0] - ly[0, 0]]) / (rows - 1)
    inv = np.linalg.inv(np.column_stack([step_c, step_r]))
    hz = hreg - z_off
    finite = np.isfinite(hz)
    top = float(hz[finite].max()) if finite.any() else 0.0
    return hz, int(margin), inv, top


@njit
def _mark_top(eff, usable, m, out):
    """``out[k]`` = candidate k has one of the ``m`` smallest ``eff`` among the usable at some cell."""
    K, rows, cols = usable.shape
    buf = np.empty(m)
    for r in range(rows):
        for c in range(cols):
            n = 0  # the m smallest values so far, sorted, in buf[:n]
            for k in range(K):
                if not usable[k, r, c]:
                    continue
                v = eff[k, r, c]
                if n == m and v >= buf[m - 1]:
                    continue
                j = n if n < m else m - 1
                while j > 0 and buf[j - 1] > v:
                    buf[j] = buf[j - 1]
                    j -= 1
                buf[j] = v
                if n < m:
                    n += 1
            if n == 0:
                continue
            thr = buf[n - 1]
            for k in range(K):
                if usable[k, r, c] and eff[k, r, c] <= thr:
                    out[k] = True
