"""Randomized acceptance battery: DSM (OSGM) and true orthophoto on scenes nobody tuned for.

Not a test (``make test`` never runs it). Run from the repository root::

    make acceptance                               # 12 scenes, master seed 2026
    source scripts/env.sh && python -P bench/acceptance.py [--scenes 12] [--seed 2026] [--only 3,7]
        [--no-sgbm] [--keep DIR] [--write-docs]

Every scene is a :mod:`truortho.core.synthetic` city drawn from wide ranges by
``default_rng([seed, index])`` (:func:`draw_config`): building density, heights up to 60 m,
flat/gable/hip/shed roofs, narrow streets and courtyards, low-texture roofs, repetitive facades,
sun shadows, nadir-only and nadir + oblique blocks (4-8 obliques, tilts 30-45 degrees), overlaps
60/30 to 80/60, exposure and white-balance jitter, vignetting, noise, JPEG compression, lens
distortion. Odd scenes have obliques, even ones are nadir only, so that both kinds are always in
the battery. The given (true) cameras are used: this measures dense matching and the true ortho,
not the orientation.

Per scene, against the exact truth on the truth DSM's grid (the scene extent at the nominal GSD):

* **OSGM** (:func:`truortho.core.osgm.run_osgm`, defaults, only ``Z_MIN``/``Z_MAX`` from the truth
  range widened by 5 m, as a user who knows the site would give), over the cells whose truth point
  is seen by at least two images: completeness, NMAD (GSD), the share of non-edge cells within
  3 GSD and of edge cells (within 2 GSD of a height step over 2 m) within 3 GSD (holes count as
  misses); wall seconds and seconds per million (cells x images);
* the **pairwise OpenCV SGBM baseline** (``bench/sgbm_baseline.py``: rectified pairs, SGBM 3WAY,
  triangulation, median fusion onto the same grid), the same figures and its wall seconds;
* the OSGM DSM after the DSM filter with its confidence (``osgm_filtered``: what
  ``truortho:pipeline`` hands on to the true ortho), the same figures (informative);
* the **true ortho** (:func:`truortho.core.ortho.pipeline.true_ortho`, defaults) on the truth DSM,
  on the raw OSGM DSM (``ortho_osgm``, the goal) and on the filtered one (``ortho_filtered``), and the
  conventional ortho (``visibility=False``) on the truth DSM:
  ghosting, median shift, coverage and mean dE (``core/ortho/evaluate.py``), and the share of
  cells seen by no image (truth, eroded by one cell) that carry a colour ("wrong fill"), and (not a
  goal) the wrong colours 1-6 cells from the outlines (``ghosting_beyond_outline``: leaning or
  double-mapped buildings, without the outline's own placement that ``ghosting`` also counts);
* the true ortho's colour edges (``TrueOrthoConfig.edge_colour``, default ``checked``; not a goal):
  the ghosting on the truth and the OSGM DSM also with them off and in the mode for exact surfaces
  (``ortho_truth_edge_off``, ``ortho_truth_edge_surface``, ``ortho_osgm_edge_off``,
  ``ortho_osgm_edge_surface``); and without the agreement of the views (``ortho_truth_agree_off``,
  ``ortho_osgm_agree_off``: ``TrueOrthoConfig.consistency = 0``), with the scenes each figure is
  lower and higher on, and the time ratio;
* a calibration of the ghosting goal (not a goal): the truth DSM with every outline one cell off
  (``truth_shift1``, moved one cell east), its DSM figures, and the ghosting of the true ortho on
  it (``ortho_shift1``).

Also, not goals: the mean dE after the best global per-channel gain and offset to the truth
(``relative_dE``: the block's absolute exposure is not observable, see :func:`relative_delta_e`), and
the streak index of the DSMs (:func:`truortho.core.surface.quality.streak_index`). One picture per
scene goes to ``bench/results/acceptance/scene_NN.jpg`` (hillshades of the truth and OSGM DSMs,
true orthos on both).

Then the distribution over the scenes (median, worst, share meeting the goal of issue 17) and
the OSGM / SGBM time ratio. Results go to ``bench/results/acceptance.json`` (a run of some scenes,
``--only``, to ``acceptance_only.json``: it does not replace the full run's); ``--write-docs``
replaces the marked section of ``docs/acceptance.md`` with the table, the command, the commit
and the machine.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DOCS = os.path.join(ROOT, "docs", "acceptance.md")

#: (figure, comparison, goal): the goals of issue 17, applied to every scene
GOALS = (
    ("osgm.completeness", ">=", 0.98),
    ("osgm.nmad_gsd", "<=", 0.5),
    ("osgm.flat3", ">=", 0.97),
    ("osgm.edge3", ">=", 0.80),
    ("ortho_truth.ghosting", "<=", 0.01),
    ("ortho_truth.ghosting_vs_conventional", "<=", 0.10),
    ("ortho_osgm.ghosting", "<=", 0.02),
    ("ortho_truth.shift_gsd", "<=", 0.3),
    ("ortho_osgm.shift_gsd", "<=", 0.3),
    ("ortho_truth.mean_dE", "<=", 3.0),
    ("ortho_truth.wrong_fill", "<=", 0.0),
)


# ------------------------------------------------------------------ scenes


#: Ranges of ``--realistic`` (:func:`draw_config`): the optics' point spread beyond the rendering's,
#: px (real blocks measured 0 to about 1.4 px by ``bench/point_spread.py``), the share of the ground
#: in crop fields and their stalks' height, metres.
REALISTIC_BLUR = (0.0, 1.4)
REALISTIC_CROPS = (0.0, 0.5)
REALISTIC_STALKS = (0.1, 0.5)
#: JPEG quality of ``--realistic`` (IJG scale): the real blocks' luminance tables read 90 to 100
#: (``bench/point_spread.py``), where the battery's own draw spans 70 to 95.
REALISTIC_JPEG = (90, 100)


def draw_config(index: int, seed: int, realistic: bool = False):
    """The :class:`~truortho.core.synthetic.SceneConfig` of scene ``index`` (deterministic).

    ``realistic``: also an optics blur, crop fields and the JPEG quality of the real blocks
    (:data:`REALISTIC_BLUR` ...), drawn from a stream of their own, so every other parameter of the
    scene is the same as without.
    """
    import dataclasses

    from truortho.core.synthetic import SceneConfig

    if realistic:
        more = np.random.default_rng([seed, index, 7]).uniform
        blur, share, stalks = more(*REALISTIC_BLUR), more(*REALISTIC_CROPS), more(*REALISTIC_STALKS)
        quality = int(round(more(*REALISTIC_JPEG)))
        return dataclasses.replace(draw_config(index, seed), optics_blur=blur, crop_share=share,
                                   crop_height=stalks, jpeg_quality=quality)  # fmt: skip

    rng = np.random.default_rng([seed, index])
    u = rng.uniform
    oblique = index % 2 == 1
    side = u(60.0, 100.0)
    aspect = u(0.75, 1.0)
    area = side * side * aspect
    density = u(1.2, 4.8)  # buildings per 1,000 m^2 (as many as fit: the generator keeps the gaps)
    size_lo = u(5.0, 10.0)
    size_hi = size_lo + u(4.0, 14.0)
    tall = u(8.0, 25.0)
    flying = u(110.0, 170.0)
    gsd = u(0.10, 0.18)
    width = int(rng.choice([480, 560, 640]))
    cfg = SceneConfig(
        extent=(-side / 2, -side * aspect / 2, side / 2, side * aspect / 2),
        terrain_relief=u(0.0, 8.0),
        n_buildings=int(max(2, round(density * area / 1000.0))),
        building_size=(size_lo, size_hi),
        eave_height=(u(3.0, 6.0), tall),
        roof_pitch=(u(15.0, 30.0), u(30.0, 50.0)),
        building_gap=u(1.5, 7.0),
        tower=bool(rng.random() < 0.7),
        tower_height=u(20.0, 60.0),
        tower_size=u(7.0, 14.0),
        texture_scale=gsd * u(1.0, 2.0),
        texture_contrast=u(1.2, 3.0),
        roof_contrast=(u(0.05, 0.4), 1.0),
        facade_windows=bool(rng.random() < 0.6),
        image_size=(width, width * 3 // 4),
        focal_px=flying / gsd,
        principal_offset=(u(-4, 4), u(-4, 4)),
        distortion=(u(-0.15, 0.05), u(-0.02, 0.05), u(-5e-4, 5e-4), u(-5e-4, 5e-4), 0.0),
        flying_height=flying,
        forward_overlap=u(0.6, 0.8),
        side_overlap=u(0.3, 0.6),
        heading_deg=u(0.0, 360.0),
        n_oblique=int(rng.integers(4, 9)) if oblique else 0,
        oblique_tilt_deg=u(30.0, 45.0),
        gain_sigma=u(0.04, 0.15),
        offset_sigma=u(0.0, 0.03),
        vignetting=u(0.0, 0.3),
        noise_sigma=u(0.5, 3.0),
        jpeg_quality=int(rng.integers(70, 96)),
        shadow_strength=u(0.0, 0.6),
        sun_azimuth_deg=u(0.0, 360.0),
        sun_elevation_deg=u(25.0, 70.0),
        seed=int(rng.integers(0, 2**31 - 1)),
    )
    return _fit(cfg)


def _fit(cfg):
    """``cfg`` with as many of its buildings as the generator can place with their gaps; where not
    even two fit (a small block drawn with large buildings, a tower and wide gaps: master seed 4242,
    scene 5), with smaller buildings."""
    import dataclasses

    from truortho.core.errors import InputError
    from truortho.core.synthetic.surface import Surface

    while True:
        try:
            Surface(cfg)
            return cfg
        except InputError as exc:
            if "could not place" not in str(exc):
                raise
            if cfg.n_buildings > 2:
                cfg = dataclasses.replace(cfg, n_buildings=max(2, int(cfg.n_buildings * 0.85)))
                continue
            lo, hi = cfg.building_size
            if lo <= 3.0:
                raise
            cfg = dataclasses.replace(cfg, building_size=(max(3.0, 0.85 * lo), max(3.0, 0.85 * hi)))


def describe(cfg) -> str:
    w, h = cfg.image_size
    return (
        f"{cfg.extent[2] - cfg.extent[0]:.0f}x{cfg.extent[3] - cfg.extent[1]:.0f} m, {cfg.n_buildings} bldg"
        f"{' + tower ' + format(cfg.tower_height, '.0f') + ' m' if cfg.tower else ''}, eaves to "
        f"{cfg.eave_height[1]:.0f} m, gap {cfg.building_gap:.1f} m, GSD {cfg.gsd:.3f} m, {w}x{h} px, overlap "
        f"{100 * cfg.forward_overlap:.0f}/{100 * cfg.side_overlap:.0f}, obliques {cfg.n_oblique}"
        f"{' at ' + format(cfg.oblique_tilt_deg, '.0f') + ' deg' if cfg.n_oblique else ''}, JPEG q"
        f"{cfg.jpeg_quality}, shadows {cfg.shadow_strength:.2f}, "
        f"windows {'yes' if cfg.facade_windows else 'no'}"
        + (f", blur {cfg.optics_blur:.2f} px" if cfg.optics_blur else "")
        + (f", fields {100 * cfg.crop_share:.0f} % ({cfg.crop_height:.2f} m)" if cfg.crop_share else "")
    )


# ------------------------------------------------------------------ figures


def _maxf(a, n):
    from scipy.ndimage import maximum_filter

    return maximum_filter(a, size=n, mode="nearest")


def _minf(a, n):
    from scipy.ndimage import minimum_filter

    return minimum_filter(a, size=n, mode="nearest")


def dsm_masks(truth: np.ndarray, gsd: float, res: float) -> np.ndarray:
    """Cells within 2 GSD of a height step over 2 m of the truth (the 'edge' cells)."""
    step = (_maxf(truth, 3) - _minf(truth, 3)) > 2.0
    r = max(1, int(math.ceil(2.0 * gsd / res)))
    return _maxf(step.astype(np.uint8), 2 * r + 1).astype(bool)


def within_stalks(dsm: np.ndarray, truth: np.ndarray, stalks: np.ndarray) -> np.ndarray:
    """The truth a DSM is measured against: in a crop field any height from the soil to the stalks'
    tops is right (a DSM of a field lies in its stalk layer), so the truth there is the DSM's height
    clipped to that interval; elsewhere the soil or roof itself."""
    on = (stalks > 0) & np.isfinite(dsm)
    return np.where(on, np.clip(dsm, truth, truth + stalks), truth)


def dsm_figures(dsm: np.ndarray, truth: np.ndarray, seen2: np.ndarray, edge: np.ndarray, gsd: float) -> dict:
    """Completeness, NMAD (GSD) and shares within 3 GSD over the cells seen by >= 2 images."""
    e = dsm - truth
    ok = np.isfinite(e) & seen2
    if not ok.any():
        return {"completeness": 0.0, "nmad_gsd": float("nan"), "flat3": 0.0, "edge3": 0.0}
    nmad = 1.4826 * float(np.median(np.abs(e[ok] - np.median(e[ok]))))
    good = np.abs(np.nan_to_num(e, nan=1e9)) <= 3 * gsd
    return {
        "completeness": float(ok.sum() / seen2.sum()),
        "nmad_gsd": nmad / gsd,
        "flat3": float(good[seen2 & ~edge].mean()),
        "edge3": float(good[seen2 & edge].mean()) if (seen2 & edge).any() else 1.0,
    }


def edge_failures(
    dsm: np.ndarray, truth: np.ndarray, seen2: np.ndarray, edge: np.ndarray, gsd: float, res: float
) -> dict:
    """What the edge cells that ``edge3`` counts as wrong (off by more than 3 GSD) are, as shares of the
    edge cells seen by two images or more (the four classes add up to ``1 - edge3``).

    The side of a cell is that of its true height against the middle of the true heights around it
    (the edge band plus one cell): ``edge_holes`` no height; ``edge_fattened`` a low-side cell (ground
    at a wall's foot) above that middle, ``edge_eroded`` a high-side cell (a roof's rim) below it,
    ``edge_own_side`` on its own side but off (a step placed a cell or two off, a roof's slope or
    rim bent); ``edge_own_side_sloped`` the part of the latter where the true surface slopes more than
    0.5 (a pitched roof's eaves and gables).
    """
    r = max(1, int(math.ceil(2.0 * gsd / res))) + 1
    mid = 0.5 * (_maxf(truth, 2 * r + 1) + _minf(truth, 2 * r + 1))
    cells = seen2 & edge
    n = max(int(cells.sum()), 1)
    e = dsm - truth
    bad = cells & ~(np.abs(np.nan_to_num(e, nan=1e9)) <= 3 * gsd)
    has = np.isfinite(dsm)
    low = truth < mid
    fat = bad & has & low & (dsm > mid)
    ero = bad & has & ~low & (dsm < mid)
    own = bad & has & ~fat & ~ero
    gy, gx = np.gradient(np.where(np.isfinite(truth), truth, 0.0), res)
    steep = np.hypot(gx, gy) > 0.5
    return {
        "edge_holes": float((bad & ~has).sum() / n),
        "edge_fattened": float(fat.sum() / n),
        "edge_eroded": float(ero.sum() / n),
        "edge_own_side": float(own.sum() / n),
        "edge_own_side_sloped": float((own & steep).sum() / n),
    }


def relative_delta_e(rgb: np.ndarray, truth_rgb: np.ndarray, valid: np.ndarray) -> float:
    """Mean dE after the best global per-channel gain and offset from the result to the truth.

    A block's absolute exposure is not observable from its images (the colour correction fixes
    the block's mean gain at 1, the images' true mean gain is not 1), so mean dE mixes that
    constant offset with what a user sees: seams, colour casts between images, wrong sources.
    """
    from truortho.core.ortho import evaluate as ev

    a = rgb[valid].astype(np.float64)
    b = truth_rgb[valid].astype(np.float64)
    fitted = np.empty_like(a)
    for ch in range(3):
        A = np.column_stack([a[:, ch], np.ones(len(a))])
        coef, *_ = np.linalg.lstsq(A, b[:, ch], rcond=None)
        fitted[:, ch] = A @ coef
    fitted = np.clip(np.round(fitted), 0, 255).astype(np.uint8)
    return float(ev.delta_e(fitted[None], truth_rgb[valid][None]).mean()) if len(a) else float("nan")


def lowpass_relative_delta_e(rgb: np.ndarray, truth_rgb: np.ndarray, valid: np.ndarray, k: int = 5) -> float:
    """:func:`relative_delta_e` of the colours averaged over k x k cells (where the whole window is
    valid): casts and seams between images stay, the noise and JPEG artefacts of a single photo
    average out (a true ortho takes each cell from one photo, so it keeps their noise)."""
    import cv2

    m = valid.astype(np.float32)
    weight = np.maximum(cv2.blur(m, (k, k)), 1e-6)[..., None]
    core = cv2.erode(valid.astype(np.uint8), np.ones((k, k), np.uint8)) > 0

    def box(a: np.ndarray) -> np.ndarray:
        s = cv2.blur(a.astype(np.float32) * m[..., None], (k, k)) / weight
        return np.clip(np.round(s), 0, 255).astype(np.uint8)

    return relative_delta_e(box(rgb), box(truth_rgb), core) if core.any() else float("nan")


def ortho_figures(path: str, truth_rgb, buildings, seen, unseen_core, gsd: float, res: float) -> dict:
    import rasterio

    from truortho.core.ortho import evaluate as ev

    with rasterio.open(path) as ds:
        rgb = np.moveaxis(ds.read([1, 2, 3]), 0, -1)
        valid = ds.dataset_mask() > 0
    gh = ev.ghosting(rgb, truth_rgb, valid, buildings, 2.0 * gsd / res)
    # wrong colours 1-6 cells away from the outline: where a leaning or double-mapped building shows,
    # apart from the placement of the outline itself (the first cell), which ``ghosting`` also counts
    from scipy.ndimage import distance_transform_edt

    dist = np.where(buildings, distance_transform_edt(buildings), distance_transform_edt(~buildings)) - 0.5
    ring = valid & (dist > 1.0) & (dist <= 6.0)
    wrong = ev.delta_e(rgb, truth_rgb) > 25.0
    sh = ev.phase_shift(rgb.astype(float).mean(-1) / 255, truth_rgb.astype(float).mean(-1) / 255, valid)
    n_unseen = int(unseen_core.sum())
    return {
        "ghosting": gh["share"],
        "ghosting_beyond_outline": float(wrong[ring].mean()) if ring.any() else 0.0,
        "shift_gsd": sh["median"] * res / gsd,
        "coverage": ev.coverage(valid, seen),
        "mean_dE": ev.mean_delta_e(rgb, truth_rgb, valid & seen),
        "relative_dE": relative_delta_e(rgb, truth_rgb, valid & seen),
        "relative_dE_5x5": lowpass_relative_delta_e(rgb, truth_rgb, valid & seen),
        "wrong_fill": float((valid & unseen_core).sum() / n_unseen) if n_unseen else 0.0,
        "unseen_cells": n_unseen,
    }


# ------------------------------------------------------------------ one scene


def run_scene(index: int, seed: int, work: str, sgbm: bool, log, realistic: bool = False) -> dict:
    from scipy.ndimage import binary_erosion

    from truortho.core.ortho import evaluate as ev
    from truortho.core.ortho.pipeline import TrueOrthoConfig, true_ortho
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.rasterio_io import read_raster, write_raster
    from truortho.core.surface.filter import filter_dsm
    from truortho.core.surface.quality import streak_index
    from truortho.core.synthetic import make_scene

    cfg = draw_config(index, seed, realistic)
    log(f"scene {index}: {describe(cfg)}")
    t = time.perf_counter()
    scene = make_scene(cfg)
    folder = os.path.join(work, f"scene_{index:02d}")
    scene.write(folder)
    gsd = cfg.gsd
    truth, grid, _ = read_raster(os.path.join(folder, "dsm.tif"))
    res = grid.res
    truth_rgb, _ = scene.orthophoto(res)
    n_images = len(scene.orientation.images)
    log(f"  rendered {n_images} images in {time.perf_counter() - t:.1f} s; grid {grid.rows}x{grid.cols}")

    nvis = ev.truth_view_counts(scene, grid, tol=0.05)
    seen2 = nvis >= 2
    edge = dsm_masks(truth, gsd, res)
    buildings = ev.building_mask(scene, grid)
    ortho_angle = TrueOrthoConfig().max_view_angle
    seen_ortho = ev.truth_view_counts(scene, grid, ortho_angle, tol=0.05) >= 1
    unseen_core = binary_erosion(~seen_ortho, iterations=1)
    row: dict = {
        "scene": index,
        "config": describe(cfg),
        "images": n_images,
        "obliques": cfg.n_oblique,
        "cells": grid.rows * grid.cols,
        "gsd": gsd,
        "seen2": float(seen2.mean()),
        # base-to-height ratio of neighbouring nadir photos (the image height lies along the strip):
        # a height error of e GSD is a parallax error of e * B/H pixels between them
        "base_height": (1.0 - cfg.forward_overlap) * cfg.image_size[1] / cfg.focal_px,
    }

    zlo, zhi = float(np.nanmin(truth)) - 5.0, float(np.nanmax(truth)) + 5.0
    out = OsgmOutputs(dsm=os.path.join(folder, "osgm.tif"), confidence=os.path.join(folder, "osgm_conf.tif"))
    t = time.perf_counter()
    run_osgm(scene.orientation, OsgmConfig(resolution=res, z_min=zlo, z_max=zhi), scene.extent_world(), out,
             folder)  # fmt: skip
    t_osgm = time.perf_counter() - t
    dsm, _, _ = read_raster(out.dsm)
    stalks = scene.crop_heights(res)
    row["fields"] = float((stalks > 0).mean())
    # in crop fields any height in the stalk layer is right (without fields: the truth itself)
    ref = within_stalks(dsm, truth, stalks)
    row["osgm"] = dsm_figures(dsm, ref, seen2, edge, gsd)
    row["osgm"]["nmad_parallax_px"] = row["osgm"]["nmad_gsd"] * row["base_height"]
    # where the flat3 failures lie: cells seen by exactly two images are two-view stereo, often a
    # near-nadir photo and a steep oblique at the rim of the block
    err = np.abs(np.nan_to_num(dsm - ref, nan=1e9))
    seen3 = (nvis >= 3) & ~edge
    row["osgm"]["flat3_seen3"] = float((err[seen3] <= 3 * gsd).mean()) if seen3.any() else 1.0
    # cells only one image sees cannot be matched: a height there is a guess (a hole is right);
    # the share of those with a height more than 3 GSD off
    one = nvis == 1
    row["osgm"]["wrong_seen1"] = float((one & (err > 3 * gsd) & np.isfinite(dsm)).sum() / max(one.sum(), 1))
    row["osgm"].update(edge_failures(dsm, ref, seen2, edge, gsd, res))
    row["osgm"]["streak_index"] = streak_index(dsm)
    row["truth_streak_index"] = streak_index(truth)
    row["osgm"]["seconds"] = t_osgm
    row["osgm"]["s_per_mcell_image"] = t_osgm / (grid.rows * grid.cols * n_images / 1e6)
    log(f"  OSGM {t_osgm:.1f} s: {_fmt(row['osgm'])}")

    # the DSM the pipeline hands on: OSGM's, filtered with its confidence (truortho:dsmfilter defaults)
    t = time.perf_counter()
    filter_dsm(out.dsm, os.path.join(folder, "osgm_filtered.tif"), out.confidence)
    filtered, _, _ = read_raster(os.path.join(folder, "osgm_filtered.tif"))
    row["osgm_filtered"] = dsm_figures(filtered, within_stalks(filtered, truth, stalks), seen2, edge, gsd)
    row["osgm_filtered"]["seconds"] = time.perf_counter() - t
    log(f"  OSGM + DSM filter: {_fmt(row['osgm_filtered'])}")

    if sgbm:
        sys.path.insert(0, HERE)
        from sgbm_baseline import sgbm_dsm

        t = time.perf_counter()
        base, info = sgbm_dsm(scene.orientation, folder, grid, zlo, zhi)
        t_sgbm = time.perf_counter() - t
        row["sgbm"] = dsm_figures(base, within_stalks(base, truth, stalks), seen2, edge, gsd)
        row["sgbm"]["streak_index"] = streak_index(base)
        row["sgbm"].update(seconds=t_sgbm, pairs=info.get("pairs"))
        row["osgm_over_sgbm_time"] = t_osgm / t_sgbm
        log(f"  SGBM {t_sgbm:.1f} s: {_fmt(row['sgbm'])}")

    # what the ghosting goal asks of a DSM: the truth DSM with every outline one cell off (moved one
    # cell east; a DSM well inside the DSM goals), through the same true ortho (ortho_shift1)
    shifted = truth.copy()
    shifted[:, 1:] = truth[:, :-1]
    write_raster(os.path.join(folder, "dsm_shift1.tif"), shifted.astype(np.float32), grid, nodata=-9999.0)
    row["truth_shift1"] = dsm_figures(shifted, truth, seen2, edge, gsd)
    log(f"  truth DSM one cell off: {_fmt(row['truth_shift1'])}")
    # the colour edges (TrueOrthoConfig.edge_colour, default "checked") also without them, and in the
    # mode for exact surfaces
    runs = (
        ("ortho_truth", "dsm.tif", True, {}),
        ("ortho_conventional", "dsm.tif", False, {}),
        ("ortho_osgm", "osgm.tif", True, {}),
        ("ortho_filtered", "osgm_filtered.tif", True, {}),
        ("ortho_shift1", "dsm_shift1.tif", True, {}),
        ("ortho_truth_edge_off", "dsm.tif", True, {"edge_colour": "off"}),
        ("ortho_truth_edge_surface", "dsm.tif", True, {"edge_colour": "surface"}),
        ("ortho_osgm_edge_off", "osgm.tif", True, {"edge_colour": "off"}),
        ("ortho_osgm_edge_surface", "osgm.tif", True, {"edge_colour": "surface"}),
        # without the agreement of the views (TrueOrthoConfig.consistency, default 0.1)
        ("ortho_truth_agree_off", "dsm.tif", True, {"consistency": 0.0}),
        ("ortho_osgm_agree_off", "osgm.tif", True, {"consistency": 0.0}),
    )
    for key, surface, vis, changes in runs:
        path = os.path.join(folder, f"{key}.tif")
        t = time.perf_counter()
        occ = os.path.join(folder, f"{key}_occ.tif")
        ocfg = TrueOrthoConfig(resolution=res, visibility=vis, extent=scene.extent_world(), **changes)
        true_ortho(
            scene.orientation, os.path.join(folder, surface), path, None, occ, config=ocfg, image_root=folder
        )
        row[key] = ortho_figures(path, truth_rgb, buildings, seen_ortho, unseen_core, gsd, res)
        row[key]["seconds"] = time.perf_counter() - t
        log(f"  {key}: {_fmt(row[key])}")
    pictures(folder, os.path.join(HERE, "results", "acceptance", f"scene_{index:02d}.jpg"))
    conv = row["ortho_conventional"]["ghosting"]
    row["ortho_truth"]["ghosting_vs_conventional"] = row["ortho_truth"]["ghosting"] / conv if conv else 0.0
    row["passed"] = [name for name, _, _ in GOALS if meets(row, name)]
    row["failed"] = [name for name, _, _ in GOALS if not meets(row, name)]
    log(f"  goals failed: {', '.join(row['failed']) or 'none'}")
    return row


def hillshade_bgr(path: str) -> np.ndarray:
    """Hillshade (BGR uint8, light from the north-west at 45 degrees) of a DSM; holes red."""
    import cv2
    import rasterio

    with rasterio.open(path) as ds:
        z = ds.read(1, masked=True).filled(np.nan).astype(np.float64)
        res = ds.res[0]
    gy, gx = np.gradient(np.where(np.isfinite(z), z, np.nanmin(z)), res)
    slope, aspect = np.arctan(np.hypot(gx, gy)), np.arctan2(-gx, gy)
    alt, az = np.radians(45.0), np.radians(315.0)
    h = np.sin(alt) * np.cos(slope) + np.cos(alt) * np.sin(slope) * np.cos(az - aspect)
    img = cv2.cvtColor((np.clip(h, 0, 1) * 255).astype(np.uint8), cv2.COLOR_GRAY2BGR)
    img[~np.isfinite(z)] = (0, 0, 255)
    return img


def ortho_bgr(path: str) -> np.ndarray:
    """The first three bands of an orthophoto as BGR uint8; cells without data magenta."""
    import rasterio

    with rasterio.open(path) as ds:
        a = np.moveaxis(ds.read([1, 2, 3]), 0, -1)[:, :, ::-1].copy()
        a[ds.dataset_mask() == 0] = (255, 0, 255)
    return a


def save_mosaic(rows: list[list[np.ndarray]], path: str, width: float = 1200.0) -> None:
    """Tiles (cropped to the smallest) in rows, scaled to ``width`` pixels at most, as a JPEG."""
    import cv2

    h = min(t.shape[0] for r in rows for t in r)
    w = min(t.shape[1] for r in rows for t in r)
    out = np.vstack([np.hstack([t[:h, :w] for t in r]) for r in rows])
    scale = min(1.0, width / out.shape[1])
    os.makedirs(os.path.dirname(path), exist_ok=True)
    cv2.imwrite(path, cv2.resize(out, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA),
                [cv2.IMWRITE_JPEG_QUALITY, 85])  # fmt: skip


def pictures(folder: str, path: str) -> None:
    """One JPEG per scene: hillshades of the truth and OSGM DSMs over the true orthos on them."""
    f = lambda name: os.path.join(folder, name)  # noqa: E731
    save_mosaic([[hillshade_bgr(f("dsm.tif")), hillshade_bgr(f("osgm.tif"))],
                 [ortho_bgr(f("ortho_truth.tif")), ortho_bgr(f("ortho_osgm.tif"))]], path)  # fmt: skip


def _fmt(d: dict) -> str:
    return ", ".join(f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in d.items())


def value(row: dict, name: str) -> float:
    part, key = name.split(".")
    return float(row.get(part, {}).get(key, float("nan")))


def meets(row: dict, name: str) -> bool:
    cmp, goal = next((c, g) for n, c, g in GOALS if n == name)
    v = value(row, name)
    if not math.isfinite(v):
        return False
    return v >= goal if cmp == ">=" else v <= goal + 1e-12


# ------------------------------------------------------------------ report


def summary(rows: list[dict]) -> list[str]:
    lines = ["| figure | goal | median | worst | scenes meeting the goal |", "|---|---|---|---|---|"]
    for name, cmp, goal in GOALS:
        vals = np.array([value(r, name) for r in rows])
        worst = np.nanmin(vals) if cmp == ">=" else np.nanmax(vals)
        ok = sum(meets(r, name) for r in rows)
        lines.append(
            f"| {name} | {cmp} {goal:g} | {np.nanmedian(vals):.4g} | {worst:.4g} | {ok} / {len(rows)} |"
        )
    if all("sgbm" in r for r in rows):
        for name in ("completeness", "nmad_gsd", "flat3", "edge3", "seconds"):
            o = np.array([r["osgm"][name] for r in rows])
            s = np.array([r["sgbm"][name] for r in rows])
            lines.append(
                f"| SGBM baseline {name} (OSGM median) | | {np.nanmedian(s):.4g} ({np.nanmedian(o):.4g}) | "
                f"{np.nanmax(s) if name in ('nmad_gsd', 'seconds') else np.nanmin(s):.4g} | |"
            )
        ratio = np.array([r["osgm_over_sgbm_time"] for r in rows])
        lines.append(
            f"| OSGM time / SGBM time | <= 1 | {np.median(ratio):.3g} | {ratio.max():.3g} | "
            f"{int((ratio <= 1).sum())} / {len(rows)} |"
        )
    informative = (
        "ortho_truth.ghosting_beyond_outline",
        "ortho_osgm.ghosting_beyond_outline",
        "ortho_conventional.ghosting_beyond_outline",
        "osgm.nmad_parallax_px",
        "osgm.flat3_seen3",
        "osgm.wrong_seen1",
        "osgm.edge_holes",
        "osgm.edge_fattened",
        "osgm.edge_eroded",
        "osgm.edge_own_side",
        "osgm.edge_own_side_sloped",
        "osgm_filtered.completeness",
        "osgm_filtered.nmad_gsd",
        "osgm_filtered.flat3",
        "osgm_filtered.edge3",
        "ortho_filtered.ghosting",
        "ortho_filtered.shift_gsd",
        "ortho_truth.relative_dE",
        "ortho_truth.relative_dE_5x5",
        "ortho_osgm.mean_dE",
        "ortho_osgm.relative_dE",
        "ortho_osgm.wrong_fill",
        "ortho_conventional.ghosting",
        "ortho_truth_edge_off.ghosting",
        "ortho_truth_edge_surface.ghosting",
        "ortho_osgm_edge_off.ghosting",
        "ortho_osgm_edge_surface.ghosting",
        "ortho_osgm_edge_off.ghosting_beyond_outline",
        "ortho_truth_agree_off.ghosting",
        "ortho_truth_agree_off.relative_dE",
        "ortho_osgm_agree_off.ghosting",
        "ortho_osgm_agree_off.ghosting_beyond_outline",
        "ortho_osgm_agree_off.relative_dE",
        "truth_shift1.edge3",
        "truth_shift1.flat3",
        "ortho_shift1.ghosting",
        "osgm.streak_index",
        "truth_streak_index",
    )
    for name in informative:
        vals = np.array([value(r, name) if "." in name else r[name] for r in rows])
        low_is_bad = any(k in name for k in ("completeness", "flat3", "edge3"))  # flat3_seen3 too
        worst = np.nanmin(vals) if low_is_bad else np.nanmax(vals)
        lines.append(f"| {name} (not a goal) | | {np.nanmedian(vals):.4g} | {worst:.4g} | |")
    # the agreement of the views, scene by scene: with it (the default) against without
    for key, name in (
        ("ortho_truth", "ghosting"),
        ("ortho_truth", "relative_dE"),
        ("ortho_osgm", "ghosting"),
        ("ortho_osgm", "ghosting_beyond_outline"),
        ("ortho_osgm", "relative_dE"),
    ):
        if all(f"{key}_agree_off" in r for r in rows):
            on = np.array([r[key][name] for r in rows])
            off = np.array([r[f"{key}_agree_off"][name] for r in rows])
            lines.append(
                f"| {key}.{name}: scenes lower / higher than without the agreement of the views "
                f"(not a goal) | | {int((on < off).sum())} / {int((on > off).sum())} | "
                f"{np.max(on - off):+.4g} | |"
            )
    if all("ortho_osgm_agree_off" in r for r in rows):
        t = np.array(
            [
                (r["ortho_truth"]["seconds"] + r["ortho_osgm"]["seconds"])
                / (r["ortho_truth_agree_off"]["seconds"] + r["ortho_osgm_agree_off"]["seconds"])
                for r in rows
            ]
        )
        lines.append(
            f"| true ortho time with / without the agreement of the views | | {np.median(t):.3g} | "
            f"{t.max():.3g} | |"
        )
    spm = np.array([r["osgm"]["s_per_mcell_image"] for r in rows])
    lines.append(f"| OSGM s per million (cells x images) | | {np.median(spm):.3g} | {spm.max():.3g} | |")
    allok = sum(not r["failed"] for r in rows)
    lines.append(f"| **every goal** | | | | **{allok} / {len(rows)}** |")
    return lines


def scene_table(rows: list[dict]) -> list[str]:
    head = (
        "| # | imgs (obl) | B/H | OSGM compl | NMAD | flat3 | edge3 | s | "
        "SGBM compl | NMAD | flat3 | edge3 | s | "
        "ghost truth | conv | ghost OSGM | shift | dE | wrong fill | failed |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        o, s = r["osgm"], r.get("sgbm")
        t, c, g = r["ortho_truth"], r["ortho_conventional"], r["ortho_osgm"]
        sg = (
            (
                f"{100 * s['completeness']:.1f} | {s['nmad_gsd']:.2f} | {100 * s['flat3']:.1f} | "
                f"{100 * s['edge3']:.1f} | {s['seconds']:.0f}"
            )
            if s
            else "- | - | - | - | -"
        )
        lines.append(
            f"| {r['scene']} | {r['images']} ({r['obliques']}) | {r.get('base_height', float('nan')):.2f} | "
            f"{100 * o['completeness']:.1f} | "
            f"{o['nmad_gsd']:.2f} | "
            f"{100 * o['flat3']:.1f} | {100 * o['edge3']:.1f} | {o['seconds']:.0f} | {sg} | "
            f"{100 * t['ghosting']:.2f} | {100 * c['ghosting']:.1f} | {100 * g['ghosting']:.2f} | "
            f"{t['shift_gsd']:.2f} | {t['mean_dE']:.2f} | {100 * t['wrong_fill']:.2f} | "
            f"{', '.join(r['failed']) or '-'} |"
        )
    return lines


def run_header(script: str, argv, detail: str = "", started: str | None = None) -> tuple[str, str, str]:
    """``(command, commit, head)`` of a run of ``bench/<script>``: the head line of its docs section
    (command, commit, date, machine, ``detail``).

    ``started``: the commit when the run started (:func:`_docs.commit`, ``+dirty`` for a changed
    tree); the figures are that code's. If HEAD moved during the run, the head says so.
    """
    sys.path.insert(0, HERE)
    from _docs import load_average, measured_commit, shown_argv

    cmd = f"python -P bench/{script} " + " ".join(shown_argv(argv if argv is not None else sys.argv[1:]))

    commit = measured_commit(started)

    head = (f"`{cmd.strip()}` on {commit or '?'}, {datetime.date.today()}, {platform.machine()} "
            f"{os.cpu_count()} cores{load_average()}" + (f", {detail}" if detail else ""))  # fmt: skip
    return cmd, commit, head


def write_docs(text: str, section: str = "acceptance") -> None:
    """Replace the marked ``section`` of docs/acceptance.md with ``text``."""
    begin, end = f"<!-- {section}:begin -->", f"<!-- {section}:end -->"
    doc = (
        open(DOCS, encoding="utf-8").read()
        if os.path.exists(DOCS)
        else f"# Acceptance battery\n\n{begin}\n{end}\n"
    )
    if begin not in doc or end not in doc:
        raise SystemExit(f"{DOCS}: the markers {begin} / {end} are missing")
    new = doc[: doc.index(begin) + len(begin)] + "\n" + text + "\n" + doc[doc.index(end) :]
    tmp = DOCS + ".tmp"
    with open(tmp, "w", encoding="utf-8") as fh:
        fh.write(new)
    os.replace(tmp, DOCS)


def warm_up(work: str, log) -> None:
    """Runs OSGM and a true ortho on its DSM once on a tiny scene, so that no measured time includes
    numba's compilation of kernels whose cache is stale (after a code change, or on a fresh
    installation: once per installation, not per run). The first scene of this battery had read
    15 s instead of 7 after an edit; fountain-P11's ``truortho:osgm`` 132-134 s with a cold cache
    against 81-84 s warm (in-process, at 8d51276 and 9c73f60). The compiled kernels are cached
    next to the sources, so ``qgis_process`` runs of the same checkout load them too."""
    from truortho.core.ortho.pipeline import true_ortho
    from truortho.core.osgm import OsgmConfig, OsgmOutputs, run_osgm
    from truortho.core.synthetic import SceneConfig, make_scene

    t = time.perf_counter()
    cfg = SceneConfig(image_size=(160, 120), focal_px=200.0, n_buildings=2, n_oblique=0, seed=1)
    scene = make_scene(cfg)
    folder = os.path.join(work, "warm_up")
    scene.write(folder)
    out = OsgmOutputs(dsm=os.path.join(folder, "osgm.tif"))
    run_osgm(scene.orientation, OsgmConfig(resolution=cfg.gsd), scene.extent_world(), out, folder)
    true_ortho(scene.orientation, out.dsm, os.path.join(folder, "ortho.tif"), image_root=folder)
    shutil.rmtree(folder, ignore_errors=True)
    log(f"warm-up (compiled kernels loaded or compiled): {time.perf_counter() - t:.1f} s")


#: The master seed of the battery's main docs section; another seed's run writes the section
#: ``acceptance-seed<N>`` (:func:`docs_section`), which must exist in the docs.
SEED = 2026


def docs_section(seed: int, realistic: bool = False) -> str:
    """The docs section a run of master seed ``seed`` (with ``--realistic``) writes."""
    if realistic:
        return f"acceptance-seed{seed}-realistic"
    return "acceptance" if seed == SEED else f"acceptance-seed{seed}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", type=int, default=12)
    seed_help = f"master seed (default {SEED}); another one writes its own docs section"
    ap.add_argument("--seed", type=int, default=SEED, help=seed_help)
    ap.add_argument("--only", default="", help="comma-separated scene indices (default all)")
    ap.add_argument("--no-sgbm", action="store_true", help="skip the pairwise SGBM baseline")
    ap.add_argument("--realistic", action="store_true",
                    help="also draw an optics blur, crop fields and a real block's JPEG quality per scene "
                         "(own docs section)")  # fmt: skip
    ap.add_argument("--keep", default="", help="keep the scenes and products in this folder")
    ap.add_argument("--write-docs", action="store_true", help=f"update the marked section of {DOCS}")
    ap.add_argument("--report", default="", help="print (and with --write-docs write) the tables of a saved "
                    "results JSON instead of running")  # fmt: skip
    args = ap.parse_args(argv)
    if args.report:
        with open(args.report) as fh:
            saved = json.load(fh)
        text = "\n".join([saved["head"], "", *summary(saved["rows"]), "", *scene_table(saved["rows"]), ""])
        print(text)
        if args.write_docs:
            section = docs_section(int(saved.get("seed", SEED)), bool(saved.get("realistic", False)))
            write_docs(text, section)
        return 0
    indices = [int(v) for v in args.only.split(",") if v] or list(range(args.scenes))
    work = args.keep or tempfile.mkdtemp(prefix="truortho-acceptance-")
    os.makedirs(work, exist_ok=True)

    def log(msg: str) -> None:
        print(msg, flush=True)

    sys.path.insert(0, HERE)
    from _docs import commit as head_commit

    started = head_commit()  # the code measured: taken before the run, not after it
    t0 = time.perf_counter()
    rows = []
    try:
        warm_up(work, log)
        for i in indices:
            rows.append(run_scene(i, args.seed, work, not args.no_sgbm, log, args.realistic))
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    wall = time.perf_counter() - t0
    import cv2

    cmd, commit, head = run_header("acceptance.py", argv, f"OpenCV {cv2.__version__}", started)
    kind = " (realistic)" if args.realistic else ""
    head += f"; {len(rows)} scenes, master seed {args.seed}{kind}, {wall / 60:.1f} min"
    text = "\n".join([head, "", *summary(rows), "", *scene_table(rows), ""])
    print("\n" + text)
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    name = "acceptance_only.json" if args.only else "acceptance.json"
    with open(os.path.join(HERE, "results", name), "w") as fh:
        json.dump(
            {"command": cmd, "commit": commit, "seed": args.seed, "realistic": args.realistic, "head": head,
             "rows": rows}, fh, indent=1  # fmt: skip
        )
    if args.write_docs:
        write_docs(text, docs_section(args.seed, args.realistic))
    return 0


if __name__ == "__main__":
    sys.exit(main())
