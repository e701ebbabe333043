"""Raster and point-cloud files, always written atomically.

Every product is first written to a temporary file beside its destination
(``.<name>.tmp<pid>...``) and renamed into place only when complete, so a
failure or a cancel never leaves a half-written output (and never destroys an
older file of the same name before the new one is ready).

* :class:`RasterWriter`: a GeoTIFF written window by window (tiles), with CRS,
  nodata, band descriptions, optional internal overviews and an optional
  Cloud-Optimized GeoTIFF layout (GDAL's COG driver) on completion.
* :func:`write_raster`: a whole array at once (through :class:`RasterWriter`).
* :func:`read_raster`, :func:`raster_grid`, :func:`read_onto_grid`: read a raster
  as stored, or resampled/reprojected onto a :class:`~.grid.RasterGrid`.
* :func:`write_point_cloud` and :class:`PointCloudWriter` (in chunks): LAS 1.4 /
  LAZ with RGB, extra dimensions, extra VLRs and the CRS as WKT;
  :func:`read_point_cloud_arrays` reads them back.
* :func:`write_seamlines`: the true orthophoto's seamline polygons as a GeoPackage.

GDAL-linked packages come from the same distribution as QGIS (docs/install.md,
"Dependency policy"); rasterio is imported lazily.
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .errors import CRSError, FormatError, InputError, MissingFileError
from .grid import RasterGrid

RASTER_EXTENSIONS = (".tif", ".tiff")
POINT_CLOUD_EXTENSIONS = (".las", ".laz")


def temporary_path(path: str | os.PathLike) -> Path:
    """A temporary sibling of ``path`` with the same suffix (hidden, pid-tagged)."""
    p = Path(path)
    return p.with_name(f".{p.stem}.tmp{os.getpid()}{p.suffix}")


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike):
    """Yield a temporary path; rename it onto ``path`` only if the block succeeds.

    Auxiliary files GDAL may create beside the temporary file (``.aux.xml``,
    ``.ovr``) are removed as well.
    """
    dest = Path(path)
    if dest.parent and not dest.parent.exists():
        dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = temporary_path(dest)
    try:
        yield tmp
        os.replace(tmp, dest)
    finally:
        for p in (tmp, Path(str(tmp) + ".aux.xml"), Path(str(tmp) + ".ovr")):
            with contextlib.suppress(FileNotFoundError):
                p.unlink()


def _check_raster_path(path, what: str = "output") -> Path:
    p = Path(os.fspath(path))
    if p.suffix.lower() not in RASTER_EXTENSIONS:
        raise InputError(f"{what} {str(p)!r}: expected a GeoTIFF file name ending in .tif or .tiff")
    return p


def _crs_object(crs):
    if crs is None:
        return None
    from rasterio.crs import CRS
    from rasterio.errors import CRSError as _RioCRSError

    try:
        return CRS.from_user_input(crs)
    except (_RioCRSError, ValueError, TypeError) as exc:
        raise CRSError(f"cannot use the CRS {str(crs)[:80]!r} for a raster: {exc}") from None


#: the compressions :class:`RasterWriter` writes (``"jpeg"``: lossy, 8-bit, COG only)
COMPRESSIONS = ("deflate", "zstd", "lzw", "jpeg", "none")

#: ZSTD's level in the products: the fastest (a 4x-scene true ortho wrote in 0.18-0.26 s against
#: 0.51 s for DEFLATE at GDAL's default level 6, and 9 % larger)
ZSTD_LEVEL = 1

_ZSTD: list[bool] = []


def _has_zstd() -> bool:
    """Whether GDAL's GTiff driver writes ZSTD (probed once, in memory)."""
    if not _ZSTD:
        import rasterio
        from rasterio.shutil import delete

        path = f"/vsimem/truortho_zstd_probe_{os.getpid()}_{id(_ZSTD)}.tif"
        ok = False
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # not georeferenced
                with rasterio.open(
                    path, "w", driver="GTiff", width=16, height=16, count=1, dtype="uint8", compress="zstd"
                ) as ds:
                    ds.write(np.ones((1, 16, 16), np.uint8))
                with rasterio.open(path) as ds:
                    comp = ds.compression
                    ok = comp is not None and comp.name.lower() == "zstd" and bool(ds.read(1).all())
        except Exception:
            ok = False
        finally:
            with contextlib.suppress(Exception):
                delete(path)
        if not _ZSTD:
            _ZSTD.append(ok)
    return _ZSTD[0]


