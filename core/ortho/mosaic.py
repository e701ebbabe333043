"""Image access for the mosaic and the per-tile mosaicking.

:class:`ImageStore` decodes source images on demand, keeps a least-recently-used
cache bounded in bytes, and serves reduced levels (area-averaged halvings) so
an output cell coarser than the image pixel samples a pixel of about its own
size instead of aliasing. :func:`candidate_colours` reads the colours of a tile's cells
from every candidate image (bilinear, one compiled pass per image), any band count and dtype;
:func:`candidate_luminance` only their luminance (for the seam costs).

:func:`mosaic_tile` turns the visibility of a tile (:mod:`.views`) into output
values: data costs and labels (:mod:`.select`), colours of every candidate
corrected radiometrically (:mod:`.color`), feathering across seams
(:mod:`.seams`).
"""

from __future__ import annotations

import math
import threading
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ..errors import FormatError, InputError
from ..imagery import REC601, level_size, read_image_level, read_level_window
from ..jit import njit
from .color import ColorCorrection, value_scale
from .edgecolour import EDGE_COLOURS, surface_edge_colour
from .seams import feather_weights
from .select import add_disagreement, data_costs, select_labels
from .views import TileViews


class ImageStore:
    """Decoded images by (index, level) with an LRU cache of at most ``max_bytes``; rasters that
    rasterio reads (GeoTIFF) are read by windows instead (:meth:`source`).

    ``chroma`` (optional, one entry per image): the colour subsampling of a JPEG whose colour
    :func:`~truortho.core.chroma.restore_chroma` restores at full resolution (level 0), or None.
    """

    def __init__(
        self,
        paths: list[str],
        sizes: list[tuple[int, int]],
        bands: int,
        dtype,
        max_bytes: int = 1 << 30,
        windowed: bool = True,
        chroma: list | None = None,
    ) -> None:
        self.paths = paths
        if chroma is not None and len(chroma) != len(paths):
            raise InputError(f"ImageStore: {len(chroma)} chroma entries for {len(paths)} images")
        self.chroma = list(chroma) if chroma is not None else [None] * len(paths)
        self.sizes = sizes
        self.bands = int(bands)
        self.dtype = np.dtype(dtype)
        self.max_bytes = int(max_bytes)
        self._cache: OrderedDict = OrderedDict()
        self._bytes = 0
        self.reads = 0  # whole images decoded
        self.window_reads = 0
        from ..imagery import _use_rasterio

        #: read by windows (rasterio formats) instead of decoded whole
        self.windowed = [bool(windowed) and _use_rasterio(str(p)) for p in paths]
        self._lock = threading.RLock()  # guards the cache and counters, not the decoding
        self._pending: dict = {}  # (image, level) being decoded -> Event set when done

    def get(self, i: int, level: int = 0) -> np.ndarray:
        """The decoded image ``i`` at ``level`` (thread-safe: tiles may run in threads).

        Images decode in parallel: the lock guards only the cache, and a thread asking for an
        image another thread is decoding waits for that one instead of decoding it again.
        """
        key = (int(i), int(level))
        while True:
            with self._lock:
                if key in self._cache:
                    self._cache.move_to_end(key)
                    return self._cache[key]
                waiting = self._pending.get(key)
                if waiting is None:
                    event = self._pending[key] = threading.Event()
            if waiting is not None:
                waiting.wait()
                continue  # cached now (or failed there: then try here and raise the same error)
            try:
                img = self._load(i, level)
                with self._lock:
                    self._insert(key, img)
                return img
            finally:
                with self._lock:
                    self._pending.pop(key, None)
                event.set()

    def __getstate__(self):
        state = dict(self.__dict__)
        state["_lock"] = None
        state["_pending"] = {}
        state["_cache"] = OrderedDict()
        state["_bytes"] = 0
        return state

    def __setstate__(self, state) -> None:
        self.__dict__.update(state)
        self._lock = threading.RLock()

    def _load(self, i: int, level: int) -> np.ndarray:
        """Decode image ``i`` at ``level`` (outside the lock): only that level is cached, so the
        cache holds 4**level times more images of a coarse product (:func:`read_image_level`
        decodes JPEGs directly at the reduced scale)."""
        img = read_image_level(self.paths[i], self.sizes[i], level)
        self._check(i, img)
        sub = self.chroma[i]
        if level == 0 and sub is not None and img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3:
            # from level 1 on a pixel averages 2 x 2 or more: the colour is about as sharp as the luma
            from ..chroma import restore_chroma

            img = restore_chroma(img, sub)
        with self._lock:
            self.reads += 1
        return np.ascontiguousarray(img)

    def _check(self, i: int, img: np.ndarray) -> None:
        """FormatError naming image ``i`` when its bands or data type differ from the block's."""
        nb = 1 if img.ndim == 2 else img.shape[2]
        if nb != self.bands or img.dtype != self.dtype:
            raise FormatError(
                self.paths[i],
                f"image has {nb} band(s) of {img.dtype}, the block {self.bands} band(s) of {self.dtype}",
            )

    def _insert(self, key, img: np.ndarray) -> None:
        """Cache ``img`` (under the lock), evicting the least recently used beyond ``max_bytes``."""
        self._cache[key] = img
        self._bytes += img.nbytes
        while self._bytes > self.max_bytes and len(self._cache) > 1:
            _, old = self._cache.popitem(last=False)
            self._bytes -= old.nbytes

    def level_size(self, i: int, level: int) -> tuple[int, int]:
        """(width, height) of image ``i`` at ``level`` (:func:`~truortho.core.imagery.level_size`)."""
        return level_size(self.sizes[i], level)

    def source(self, i: int, level: int, uv: np.ndarray):
        """What to sample the full-resolution points ``uv`` (n, 2) from at ``level``.

        ``(array, (x0, y0), (w', h'))``: the whole decoded level image (JPEG, PNG: decoded once,
        cached) or, for rasters that can be read by windows (GeoTIFF: tiled, with overviews if
        any), only the window the points need plus 2 pixels, read for this call (not cached):
        a tile task then reads the windows it needs, not the images.
        """
        lw, lh = self.level_size(i, level)
        if not self.windowed[i] or not len(uv):
            img = self.get(i, level)
            return img, (0, 0), (img.shape[1], img.shape[0])
        s = 0.5**level  # the levels' blocks stay on the stored pixel grid (imagery.halve_image)
        u = (uv[:, 0].astype(np.float64) + 0.5) * s - 0.5
        v = (uv[:, 1].astype(np.float64) + 0.5) * s - 0.5
        ok = np.isfinite(u) & np.isfinite(v)
        if not ok.any():
            img = self.get(i, level)
            return img, (0, 0), (img.shape[1], img.shape[0])
        x0 = max(int(np.floor(u[ok].min())) - 2, 0)
        y0 = max(int(np.floor(v[ok].min())) - 2, 0)
        x1 = min(int(np.ceil(u[ok].max())) + 3, lw)
        y1 = min(int(np.ceil(v[ok].max())) + 3, lh)
        if x1 <= x0 or y1 <= y0:
            x0, y0, x1, y1 = 0, 0, min(lw, 1), min(lh, 1)
        return self._read_window(i, level, x0, y0, x1 - x0, y1 - y0), (x0, y0), (lw, lh)

    def _read_window(self, i: int, level: int, x0: int, y0: int, w: int, h: int) -> np.ndarray:
        """Window of level ``level`` (:func:`~truortho.core.imagery.read_level_window`)."""
        img = read_level_window(self.paths[i], self.sizes[i], level, x0, y0, w, h)
        self._check(i, img)
        with self._lock:
            self.window_reads += 1
        return img

    def level_for(self, gsd: float, res: float) -> int:
        """Level whose pixel (``gsd * 2**level``) is at most the output cell ``res``."""
        if not (gsd > 0 and res > 0):
            return 0
        return max(0, min(8, int(math.floor(math.log2(res / gsd) + 1e-9))))


