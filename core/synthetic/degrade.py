"""Raw-DSM-like inputs made from a truth DSM: seeded noise, outliers, holes and edge blur.

A stand-in for a dense-matching DSM (and its confidence raster) when testing
DSM post-processing against the exact truth of a synthetic scene. Every
random choice comes from ``np.random.default_rng([seed, 71])``.

Degradations, in order (:class:`Degradation` holds the parameters):

1. **Edge blur**: cells within ``edge_width`` cells of a height step larger
   than ``step`` are replaced by the 3x3 mean of the truth (a matching cost
   window straddling a wall gives intermediate heights).
2. **Noise**: Gaussian, ``noise_sigma`` metres, on every cell.
3. **Outliers**: a fraction ``outlier_fraction`` of the cells gets an offset
   of random sign and magnitude in ``outlier_range`` metres; a share
   ``blob_share`` of them come as 2 x 2 blobs (the same offset on 4 cells).
4. **Holes** (nodata): ``holes`` random discs of radius up to
   ``hole_radius`` metres, plus occlusion strips of ``occlusion_width``
   metres on the ground along the step edges that face ``occlusion_azimuth``
   (what a matcher misses at the foot of walls facing away from the cameras).

The **confidence** (float32 in [0, 1], 0 on holes) is high (U(0.6, 1)) on
clean cells, lower on blurred edges (U(0.3, 0.7)), and on outliers low
(U(0, 0.35)) for 80 % of them and high (U(0.6, 1)) for the rest, so that a
filter cannot rely on it alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass
class Degradation:
    """Parameters of :func:`degrade_dsm` (lengths in metres unless stated)."""

    noise_sigma: float = 0.05
    outlier_fraction: float = 0.01
    outlier_range: tuple[float, float] = (1.5, 12.0)
    blob_share: float = 0.3
    holes: int = 12
    hole_radius: float = 2.0
    occlusion_width: float = 1.0
    occlusion_azimuth_deg: float = 45.0
    edge_width: int = 1
    step: float = 1.0


@dataclass
class DegradedDsm:
    """Output of :func:`degrade_dsm`.

    Attributes
    ----------
    dsm : (rows, cols) float32
        Degraded heights, NaN = nodata.
    confidence : (rows, cols) float32
        In [0, 1]; 0 on nodata.
    outliers, holes, edges : (rows, cols) bool
        Where outliers were added, where nodata was made, which cells were blurred.
    """

    dsm: np.ndarray
    confidence: np.ndarray
    outliers: np.ndarray
    holes: np.ndarray
    edges: np.ndarray


def degrade_dsm(
    truth: np.ndarray, resolution: float, seed: int = 0, params: Degradation | None = None
) -> DegradedDsm:
    """Degrade a truth DSM (see the module docstring).

    Parameters
    ----------
    truth : (rows, cols) float
        Truth heights (finite), metres.
    resolution : float
        Cell size, metres.
    seed : int
    params : Degradation, optional
    """
    from scipy import ndimage

    p = params or Degradation()
    z0 = np.asarray(truth, dtype=np.float64)
    if z0.ndim != 2 or not np.all(np.isfinite(z0)):
        raise InputError("degrade_dsm: the truth must be a finite 2-D array")
    res = float(resolution)
    rng = np.random.default_rng([int(seed), 71])
    rows, cols = z0.shape
    # 1. edge blur
    dz = np.zeros(z0.shape, bool)
    dz[:, :-1] |= np.abs(np.diff(z0, axis=1)) > p.step
    dz[:, 1:] |= np.abs(np.diff(z0, axis=1)) > p.step
    dz[:-1] |= np.abs(np.diff(z0, axis=0)) > p.step
    dz[1:] |= np.abs(np.diff(z0, axis=0)) > p.step
    edges = ndimage.binary_dilation(dz, iterations=max(p.edge_width - 1, 0)) if p.edge_width > 1 else dz
    if p.edge_width < 1:
        edges = np.zeros_like(dz)
    z = z0.copy()
    z[edges] = ndimage.uniform_filter(z0, 3, mode="nearest")[edges]
    # 2. noise
    z += rng.normal(0.0, p.noise_sigma, z.shape)
    # 3. outliers
    n_out = int(round(p.outlier_fraction * z.size))
    n_blob = int(round(n_out * p.blob_share / 4))
    n_single = max(n_out - 4 * n_blob, 0)
    outliers = np.zeros(z.shape, bool)
    idx = rng.choice(z.size, n_single, replace=False)
    r, c = np.unravel_index(idx, z.shape)
    mag = rng.uniform(*p.outlier_range, n_single) * rng.choice([-1.0, 1.0], n_single)
    z[r, c] += mag
    outliers[r, c] = True
    br = rng.integers(0, rows - 1, n_blob)
    bc = rng.integers(0, cols - 1, n_blob)
    bmag = rng.uniform(*p.outlier_range, n_blob) * rng.choice([-1.0, 1.0], n_blob)
    for a in (0, 1):
        for b in (0, 1):
            z[br + a, bc + b] += bmag
            outliers[br + a, bc + b] = True
    # 4. holes: discs and occlusion strips at the foot of walls facing the azimuth
    holes = np.zeros(z.shape, bool)
    yy, xx = np.mgrid[0:rows, 0:cols]
    for _ in range(p.holes):
        rad = rng.uniform(0.3, 1.0) * p.hole_radius / res
        cr, cc = rng.uniform(0, rows), rng.uniform(0, cols)
        r0, r1 = int(max(cr - rad - 1, 0)), int(min(cr + rad + 2, rows))
        c0, c1 = int(max(cc - rad - 1, 0)), int(min(cc + rad + 2, cols))
        sub = (yy[r0:r1, c0:c1] - cr) ** 2 + (xx[r0:r1, c0:c1] - cc) ** 2 <= rad**2
        holes[r0:r1, c0:c1] |= sub
    if p.occlusion_width > 0:
        # a ground cell is occluded when the truth k cells towards the azimuth (k = 1..w) is higher
        # by more than `step`: strips of about occlusion_width at the foot of the walls facing away
        az = math.radians(p.occlusion_azimuth_deg)
        dcol, drow = math.sin(az), -math.cos(az)  # rows grow southwards
        w = max(int(round(p.occlusion_width / res)), 1)
        for k in range(1, w + 1):
            sr, sc = int(round(k * drow)), int(round(k * dcol))
            shifted = np.full(z.shape, -np.inf)
            shifted[max(-sr, 0) : rows - max(sr, 0), max(-sc, 0) : cols - max(sc, 0)] = z0[
                max(sr, 0) : rows - max(-sr, 0), max(sc, 0) : cols - max(-sc, 0)
            ]
            holes |= shifted - z0 > p.step
    z[holes] = np.nan
    outliers &= ~holes
    edges &= ~holes
    conf = rng.uniform(0.6, 1.0, z.shape)
    conf[edges] = rng.uniform(0.3, 0.7, int(edges.sum()))
    n_o = int(outliers.sum())
    low_c = rng.random(n_o) < 0.8
    conf[outliers] = np.where(low_c, rng.uniform(0.0, 0.35, n_o), rng.uniform(0.6, 1.0, n_o))
    conf[holes] = 0.0
    return DegradedDsm(z.astype(np.float32), conf.astype(np.float32), outliers, holes, edges)


def flatten_roofs(scene) -> None:
    """Make every roof of a synthetic scene flat at its eave height, in place.

    Only the truth rasters (``scene.dsm``, ``scene.orthophoto``) and the surface
    queries change; the rendered images are **not** re-rendered.
    """
    import dataclasses

    from .surface import _pack

    s = scene.surface
    s.buildings = [dataclasses.replace(b, roof="flat", ridge=0.0) for b in s.buildings]
    s.bld = _pack(s.buildings)