class RasterWriter:
    """A GeoTIFF written by windows, renamed into place on success.

    Use as a context manager::

        with RasterWriter(path, grid, bands=1, dtype="float32", nodata=-9999) as w:
            for tile in grid.tiles(512):
                w.write(values[tile.inner_slices], tile.core)

    Parameters
    ----------
    path : str or os.PathLike
        ``.tif`` destination.
    grid : RasterGrid
        Georeferencing (CRS from ``grid.crs``).
    bands : int
    dtype : numpy dtype name
    nodata : number or None
    descriptions : sequence of str, optional
        One description per band.
    photometric : str, optional
        ``"RGB"`` or ``"MINISBLACK"``; RGB(A) is set automatically for 3-4 uint8 bands.
    alpha : bool
        The last band is an alpha band (``ExtraSamples = unassociated alpha``).
    overviews : bool
        Build internal overviews (average, or nearest for integer classes when
        ``overview_resampling="nearest"``) when closing.
    cog : bool
        Rewrite as a Cloud-Optimized GeoTIFF (implies overviews).
    compress : str
        ``"deflate"`` (default, GDAL's level 6), ``"lzw"``, ``"zstd"`` (level 1, the fastest),
        ``"none"`` (lossless), or ``"jpeg"``
        (lossy; 8-bit RGB, optionally + alpha, and ``cog`` only: stored as YCbCr, and the alpha
        band becomes the file's internal mask, as GDAL's COG driver does).
    quality : int
        JPEG quality (1-100) of ``compress="jpeg"``.
    block : int
        Internal tile size (a multiple of 16).
    """

    def __init__(
        self,
        path,
        grid: RasterGrid,
        bands: int = 1,
        dtype="float32",
        nodata=None,
        descriptions: Sequence[str] | None = None,
        photometric: str | None = None,
        alpha: bool = False,
        overviews: bool = False,
        overview_resampling: str = "average",
        cog: bool = False,
        compress: str = "deflate",
        block: int = 256,
        quality: int = 90,
    ) -> None:
        self.path = _check_raster_path(path)
        if not isinstance(grid, RasterGrid):
            raise InputError(f"{self.path}: expected a RasterGrid, got {type(grid).__name__}")
        if not isinstance(bands, int) or bands < 1:
            raise InputError(f"{self.path}: band count must be a positive integer, got {bands!r}")
        if block % 16 or block < 16:
            raise InputError(f"{self.path}: block size must be a positive multiple of 16, got {block}")
        self.grid = grid
        self.bands = bands
        self.dtype = np.dtype(dtype)
        self.nodata = nodata
        self.descriptions = list(descriptions) if descriptions else None
        if self.descriptions is not None and len(self.descriptions) != bands:
            raise InputError(f"{self.path}: {len(self.descriptions)} band descriptions for {bands} bands")
        compress = (compress or "none").lower()
        if compress not in COMPRESSIONS:
            raise InputError(f"{self.path}: compression {compress!r} is not one of {', '.join(COMPRESSIONS)}")
        if compress == "zstd" and not _has_zstd():
            raise InputError(f"{self.path}: this GDAL cannot write ZSTD; use 'deflate' or 'lzw'")
        if compress == "jpeg":
            if self.dtype != np.uint8:
                raise InputError(
                    f"{self.path}: JPEG compression needs 8-bit data, got {self.dtype.name}; "
                    "use a lossless compression ('deflate', 'zstd' or 'lzw')"
                )
            if bands - int(bool(alpha)) != 3:
                raise InputError(
                    f"{self.path}: JPEG compression is for 3-band (RGB) data, got "
                    f"{bands - int(bool(alpha))} band(s); use a lossless compression"
                )
            if not cog:
                raise InputError(f"{self.path}: JPEG compression is written in the COG layout only")
            if isinstance(quality, bool) or not isinstance(quality, int) or not 1 <= quality <= 100:
                raise InputError(f"{self.path}: JPEG quality must be an integer in [1, 100], got {quality!r}")
        self.quality = quality
        self.overviews = overviews or cog
        self.overview_resampling = overview_resampling
        self.cog = cog
        self.compress = compress
        self.profile = {
            "driver": "GTiff",
            "width": grid.cols,
            "height": grid.rows,
            "count": bands,
            "dtype": self.dtype.name,
            "crs": _crs_object(grid.crs),
            "transform": grid.transform,
            "nodata": nodata,
            "tiled": True,
            "blockxsize": block,
            "blockysize": block,
            "BIGTIFF": "IF_SAFER",
        }
        if compress != "none":
            self.profile["compress"] = compress
            if compress in ("deflate", "lzw", "zstd"):
                self.profile["predictor"] = 3 if self.dtype.kind == "f" else 2
            self.profile["num_threads"] = "ALL_CPUS"  # GDAL compresses blocks in threads
            if compress == "zstd":
                self.profile["zstd_level"] = ZSTD_LEVEL
            if cog:
                # the temporary file is read once by the COG copy, which compresses again: the
                # fastest lossless codec this GDAL has (ZSTD level 1, else DEFLATE level 1)
                self.profile["predictor"] = 3 if self.dtype.kind == "f" else 2
                if _has_zstd():
                    self.profile["compress"] = "zstd"
                    self.profile["zstd_level"] = 1
                else:
                    self.profile["compress"] = "deflate"
                    self.profile["zlevel"] = 1
        if photometric is None and self.dtype == np.uint8 and bands in (3, 4):
            photometric = "RGB"
        if photometric:
            self.profile["photometric"] = photometric
        self.alpha = alpha
        self._tmp: Path | None = None
        self._ds: Any = None

    # ------------------------------------------------------------ context
    def __enter__(self) -> RasterWriter:
        import rasterio

        self._tmp = temporary_path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._ds = rasterio.open(self._tmp, "w", **self.profile)
        except Exception as exc:
            self._cleanup()
            raise FormatError(self.path, f"cannot create the raster ({exc})") from None
        if self.descriptions:
            for i, d in enumerate(self.descriptions, start=1):
                self._ds.set_band_description(i, d)
        if self.alpha:
            from rasterio.enums import ColorInterp

            if self.bands - 1 == 3:
                ci = [ColorInterp.red, ColorInterp.green, ColorInterp.blue]
            else:  # one band (panchromatic, thermal) or a multispectral stack: grey, not red
                ci = [ColorInterp.gray] * (self.bands - 1)
            self._ds.colorinterp = ci + [ColorInterp.alpha]
        return self

    def write(self, data: np.ndarray, window: tuple[int, int, int, int] | None = None) -> None:
        """Write ``data`` ((rows, cols) or (bands, rows, cols)) at ``window = (row0, col0, rows, cols)``."""
        if self._ds is None:
            raise InputError(f"{self.path}: RasterWriter.write outside its 'with' block")
        from rasterio.windows import Window

        a = np.asarray(data)
        if a.ndim == 2:
            a = a[None]
        if a.ndim != 3 or a.shape[0] != self.bands:
            raise InputError(
                f"{self.path}: expected {self.bands} band(s) of 2-D data, got shape {np.shape(data)}"
            )
        if window is None:
            window = (0, 0, self.grid.rows, self.grid.cols)
        r0, c0, nr, nc = (int(v) for v in window)
        if a.shape[1:] != (nr, nc):
            raise InputError(f"{self.path}: data of shape {a.shape[1:]} for a window of {nr} x {nc} cells")
        if r0 < 0 or c0 < 0 or r0 + nr > self.grid.rows or c0 + nc > self.grid.cols:
            raise InputError(
                f"{self.path}: window {window} outside the {self.grid.rows} x {self.grid.cols} grid"
            )
        self._ds.write(a.astype(self.dtype, copy=False), window=Window(c0, r0, nc, nr))

    def close(self) -> None:
        """Finish the file now (overviews, COG copy, rename into place), as a successful exit of
        the ``with`` block does; the exit after it does nothing more."""
        self.__exit__(None, None, None)

    def __exit__(self, exc_type, exc, tb) -> None:
        ds, self._ds = self._ds, None
        try:
            if exc_type is None and ds is not None and self._tmp is not None:
                if self.overviews:
                    self._build_overviews(ds)
                ds.close()
                if self.cog:
                    self._to_cog()
                os.replace(self._tmp, self.path)
            elif ds is not None:
                ds.close()
        finally:
            self._cleanup()

    # ------------------------------------------------------------ helpers
    def _build_overviews(self, ds) -> None:
        from rasterio.enums import Resampling

        factors = []
        f = 2
        while max(self.grid.rows, self.grid.cols) / f >= 256:
            factors.append(f)
            f *= 2
        if factors:
            ds.build_overviews(factors, getattr(Resampling, self.overview_resampling))
            ds.update_tags(ns="rio_overview", resampling=self.overview_resampling)

    def _to_cog(self) -> None:
        from rasterio.shutil import copy as rio_copy

        assert self._tmp is not None
        cog_tmp = self._tmp.with_name(self._tmp.stem + ".cog" + self._tmp.suffix)
        opts = {
            "compress": self.compress.upper(),
            "BIGTIFF": "IF_SAFER",
            "blocksize": self.profile["blockxsize"],
            "overview_resampling": self.overview_resampling.upper(),
        }
        if self.compress in ("deflate", "lzw", "zstd"):
            opts["predictor"] = "YES"
        if self.compress == "zstd":
            opts["level"] = str(ZSTD_LEVEL)
        elif self.compress == "jpeg":
            opts["quality"] = str(self.quality)  # RGB(A) -> YCbCr (+ mask from the alpha band)
        if "num_threads" in self.profile:
            opts["num_threads"] = "ALL_CPUS"
        try:
            rio_copy(self._tmp, cog_tmp, driver="COG", **opts)
            os.replace(cog_tmp, self._tmp)
        finally:
            with contextlib.suppress(FileNotFoundError):
                cog_tmp.unlink()

    def _cleanup(self) -> None:
        if self._tmp is not None:
            for p in (self._tmp, Path(str(self._tmp) + ".aux.xml"), Path(str(self._tmp) + ".ovr")):
                with contextlib.suppress(FileNotFoundError):
                    p.unlink()
            self._tmp = None