@dataclass
class MosaicParams:
    """Selection and blending parameters (see :class:`~.pipeline.TrueOrthoConfig`)."""

    edge_penalty: float = 1.0
    smoothness: float = 1.0
    contrast: float = 4.0
    discontinuity: float = 0.5
    blend_width: int = 5
    sweeps: int = 8
    edge_colour: str = "off"  # :data:`~.edgecolour.EDGE_COLOURS`
    #: Largest colour difference from the consensus of a cell's views (fraction of the value
    #: scale) of a view that agrees with it (:func:`~.select.add_disagreement`); 0 = off.
    consistency: float = 0.0

    def __post_init__(self) -> None:
        # TrueOrthoConfig checks its own copy; code that builds the parameters directly must not get
        # ``surface`` for a misspelt mode
        if self.edge_colour not in EDGE_COLOURS:
            want = ", ".join(EDGE_COLOURS)
            raise InputError(f"MosaicParams.edge_colour: expected one of {want}, got {self.edge_colour!r}")
        if not (0.0 <= self.consistency < math.inf):
            raise InputError(f"MosaicParams.consistency: expected a number >= 0, got {self.consistency!r}")


@dataclass
class TileMosaic:
    """Output of one tile's outer window.

    values : (bands, rows, cols) float32 (0 where no data); alpha : (rows, cols) bool;
    label : (rows, cols) int, global image index or -1; occlusion : (rows, cols) uint8
    (0 seen, 1 seen by no image, 255 no surface).
    """

    values: np.ndarray
    alpha: np.ndarray
    label: np.ndarray
    occlusion: np.ndarray


