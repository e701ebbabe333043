"""The surface a true orthophoto is draped on: a DSM raster, an in-memory grid or a mesh.

Every surface answers two questions for a window of the output grid:

* :meth:`heights_on` -- the surface height (world z) at every cell centre, NaN
  where the surface has no data. A DSM is resampled onto the grid with
  *nearest* neighbour (a point sample of the cell the centre falls in, so
  building outlines stay sharp), bilinearly when it is more than 1.5 times
  coarser than the cells (:func:`_resampling`); a mesh is rasterised from
  above (highest face at the cell centre).
* :meth:`triangles` -- the occluding surface in the orientation's local frame
  for the depth buffers (:mod:`.zbuffer`): for a DSM the cell tops and walls of
  the resampled heights (:func:`~.zbuffer.dsm_triangles`), for a mesh its own
  faces in the window.

Heights are used as they are: DSM/mesh heights and the orientation's heights
must refer to the same vertical datum (only plan coordinates are reprojected).

A mesh is anything with ``vertices`` ((N, 3) float64 world coordinates),
``faces`` ((M, 3) int) and ``crs`` (e.g. ``core.surface.meshio.read_mesh``'s
``Mesh``); :func:`open_surface` accepts a path to a GeoTIFF DSM or to a PLY/OBJ
mesh (read through ``core.surface.meshio`` when that module is present).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..errors import CRSError, FormatError, InputError, MissingFileError
from ..grid import RasterGrid
from ..jit import njit
from .zbuffer import Triangles, dsm_triangles

MESH_EXTENSIONS = (".ply", ".obj")


class PlanTransform:
    """Plan coordinates of the output CRS -> the orientation's local frame.

    ``identity`` when both CRSs are the same: ``local = world - offset``;
    otherwise pyproj (always x = east, y = north) then the offset. Heights are
    not transformed.
    """

    def __init__(self, src_crs: str | None, dst_crs: str | None, offset) -> None:
        self.offset = np.asarray(offset, dtype=np.float64).reshape(3)
        self.src_crs = src_crs
        self.dst_crs = dst_crs
        self._tr = None
        if src_crs is not None and dst_crs is not None and not same_crs(src_crs, dst_crs):
            from pyproj import Transformer
            from pyproj.exceptions import ProjError

            from ..geometry.frame import parse_crs

            try:
                self._tr = Transformer.from_crs(parse_crs(src_crs), parse_crs(dst_crs), always_xy=True)
            except ProjError as exc:
                raise CRSError(
                    f"CRS: no transformation from {_short(src_crs)} to {_short(dst_crs)} ({exc})"
                ) from None

    def __getstate__(self):
        # pyproj transformers are rebuilt where the object is unpickled (a Dask worker)
        return {"offset": self.offset, "src_crs": self.src_crs, "dst_crs": self.dst_crs}

    def __setstate__(self, state) -> None:
        self.__init__(state["src_crs"], state["dst_crs"], state["offset"])  # type: ignore[misc]

    @property
    def identity(self) -> bool:
        return self._tr is None

    def xy(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Local plan coordinates of output-CRS points (arrays of any shape)."""
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        if self._tr is not None:
            from pyproj.exceptions import ProjError

            try:
                xx, yy = self._tr.transform(x, y, errcheck=True)
            except ProjError as exc:
                raise CRSError(
                    f"CRS: cannot transform points from {_short(self.src_crs)} to "
                    f"{_short(self.dst_crs)} ({exc})"
                ) from None
            x, y = np.asarray(xx, dtype=np.float64), np.asarray(yy, dtype=np.float64)
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
                raise CRSError(
                    f"CRS: the transformation from {_short(self.src_crs)} to {_short(self.dst_crs)} "
                    "gives no finite coordinates for the extent"
                )
        return x - self.offset[0], y - self.offset[1]

    def vertices(self, v: np.ndarray) -> np.ndarray:
        """(N, 3) output-CRS world vertices -> local vertices."""
        x, y = self.xy(v[:, 0], v[:, 1])
        return np.column_stack([x, y, v[:, 2] - self.offset[2]])