def write_raster(path, data: np.ndarray, grid: RasterGrid, nodata=None, **options) -> Path:
    """Write a whole raster ((rows, cols) or (bands, rows, cols)) atomically.

    ``options`` are those of :class:`RasterWriter`.
    """
    a = np.asarray(data)
    bands = 1 if a.ndim == 2 else a.shape[0]
    if a.shape[-2:] != grid.shape:
        raise InputError(f"{path}: data of shape {a.shape[-2:]} for a grid of {grid.shape}")
    options.setdefault("dtype", a.dtype)
    with RasterWriter(path, grid, bands=bands, nodata=nodata, **options) as w:
        w.write(a)
    return Path(path)


# ------------------------------------------------------------------ reading


def _open(path):
    import rasterio

    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MissingFileError(p, "raster file not found")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            return rasterio.open(p)
    except Exception as exc:
        raise FormatError(p, f"not a readable raster ({exc})") from None


def raster_grid(path, require_crs: bool = True) -> RasterGrid:
    """The :class:`RasterGrid` of a north-up raster file (CRS as WKT or ``AUTH:CODE``)."""
    with _open(path) as ds:
        crs = ds.crs
        if crs is None and require_crs:
            raise CRSError(f"{path}: the raster has no CRS; assign one (e.g. with gdal_edit.py -a_srs)")
        text = None
        if crs is not None:
            auth = crs.to_authority()
            text = f"{auth[0]}:{auth[1]}" if auth and crs.to_epsg() is not None else crs.to_wkt()
        try:
            return RasterGrid.from_geotransform(ds.transform.to_gdal(), ds.height, ds.width, text)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None