def candidate_colours(
    views: TileViews,
    store: ImageStore,
    correction: ColorCorrection | None,
    res: float,
    needed: np.ndarray | None = None,
    workers: int = 1,
    fill: bool = True,
) -> np.ndarray:
    """Colours ``(K, rows, cols, bands)`` float32 of every candidate where usable (bilinear, border
    replicated), corrected when ``correction`` is given.

    NaN where the candidate is not usable (or not ``needed``); with ``fill=False`` those entries
    are left unset (for a caller that reads only the needed ones). Images run in ``workers`` threads.
    """
    K, rows, cols = views.usable.shape
    out = np.empty((K, rows, cols, store.bands), np.float32)
    _sample_candidates(views, store, res, needed, workers, out, None, fill, correction)
    return out


def candidate_luminance(views: TileViews, store: ImageStore, res: float, workers: int = 1) -> np.ndarray:
    """Luminance in [0, 1]-ish units ``(K, rows, cols)`` float32 of every candidate where usable
    (Rec. 601 of the first three bands of RGB data, band 1 otherwise; bilinear, uncorrected), NaN
    elsewhere: the luminance of :func:`candidate_colours` without computing the colours."""
    K, rows, cols = views.usable.shape
    lw = np.zeros(store.bands)
    if store.bands >= 3:
        lw[:3] = REC601
    else:
        lw[0] = 1.0
    lw /= float(value_scale(store.dtype))
    out = np.empty((K, rows, cols, 1), np.float32)
    _sample_candidates(views, store, res, None, workers, out, lw, True, None)
    return out[..., 0]


def _sample_candidates(views, store, res, needed, workers, out, lum_weights, fill, correction) -> None:
    K = views.usable.shape[0]
    lw = np.zeros(1) if lum_weights is None else np.ascontiguousarray(lum_weights, np.float64)

    def one(k):
        m = views.usable[k] if needed is None else (views.usable[k] & needed[k])
        i = int(views.cands[k])
        if not m.any():
            if fill:
                out[k] = np.nan
            return
        level = store.level_for(float(views.gsd[k]), res)
        uvk = views.uv[k]
        img, origin, _ = store.source(i, level, uvk[m] if store.windowed[i] else uvk[:0, 0])
        s = 0.5**level  # pixel centres x' = (x + 0.5) / 2**level - 0.5 (imagery.read_image_level)
        _bilinear_into(
            img.reshape(img.shape[0], img.shape[1], -1),
            uvk,
            m,
            s,
            s,
            float(origin[0]),
            float(origin[1]),
            lw,
            lum_weights is not None,
            fill,
            out[k],
        )
        if correction is not None:
            correction.apply_inplace(i, out[k], m, store.dtype, uvk)

    each(one, range(K), workers)