def same_crs(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    if a == b:
        return True
    from ..geometry.frame import parse_crs

    return bool(parse_crs(a).equals(parse_crs(b), ignore_axis_order=True))


def _short(crs) -> str:
    s = str(crs)
    return repr(s if len(s) < 60 else s[:57] + "...")


def transform_bounds(bounds, src_crs, dst_crs, densify: int = 21):
    """Bounding box of ``bounds = (xmin, ymin, xmax, ymax)`` from ``src_crs`` in ``dst_crs``."""
    if src_crs is None or dst_crs is None or same_crs(src_crs, dst_crs):
        return tuple(float(v) for v in bounds)
    from pyproj import Transformer
    from pyproj.exceptions import ProjError

    from ..geometry.frame import parse_crs

    try:
        tr = Transformer.from_crs(parse_crs(src_crs), parse_crs(dst_crs), always_xy=True)
        x0, y0, x1, y1 = (float(v) for v in bounds)
        out = tr.transform_bounds(x0, y0, x1, y1, densify_pts=densify, errcheck=True)
    except ProjError as exc:
        raise CRSError(
            f"CRS: no transformation from {_short(src_crs)} to {_short(dst_crs)} ({exc})"
        ) from None
    if not all(math.isfinite(v) for v in out):
        raise CRSError(f"CRS: no transformation from {_short(src_crs)} to {_short(dst_crs)} for {bounds}")
    return tuple(float(v) for v in out)


# ------------------------------------------------------------------ DSM raster


class DsmSurface:
    """A DSM GeoTIFF (any CRS, any resolution), read window by window.

    Parameters
    ----------
    path : str
    band : int
        1-based band holding the heights.
    name : str
        How errors name the input (the Processing parameter).
    """

    kind = "dsm"

    def __init__(self, path, band: int = 1, name: str = "SURFACE") -> None:
        import rasterio

        self.path = os.fspath(path)
        self.name = name
        if not os.path.isfile(self.path):
            raise MissingFileError(self.path, f"{name}: DSM file not found")
        try:
            with rasterio.open(self.path) as ds:
                self.crs = _crs_text(ds.crs)
                self.bounds = tuple(ds.bounds)
                self.res = float(abs(ds.transform.a))
                self.nodata = ds.nodata
                self.shape = (ds.height, ds.width)
                count = ds.count
                dtype = ds.dtypes[band - 1] if 1 <= band <= ds.count else None
        except rasterio.errors.RasterioIOError as exc:
            raise FormatError(self.path, f"{name}: not a readable raster ({exc})") from None
        if not 1 <= band <= count:
            raise InputError(f"{name}: band {band} does not exist in {self.path} ({count} band(s))")
        if dtype is not None and np.dtype(dtype).kind not in "uif":
            raise InputError(f"{name}: {self.path} band {band} is not numeric")
        self.band = band
        self._range: tuple[float, float] | None = None
        self._array: np.ndarray | None = None

    #: A DSM of at most this many cells is kept in memory once read (8 B per cell).
    memory_cells = 16_000_000

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_array"] = None  # a worker reads its own copy
        return state

    def height_range(self) -> tuple[float, float]:
        """(min, max) of the valid heights, read in strips (bounded memory)."""
        if self._range is None:
            import rasterio
            from rasterio.windows import Window

            lo, hi = np.inf, -np.inf
            with rasterio.open(self.path) as ds:
                step = max(1, 4_000_000 // max(ds.width, 1))
                for r0 in range(0, ds.height, step):
                    a = ds.read(
                        self.band, window=Window(0, r0, ds.width, min(step, ds.height - r0)), masked=True
                    ).astype(np.float64)
                    v = a.compressed() if np.ma.isMaskedArray(a) else np.ravel(a)
                    v = v[np.isfinite(v)]
                    if len(v):
                        lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
            if not np.isfinite(lo):
                raise InputError(f"{self.name}: {self.path} holds no valid height")
            self._range = (lo, hi)
        return self._range

    def heights_on(self, grid: RasterGrid) -> np.ndarray:
        """World heights (rows, cols) float64 at the cell centres of ``grid`` (NaN = no data).

        Resampled as :func:`_resampling` says.
        """
        import rasterio
        from rasterio.warp import reproject

        dst = np.full(grid.shape, np.nan, np.float64)
        with rasterio.open(self.path) as ds:
            win = _aligned_offset(ds.transform, self.crs, grid)
            if win is not None:  # same CRS and cells: no resampling
                if ds.width * ds.height <= self.memory_cells:
                    # a DSM this small is read once and kept (tiles read overlapping regions of it)
                    if self._array is None:
                        self._array = _read_heights(ds, self.band)
                    full = self._array
                    return _paste(dst, win, full.shape, lambda a0, b0, a1, b1: full[a0:a1, b0:b1])
                return _paste(
                    dst,
                    win,
                    (ds.height, ds.width),
                    lambda a0, b0, a1, b1: _read_heights(ds, self.band, (a0, b0, a1, b1)),
                )
            try:
                reproject(
                    source=rasterio.band(ds, self.band),
                    destination=dst,
                    src_nodata=ds.nodata,
                    dst_transform=grid.transform,
                    dst_crs=_crs_obj(grid.crs or self.crs),
                    dst_nodata=np.nan,
                    resampling=_resampling(self, grid),
                )
            except Exception as exc:
                raise CRSError(
                    f"{self.name}: cannot resample {self.path} onto the output grid ({exc})"
                ) from None
        dst[~np.isfinite(dst)] = np.nan
        return dst

    def triangles(
        self, grid: RasterGrid, heights: np.ndarray, include, to_local: PlanTransform, wall_min: float
    ) -> Triangles:
        return grid_triangles(grid, heights, include, to_local, wall_min)


class ArraySurface(DsmSurface):
    """A height grid in memory (world heights on ``grid``; NaN = no data), e.g. a truth DSM."""

    kind = "dsm"

    def __init__(self, heights, grid: RasterGrid, name: str = "SURFACE") -> None:
        h = np.asarray(heights, dtype=np.float64)
        if h.shape != grid.shape:
            raise InputError(f"{name}: heights of shape {h.shape} for a grid of {grid.shape}")
        self.h = h
        self.grid = grid
        self.name = name
        self.path = f"<{name} array>"
        self.crs = grid.crs
        self.bounds = grid.extent
        self.res = grid.res
        self._range = None
        self._file: str | None = None

    def height_range(self) -> tuple[float, float]:
        v = self.h[np.isfinite(self.h)]
        if not len(v):
            raise InputError(f"{self.name}: no valid height")
        return float(v.min()), float(v.max())

    def heights_on(self, grid: RasterGrid) -> np.ndarray:
        win = _aligned_offset(self.grid.transform, self.crs, grid)
        if win is not None:
            out = np.full(grid.shape, np.nan)
            return _paste(out, win, self.h.shape, lambda a0, b0, a1, b1: self.h[a0:a1, b0:b1])
        from rasterio.warp import reproject

        dst = np.full(grid.shape, np.nan, np.float64)
        try:
            reproject(
                source=self.h,
                destination=dst,
                src_transform=self.grid.transform,
                src_crs=_crs_obj(self.crs),
                src_nodata=np.nan,
                dst_transform=grid.transform,
                dst_crs=_crs_obj(grid.crs or self.crs),
                dst_nodata=np.nan,
                resampling=_resampling(self, grid),
            )
        except Exception as exc:
            raise CRSError(f"{self.name}: cannot resample the heights onto the output grid ({exc})") from None
        return dst


def _aligned_offset(t, crs, grid: RasterGrid) -> tuple[int, int] | None:
    """(row, col) of ``grid``'s first cell in a raster of transform ``t`` and CRS ``crs`` when both
    share CRS, cell size and cell edges (north-up), else None."""
    if not (t.b == 0 and t.d == 0 and t.e < 0) or not same_crs(grid.crs or crs, crs):
        return None
    if not (math.isclose(t.a, grid.res, rel_tol=1e-9) and math.isclose(-t.e, grid.res, rel_tol=1e-9)):
        return None
    fr = (t.f - grid.y_max) / grid.res
    fc = (grid.x_min - t.c) / grid.res
    if abs(fr - round(fr)) > 1e-6 or abs(fc - round(fc)) > 1e-6:
        return None
    return int(round(fr)), int(round(fc))


def _paste(dst: np.ndarray, offset: tuple[int, int], src_shape: tuple[int, ...], read) -> np.ndarray:
    """Fill ``dst`` (a grid starting at ``offset`` of a source of ``src_shape``) with
    ``read(r0, c0, r1, c1)`` of the overlapping source rows/cols; the rest stays as it is."""
    r0, c0 = offset
    rows, cols = dst.shape
    rs0, cs0 = max(r0, 0), max(c0, 0)
    rs1, cs1 = min(r0 + rows, src_shape[0]), min(c0 + cols, src_shape[1])
    if rs1 > rs0 and cs1 > cs0:
        dst[rs0 - r0 : rs1 - r0, cs0 - c0 : cs1 - c0] = read(rs0, cs0, rs1, cs1)
    return dst


def _read_heights(ds, band: int, window: tuple[int, int, int, int] | None = None) -> np.ndarray:
    """Heights of an open raster (or of rows r0:r1, cols c0:c1) as float64, NaN for nodata."""
    from rasterio.windows import Window

    win = (
        None if window is None else Window(window[1], window[0], window[3] - window[1], window[2] - window[0])
    )
    a = ds.read(band, window=win).astype(np.float64)
    if ds.nodata is not None:
        a[a == ds.nodata] = np.nan
    a[~np.isfinite(a)] = np.nan
    return a


def _resampling(surface, grid: RasterGrid):
    """Nearest neighbour (sharp outlines) unless the DSM is much coarser than the output grid.

    A DSM more than 1.5 times coarser than the cells is interpolated bilinearly:
    nearest neighbour would turn every slope into blocks of output cells with
    artificial steps (walls in the depth buffers, occluded stripes behind them),
    and such a DSM has no outline sharper than its own cells anyway.
    """
    from rasterio.enums import Resampling

    res = getattr(surface, "res", None)
    if res and same_crs(surface.crs, grid.crs) and res > 1.5 * grid.res:
        return Resampling.bilinear
    return Resampling.nearest


@njit
def _step_tops(h, wall_min, ring, out):
    """Cells within ``ring`` 4-neighbour steps (Manhattan distance) of a height step above ``wall_min``."""
    rows, cols = h.shape
    for r in range(rows):
        for c in range(cols):
            step = False
            if c + 1 < cols and abs(h[r, c + 1] - h[r, c]) > wall_min:
                step = True
            elif c > 0 and abs(h[r, c - 1] - h[r, c]) > wall_min:
                step = True
            elif r + 1 < rows and abs(h[r + 1, c] - h[r, c]) > wall_min:
                step = True
            elif r > 0 and abs(h[r - 1, c] - h[r, c]) > wall_min:
                step = True
            if not step:
                continue
            for dr in range(-ring, ring + 1):
                rr = r + dr
                if rr < 0 or rr >= rows:
                    continue
                w = ring - abs(dr)
                for cc in range(max(c - w, 0), min(c + w + 1, cols)):
                    out[rr, cc] = True


def grid_triangles(
    grid: RasterGrid, heights: np.ndarray, include, to_local: PlanTransform, wall_min: float, ring: int = 2
) -> Triangles:
    """Occluders of heights on an output-grid window, in the local frame.

    The walls (steps above ``wall_min``) and the tops of the cells within
    ``ring`` cells of such a step, rendered double-sided: enough for the
    visibility of the DSM's own cells (:func:`~.zbuffer.dsm_triangles`), far
    fewer triangles than every cell top.
    """
    h = np.ascontiguousarray(heights, dtype=np.float64)
    tops = np.zeros(h.shape, np.bool_)
    _step_tops(h, float(wall_min), int(max(ring, 0)), tops)
    if to_local.identity:
        o = to_local.offset
        return dsm_triangles(
            heights - o[2], grid.x_min - o[0], grid.y_max - o[1], grid.res, include, wall_min, tops
        )
    tris = dsm_triangles(heights, grid.x_min, grid.y_max, grid.res, include, wall_min, tops)
    v = to_local.vertices(tris.vertices) if len(tris.vertices) else tris.vertices
    return Triangles(v, tris.faces, tris.oriented, tris.groups)


# ------------------------------------------------------------------ mesh


@njit
def _top_raster(vx, vy, vz, faces, out):
    """Highest face at every cell centre; vertex plan coordinates in fractional cells (col, row)."""
    rows = out.shape[0]
    cols = out.shape[1]
    for f in range(faces.shape[0]):
        a = faces[f, 0]
        b = faces[f, 1]
        c = faces[f, 2]
        ua, va, za = vx[a], vy[a], vz[a]
        ub, vb, zb = vx[b], vy[b], vz[b]
        uc, vc, zc = vx[c], vy[c], vz[c]
        area = (ub - ua) * (vc - va) - (uc - ua) * (vb - va)
        if area == 0.0:
            continue
        i0 = max(np.int64(math.ceil(min(ua, min(ub, uc)))), 0)
        i1 = min(np.int64(math.floor(max(ua, max(ub, uc)))), cols - 1)
        j0 = max(np.int64(math.ceil(min(va, min(vb, vc)))), 0)
        j1 = min(np.int64(math.floor(max(va, max(vb, vc)))), rows - 1)
        inv = 1.0 / area
        for j in range(j0, j1 + 1):
            for i in range(i0, i1 + 1):
                w0 = ((ub - i) * (vc - j) - (uc - i) * (vb - j)) * inv
                w1 = ((uc - i) * (va - j) - (ua - i) * (vc - j)) * inv
                w2 = 1.0 - w0 - w1
                if w0 < -1e-9 or w1 < -1e-9 or w2 < -1e-9:
                    continue
                z = w0 * za + w1 * zb + w2 * zc
                if not (out[j, i] >= z):
                    out[j, i] = z


@dataclass
class MeshSurface:
    """A triangle mesh: world vertices (N, 3) in ``crs``, faces (M, 3).

    Heights on a grid are the highest face at each cell centre; the depth
    buffers use the faces themselves, without back-face culling (the winding of
    meshes from other tools is not trusted).
    """

    vertices: np.ndarray
    faces: np.ndarray
    crs: str | None = None
    name: str = "SURFACE"
    kind: str = "mesh"

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(np.asarray(self.vertices, dtype=np.float64))
        f = np.ascontiguousarray(np.asarray(self.faces, dtype=np.int64))
        if v.ndim != 2 or v.shape[1] != 3 or not len(v) or not np.all(np.isfinite(v)):
            raise InputError(f"{self.name}: mesh vertices must be finite (N, 3) coordinates")
        if f.ndim != 2 or f.shape[1] != 3 or not len(f) or f.min() < 0 or f.max() >= len(v):
            raise InputError(f"{self.name}: mesh faces must be (M, 3) vertex indices in range")
        self.vertices = v
        self.faces = f.astype(np.int32)
        lo, hi = v.min(axis=0), v.max(axis=0)
        self.bounds = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        self.res = None
        self._cache: dict = {}

    @property
    def path(self) -> str:
        return f"<{self.name} mesh>"

    def height_range(self) -> tuple[float, float]:
        return float(self.vertices[:, 2].min()), float(self.vertices[:, 2].max())

    def _in_crs(self, crs) -> np.ndarray:
        key = ("crs", str(crs))
        if key not in self._cache:
            if crs is None or self.crs is None or same_crs(crs, self.crs):
                self._cache[key] = self.vertices
            else:
                t = PlanTransform(self.crs, crs, np.zeros(3))
                self._cache[key] = t.vertices(self.vertices)
        return self._cache[key]

    def heights_on(self, grid: RasterGrid) -> np.ndarray:
        v = self._in_crs(grid.crs)
        out = np.full(grid.shape, np.nan)
        col = (v[:, 0] - grid.x_min) / grid.res - 0.5
        row = (grid.y_max - v[:, 1]) / grid.res - 0.5
        sel = self._faces_in(col, row, 0, 0, grid.cols, grid.rows)
        _top_raster(
            np.ascontiguousarray(col),
            np.ascontiguousarray(row),
            np.ascontiguousarray(v[:, 2]),
            self.faces[sel],
            out,
        )
        return out

    def _faces_in(self, col, row, c0, r0, c1, r1) -> np.ndarray:
        fc = col[self.faces]
        fr = row[self.faces]
        return (
            (fc.max(axis=1) >= c0 - 1)
            & (fc.min(axis=1) <= c1)
            & (fr.max(axis=1) >= r0 - 1)
            & (fr.min(axis=1) <= r1)
        )

    def triangles(
        self, grid: RasterGrid, heights: np.ndarray, include, to_local: PlanTransform, wall_min: float
    ) -> Triangles:
        v = self._in_crs(grid.crs)
        col = (v[:, 0] - grid.x_min) / grid.res - 0.5
        row = (grid.y_max - v[:, 1]) / grid.res - 0.5
        sel = self._faces_in(col, row, 0, 0, grid.cols, grid.rows)
        faces = self.faces[sel]
        used, inv = np.unique(faces, return_inverse=True)
        verts = to_local.vertices(v[used]) if len(used) else np.zeros((0, 3))
        tris = Triangles(verts, inv.reshape(-1, 3).astype(np.int32), oriented=False)
        if not len(faces):
            return tris
        # faces grouped by blocks of 32 x 32 cells (of their first vertex), so depth buffers skip
        # the blocks outside their window
        gc = np.clip(col[faces[:, 0]], 0, grid.cols - 1).astype(np.int64) // 32
        gr = np.clip(row[faces[:, 0]], 0, grid.rows - 1).astype(np.int64) // 32
        return tris.grouped(gr * (-(-grid.cols // 32)) + gc)


# ------------------------------------------------------------------ opening


def open_surface(surface, name: str = "SURFACE"):
    """A surface object from a path (GeoTIFF DSM, PLY/OBJ mesh) or an existing surface/mesh object."""
    if isinstance(surface, DsmSurface | MeshSurface):
        return surface
    if hasattr(surface, "vertices") and hasattr(surface, "faces"):
        return MeshSurface(surface.vertices, surface.faces, getattr(surface, "crs", None), name)
    if not isinstance(surface, str | os.PathLike):
        raise InputError(
            f"{name}: expected a DSM GeoTIFF, a PLY/OBJ mesh or a mesh object, got {type(surface).__name__}"
        )
    p = os.fspath(surface)
    if p.lower().endswith(MESH_EXTENSIONS):
        if not os.path.isfile(p):
            raise MissingFileError(p, f"{name}: mesh file not found")
        try:
            from ..surface.meshio import read_mesh  # type: ignore[import-not-found]
        except ImportError:
            raise InputError(
                f"{name}: reading PLY/OBJ meshes needs core/surface/meshio.py, which this "
                "installation lacks; give a DSM GeoTIFF instead"
            ) from None
        m = read_mesh(p)
        return MeshSurface(m.vertices, m.faces, getattr(m, "crs", None), name)
    if not p.lower().endswith((".tif", ".tiff", ".vrt", ".img")):
        raise InputError(f"{name}: {p!r} is neither a DSM raster (.tif) nor a mesh (.ply, .obj)")
    return DsmSurface(p, name=name)


def _crs_text(crs) -> str | None:
    if crs is None:
        return None
    auth = crs.to_authority()
    return f"{auth[0]}:{auth[1]}" if auth and crs.to_epsg() is not None else crs.to_wkt()


def _crs_obj(crs):
    if crs is None:
        return None
    from rasterio.crs import CRS

    try:
        return CRS.from_user_input(crs)
    except Exception as exc:
        raise CRSError(f"cannot use the CRS {_short(crs)} ({exc})") from None