def read_raster(
    path, band: int | None = 1, window: tuple[int, int, int, int] | None = None, masked_to_nan: bool = True
):
    """Read a raster as stored.

    Parameters
    ----------
    band : int or None
        1-based band, or None for all bands ((bands, rows, cols)).
    window : (row0, col0, rows, cols), optional
    masked_to_nan : bool
        For float output: nodata cells become NaN.

    Returns
    -------
    (data, grid, nodata)
        ``grid`` is the grid of the window read; ``nodata`` the file's value.
    """
    from rasterio.windows import Window

    grid = raster_grid(path, require_crs=False)
    with _open(path) as ds:
        if band is not None and not 1 <= band <= ds.count:
            raise InputError(f"{path}: band {band} does not exist (the raster has {ds.count} band(s))")
        win = None
        if window is not None:
            r0, c0, nr, nc = window
            win = Window(c0, r0, nc, nr)
            grid = grid.window(r0, c0, nr, nc)
        data = ds.read(band, window=win) if band is not None else ds.read(window=win)
        nodata = ds.nodata
    if masked_to_nan and data.dtype.kind == "f" and nodata is not None and not np.isnan(nodata):
        data = np.where(data == nodata, np.float32(np.nan), data).astype(data.dtype)
    return data, grid, nodata