def each(fn, items, workers: int = 1) -> None:
    """``fn(item)`` for every item, in ``workers`` threads when > 1 (compiled kernels release the GIL)."""
    items = list(items)
    if workers > 1 and len(items) > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=min(workers, len(items))) as pool:
            list(pool.map(fn, items))
    else:
        for it in items:
            fn(it)


@njit
def _bilinear_into(img, uv, mask, sx, sy, ox, oy, lum_w, lum, fill, out):
    """``out[r, c]`` = bilinear sample (border replicated) of ``img`` (h, w, bands) at the
    full-resolution pixel ``uv[r, c]`` mapped to the level (``x' = (x + 0.5) sx - 0.5``) and
    shifted by the window origin ``(ox, oy)`` — with ``lum`` the single value ``sum_b lum_w[b]
    sample_b`` in ``out[r, c, 0]``; NaN where ``mask`` is False or uv is NaN (left unset there
    without ``fill``)."""
    H, W, B = img.shape
    rows, cols = mask.shape
    nout = out.shape[2]
    for r in range(rows):
        for c in range(cols):
            x = y = np.nan
            if mask[r, c]:
                x = (np.float64(uv[r, c, 0]) + 0.5) * sx - 0.5 - ox
                y = (np.float64(uv[r, c, 1]) + 0.5) * sy - 0.5 - oy
            if not (x == x and y == y):
                if fill:
                    for b in range(nout):
                        out[r, c, b] = np.nan
                continue
            xf = math.floor(x)
            yf = math.floor(y)
            fx = x - xf
            fy = y - yf
            i0 = min(max(np.int64(xf), 0), W - 1)
            i1 = min(max(np.int64(xf) + 1, 0), W - 1)
            j0 = min(max(np.int64(yf), 0), H - 1)
            j1 = min(max(np.int64(yf) + 1, 0), H - 1)
            w00 = (1.0 - fx) * (1.0 - fy)
            w01 = fx * (1.0 - fy)
            w10 = (1.0 - fx) * fy
            w11 = fx * fy
            if lum:
                acc = 0.0
                for b in range(B):
                    if lum_w[b] != 0.0:
                        v = (
                            np.float64(img[j0, i0, b]) * w00
                            + np.float64(img[j0, i1, b]) * w01
                            + np.float64(img[j1, i0, b]) * w10
                            + np.float64(img[j1, i1, b]) * w11
                        )
                        acc += lum_w[b] * v
                out[r, c, 0] = acc
            else:
                for b in range(B):
                    out[r, c, b] = (
                        np.float64(img[j0, i0, b]) * w00
                        + np.float64(img[j0, i1, b]) * w01
                        + np.float64(img[j1, i0, b]) * w10
                        + np.float64(img[j1, i1, b]) * w11
                    )


@njit
def _blend(w, colours, out):
    """``out[b, r, c] = sum_k w[k, r, c] colours[k, r, c, b]`` over the k with a positive weight."""
    K, rows, cols = w.shape
    B = colours.shape[3]
    for r in range(rows):
        for c in range(cols):
            for b in range(B):
                out[b, r, c] = 0.0
            for k in range(K):
                wk = w[k, r, c]
                if wk > 0:
                    for b in range(B):
                        v = colours[k, r, c, b]
                        if v == v:
                            out[b, r, c] += wk * v