def read_preview(path, max_side: int = 1200, band: int | None = 1, resampling: str = "nearest"):
    """A raster reduced by a whole factor so that its larger side is at most ``max_side`` cells.

    GDAL reads it from the file's overviews when they exist, so the memory is that of the
    preview, not of the raster (a report of a large block never reads its full DSM).

    Returns
    -------
    (data, grid, nodata)
        As :func:`read_raster`; ``grid`` is the preview's (cells about ``factor`` times larger,
        with the raster's origin: for display, not for measuring).
    """
    import math

    from rasterio.enums import Resampling

    grid = raster_grid(path, require_crs=False)
    if max_side < 1:
        raise InputError(f"{path}: a preview needs max_side >= 1, got {max_side!r}")
    factor = max(1, math.ceil(max(grid.rows, grid.cols) / int(max_side)))
    if factor == 1:
        return read_raster(path, band)
    pg = grid.scaled(factor)
    with _open(path) as ds:
        if band is not None and not 1 <= band <= ds.count:
            raise InputError(f"{path}: band {band} does not exist (the raster has {ds.count} band(s))")
        bands = ds.count if band is None else 1
        data = ds.read(
            band if band is not None else None,
            out_shape=(bands, pg.rows, pg.cols) if band is None else (pg.rows, pg.cols),
            resampling=getattr(Resampling, resampling),
        )
        nodata = ds.nodata
    if data.dtype.kind == "f" and nodata is not None and not np.isnan(nodata):
        data = np.where(data == nodata, np.float32(np.nan), data).astype(data.dtype)
    return data, pg, nodata


def valid_share(path, band: int = 1, block: int = 1024) -> float:
    """Share of the cells of ``band`` that hold data (not nodata, not NaN), read window by window."""
    grid = raster_grid(path, require_crs=False)
    valid = 0
    for t in grid.tiles(block):
        data, _, nod = read_raster(path, band, t.core)  # float nodata arrives as NaN
        if data.dtype.kind == "f":
            valid += int(np.isfinite(data).sum())
        else:
            valid += int(data.size if nod is None else (data != nod).sum())
    return valid / max(grid.rows * grid.cols, 1)


def read_onto_grid(
    path, grid: RasterGrid, band: int = 1, resampling: str = "bilinear", dtype="float32"
) -> np.ndarray:
    """Resample (and reproject when the CRSs differ) one band onto ``grid``.

    Cells outside the raster or on its nodata become NaN (float output). Only the
    window of the raster that covers ``grid`` (plus a margin) is read.

    Raises
    ------
    CRSError
        The raster or the grid has no CRS, or no transformation exists between them.
    """
    from rasterio.enums import Resampling
    from rasterio.warp import reproject

    src_grid = raster_grid(path, require_crs=True)
    if grid.crs is None:
        raise CRSError("the target grid has no CRS")
    dst = np.full(grid.shape, np.nan, dtype=dtype)
    with _open(path) as ds:
        if not 1 <= band <= ds.count:
            raise InputError(f"{path}: band {band} does not exist (the raster has {ds.count} band(s))")
        try:
            src, src_transform = _source_window(ds, grid, band, dtype)
            if src is None:
                return dst
            reproject(
                source=src,
                destination=dst,
                src_transform=src_transform,
                src_crs=ds.crs,
                src_nodata=ds.nodata,
                dst_transform=grid.transform,
                dst_crs=_crs_object(grid.crs),
                dst_nodata=np.nan,
                resampling=getattr(Resampling, resampling),
            )
        except Exception as exc:
            raise CRSError(
                f"{path}: cannot transform from {src_grid.crs!r} to {grid.crs!r} ({exc})"
            ) from None
    return dst


def _source_window(ds, grid: RasterGrid, band: int, dtype):
    """The part of band ``band`` of ``ds`` covering ``grid`` (+ 3 pixels): ``(array, transform)``.

    ``(None, None)`` when the grid lies entirely outside the raster.
    """
    from rasterio.warp import transform_bounds
    from rasterio.windows import Window, from_bounds

    x0, y0, x1, y1 = grid.extent
    dst_crs = _crs_object(grid.crs)
    if ds.crs is not None and dst_crs is not None and ds.crs != dst_crs:
        x0, y0, x1, y1 = transform_bounds(dst_crs, ds.crs, x0, y0, x1, y1, densify_pts=21)
    win = from_bounds(x0, y0, x1, y1, transform=ds.transform)
    c0 = max(int(np.floor(win.col_off)) - 3, 0)
    r0 = max(int(np.floor(win.row_off)) - 3, 0)
    c1 = min(int(np.ceil(win.col_off + win.width)) + 3, ds.width)
    r1 = min(int(np.ceil(win.row_off + win.height)) + 3, ds.height)
    if c1 <= c0 or r1 <= r0:
        return None, None
    w = Window(c0, r0, c1 - c0, r1 - r0)
    return ds.read(band, window=w).astype(dtype), ds.window_transform(w)


# ------------------------------------------------------------------ point clouds