def mosaic_tile(
    views: TileViews,
    store: ImageStore,
    correction: ColorCorrection | None,
    res: float,
    params: MosaicParams,
    fixed: np.ndarray | None = None,
    workers: int = 1,
) -> TileMosaic:
    """Labels, blended colours, alpha and occlusion of a tile's outer window.

    ``fixed``: (rows, cols) global image indices already written by neighbouring
    tiles (-1 = free), continued here (:func:`~.select.select_labels`). Per-image sampling and
    correction run in ``workers`` threads.
    """
    rows, cols = views.heights.shape
    valid = np.isfinite(views.heights)
    bands = store.bands
    K = len(views.cands)
    occl = np.where(valid, 1, 255).astype(np.uint8)
    if K == 0:
        return TileMosaic(
            np.zeros((bands, rows, cols), np.float32),
            np.zeros((rows, cols), bool),
            np.full((rows, cols), -1, np.int64),
            occl,
        )
    usable = views.usable & valid[None]
    seen = usable.any(axis=0)
    occl[valid & seen] = 0
    cost = data_costs(views.eff_res, usable, views.near_edge, params.edge_penalty)
    colours = None
    clean = usable & ~views.near_edge
    if params.consistency > 0 and K >= 3:
        # every usable candidate's colour, for the agreement of the views; the blend reads the same
        # samples and leaves out the views that disagree
        colours = candidate_colours(views, store, correction, res, None, workers)
        clean &= ~add_disagreement(cost, colours, usable, params.consistency * value_scale(store.dtype))
    # the seam cost uses every candidate's luminance corrected by the lightness (or first band)
    # gain and offset; without the agreement of the views, colours (fully corrected) are sampled
    # below only where they enter the mosaic
    lum = candidate_luminance(views, store, res, workers)
    if correction is not None:
        for k, i in enumerate(views.cands):
            if not correction.is_identity(int(i)):
                if correction.has_rgb_stage(int(i)) and store.bands >= 3:
                    # the RGB stage's gains and offsets averaged with the luminance's weights
                    assert correction.rgb_gain is not None and correction.rgb_offset is not None
                    g1 = float(np.asarray(REC601) @ correction.rgb_gain[int(i)])
                    o1 = float(np.asarray(REC601) @ correction.rgb_offset[int(i)])
                    lum[k] = g1 * lum[k] + o1 / value_scale(store.dtype)
                g, o = correction.gain[int(i), 0], correction.offset[int(i), 0]
                lum[k] = g * lum[k] + (o / 100.0 if correction.lab else o / value_scale(store.dtype))
    local_fixed = None
    if fixed is not None and (fixed >= 0).any():
        lut = {int(g): k for k, g in enumerate(views.cands)}
        local_fixed = np.full(fixed.shape, -1, np.int32)
        for g, k in lut.items():
            local_fixed[fixed == g] = k
    labels = select_labels(
        cost,
        views.heights,
        lum,
        res,
        params.smoothness,
        params.contrast,
        params.discontinuity,
        sweeps=params.sweeps,
        fixed=local_fixed,
    )
    w = feather_weights(labels, clean, params.blend_width)
    # _blend reads a candidate's colour only where its weight is positive: only those are sampled
    if colours is None:
        colours = candidate_colours(views, store, correction, res, w > 0, workers, fill=False)
    values = np.empty((bands, rows, cols), np.float32)
    _blend(w, colours, values)
    alpha = labels >= 0
    if params.edge_colour != "off" and bands == 3:
        h0 = max(float(params.discontinuity), 2.0 * float(res))  # the selection's (select_labels)
        scale = float(value_scale(store.dtype))
        values = surface_edge_colour(values, alpha, views.heights, h0, scale, params.edge_colour == "checked")
    glabel = np.where(alpha, views.cands[np.clip(labels, 0, K - 1)], -1).astype(np.int64)
    return TileMosaic(values, alpha, glabel, occl)


def to_dtype(values: np.ndarray, dtype) -> np.ndarray:
    """Round and clip float values to an output dtype."""
    dt = np.dtype(dtype)
    if dt.kind in "ui":
        info = np.iinfo(dt)
        return np.clip(np.round(values), info.min, info.max).astype(dt)
    if dt.kind == "f":
        return values.astype(dt)
    raise InputError(f"unsupported image data type {dt}")