class PointCloudWriter:
    """A LAS 1.4 / LAZ file written in chunks, renamed into place on success.

    Point format 7 (RGB) or 6, 16-bit colours (8-bit input is scaled by 257),
    extra dimensions (LAS extra bytes) and the CRS as a WKT VLR (global
    encoding WKT bit set). Header bounds and counts are updated on closing.
    Use as a context manager::

        with PointCloudWriter(path, crs, rgb=True, extra={"confidence": "f4"},
                              offsets=(x0, y0, 0.0)) as w:
            for chunk in chunks:
                w.write(xyz, rgb, confidence=conf)

    Parameters
    ----------
    path : str or os.PathLike
        ``.las`` or ``.laz`` (compressed, LASzip via lazrs).
    crs : str, optional
    rgb : bool
        Whether points carry colours (point format 7, else 6).
    extra : dict name -> numpy dtype, optional
        Extra dimensions, in order.
    offsets : (3,) float, optional
        Coordinate offsets of the integer storage (default: from the first chunk).
    scale : float
        Coordinate resolution, metres.
    vlrs : sequence of (user_id, record_id, description, bytes), optional
        Additional variable-length records (e.g. TruOrtho's reference-system table).
    legacy : bool
        Write LAS point format 2 (RGB) or 0 instead of 7/6: the formats the LASzip
        decoder of older readers (QGIS 3.22's EPT provider) decompresses.
    """

    def __init__(
        self,
        path,
        crs: str | None = None,
        rgb: bool = False,
        extra: dict[str, Any] | None = None,
        offsets=None,
        scale: float = 0.001,
        vlrs: Sequence[tuple[str, int, str, bytes]] = (),
        legacy: bool = False,
    ) -> None:
        import laspy

        p = Path(os.fspath(path))
        if p.suffix.lower() not in POINT_CLOUD_EXTENSIONS:
            raise InputError(f"point cloud {str(p)!r}: expected a file name ending in .las or .laz")
        if not (np.isfinite(scale) and scale > 0):
            raise InputError(f"{p}: coordinate scale must be positive, got {scale!r}")
        self.path = p
        self.rgb = bool(rgb)
        self.extra = {str(k): np.dtype(v) for k, v in (extra or {}).items()}
        fmt = (2 if rgb else 0) if legacy else (7 if rgb else 6)
        header = laspy.LasHeader(point_format=fmt, version="1.4")
        header.scales = np.array([scale, scale, scale])
        for name, dt in self.extra.items():
            header.add_extra_dim(laspy.ExtraBytesParams(name=name, type=dt))
        if crs is not None:
            from .geometry.frame import parse_crs

            header.add_crs(parse_crs(crs))
        for user_id, record_id, description, data in vlrs:
            header.vlrs.append(
                laspy.VLR(user_id=user_id, record_id=record_id, description=description, record_data=data)
            )
        self.header = header
        self._offsets = None if offsets is None else np.asarray(offsets, dtype=np.float64).reshape(3)
        self._tmp: Path | None = None
        self._writer: Any = None
        self.count = 0

    def __enter__(self) -> PointCloudWriter:
        self._tmp = temporary_path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        return self

    def _open(self, first_xyz: np.ndarray) -> None:
        import laspy

        if self._offsets is None:
            self._offsets = np.floor(first_xyz.min(axis=0)) if len(first_xyz) else np.zeros(3)
        self.header.offsets = self._offsets
        try:
            self._writer = laspy.open(
                str(self._tmp), mode="w", header=self.header, do_compress=self.path.suffix.lower() == ".laz"
            )
        except Exception as exc:
            raise FormatError(self.path, f"cannot create the point cloud ({exc})") from None

    def write(self, xyz: np.ndarray, rgb: np.ndarray | None = None, **extra: np.ndarray) -> None:
        """Append points: ``xyz`` (N, 3) world, ``rgb`` (N, 3) uint8/uint16, extra dims (N,)."""
        import laspy

        if self._tmp is None:
            raise InputError(f"{self.path}: PointCloudWriter.write outside its 'with' block")
        pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        if not np.all(np.isfinite(pts)):
            raise InputError(f"{self.path}: point coordinates must be finite")
        n = len(pts)
        if self._writer is None:
            self._open(pts)
        if n == 0:
            return
        rec = laspy.ScaleAwarePointRecord.zeros(n, header=self.header)
        rec.x, rec.y, rec.z = pts[:, 0], pts[:, 1], pts[:, 2]
        if self.rgb:
            if rgb is None:
                raise InputError(f"{self.path}: this point cloud has colours; rgb is required")
            c = np.asarray(rgb).reshape(-1, 3)
            if len(c) != n:
                raise InputError(f"{self.path}: {len(c)} colours for {n} points")
            c16 = c.astype(np.uint16) * 257 if c.dtype == np.uint8 else c.astype(np.uint16)
            rec.red, rec.green, rec.blue = c16[:, 0], c16[:, 1], c16[:, 2]
        for name in self.extra:
            if name not in extra:
                raise InputError(f"{self.path}: extra dimension {name!r} missing from write()")
        for name, values in extra.items():
            if name not in self.extra:
                raise InputError(f"{self.path}: unknown extra dimension {name!r}")
            v = np.asarray(values)
            if v.shape != (n,):
                raise InputError(
                    f"{self.path}: extra dimension {name!r} has shape {v.shape}, expected ({n},)"
                )
            rec[name] = v.astype(self.extra[name])
        try:
            self._writer.write_points(rec)
        except Exception as exc:
            raise FormatError(self.path, f"cannot write the point cloud ({exc})") from None
        self.count += n

    def __exit__(self, exc_type, exc, tb) -> None:
        writer, self._writer = self._writer, None
        tmp, self._tmp = self._tmp, None
        try:
            if exc_type is None and tmp is not None:
                if writer is None:
                    self._open(np.zeros((0, 3)))
                    writer, self._writer = self._writer, None
                writer.close()
                os.replace(tmp, self.path)
            elif writer is not None:
                with contextlib.suppress(Exception):
                    writer.close()
        finally:
            if tmp is not None:
                with contextlib.suppress(FileNotFoundError):
                    tmp.unlink()


def write_point_cloud(
    path,
    xyz: np.ndarray,
    rgb: np.ndarray | None = None,
    crs: str | None = None,
    extra: dict[str, np.ndarray] | None = None,
    scale: float = 0.001,
) -> Path:
    """Write a LAS 1.4 (``.las``) or LAZ (``.laz``) file atomically.

    Parameters
    ----------
    xyz : (N, 3) float64
        World coordinates (CRS units).
    rgb : (N, 3) uint8 or uint16, optional
        Colours; 8-bit values are scaled to LAS's 16-bit range (x 257).
    crs : str, optional
        Written as a WKT CRS VLR (LAS 1.4 global encoding WKT bit set).
    extra : dict name -> (N,) array
        Extra dimensions (float32, uint8, uint16, int32 ...), e.g. ``confidence``.
    scale : float
        Coordinate resolution (metres).

    See :class:`PointCloudWriter` for writing in chunks.
    """
    extra = extra or {}
    pts = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    with PointCloudWriter(
        path, crs, rgb is not None, {k: np.asarray(v).dtype for k, v in extra.items()}, scale=scale
    ) as w:
        w.write(pts, rgb, **extra)
    return Path(os.fspath(path))


def read_point_cloud_arrays(path) -> dict[str, Any]:
    """Read a LAS/LAZ file: ``{"xyz", "rgb" (uint16 or None), "extra": {name: array}, "crs", "vlrs"}``.

    ``crs`` is the WKT of the file's CRS (None when it has none); ``vlrs`` maps
    ``(user_id, record_id)`` to the record bytes of the other VLRs.
    """
    import laspy

    p = os.fspath(path)
    if not os.path.isfile(p):
        raise MissingFileError(p, "point cloud file not found")
    try:
        las = laspy.read(p)
    except Exception as exc:
        raise FormatError(p, f"not a readable LAS/LAZ file ({exc})") from None
    xyz = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    dims = set(las.point_format.dimension_names)
    rgb = None
    if {"red", "green", "blue"} <= dims:
        rgb = np.column_stack([np.asarray(las.red), np.asarray(las.green), np.asarray(las.blue)])
    extra = {name: np.asarray(las[name]) for name in las.point_format.extra_dimension_names}
    crs = None
    try:
        c = las.header.parse_crs()
        crs = c.to_wkt() if c is not None else None
    except Exception:
        crs = None
    vlrs = {}
    for v in las.header.vlrs:
        if hasattr(v, "record_data") and isinstance(getattr(v, "record_data", None), bytes | bytearray):
            vlrs[(v.user_id, v.record_id)] = bytes(v.record_data)
    return {"xyz": xyz, "rgb": rgb, "extra": extra, "crs": crs, "vlrs": vlrs}


def write_seamlines(path, regions, crs) -> None:
    """Seamline polygons as a GeoPackage layer ``seamlines``, written atomically.

    Parameters
    ----------
    path : path
        Destination ``.gpkg``.
    regions : sequence of SeamRegion
        One per source image (:class:`truortho.core.ortho.pipeline.SeamRegion`: ``wkt`` a
        polygon or multipolygon in ``crs``, ``image_index``, ``image_name``, ``cells``). They
        become multipolygon features with the fields ``image``, ``name`` and ``cells``.
    crs : str or None
        CRS of the polygons (WKT, ``EPSG:n``, ...); None writes a layer without one.
    """
    from osgeo import ogr, osr

    with atomic_output(path) as tmp:
        drv = ogr.GetDriverByName("GPKG")
        ds = drv.CreateDataSource(str(tmp))
        srs = osr.SpatialReference()
        if crs:
            srs.SetFromUserInput(str(crs))
            srs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        layer = ds.CreateLayer("seamlines", srs if crs else None, ogr.wkbMultiPolygon)
        for name, kind in (("image", ogr.OFTInteger), ("name", ogr.OFTString), ("cells", ogr.OFTInteger)):
            layer.CreateField(ogr.FieldDefn(name, kind))
        for r in regions:
            f = ogr.Feature(layer.GetLayerDefn())
            geom = ogr.ForceToMultiPolygon(ogr.CreateGeometryFromWkt(r.wkt))
            f.SetGeometry(geom)
            f.SetField("image", int(r.image_index))
            f.SetField("name", str(r.image_name))
            f.SetField("cells", int(r.cells))
            layer.CreateFeature(f)
        ds = None  # close before the rename
        del ds
