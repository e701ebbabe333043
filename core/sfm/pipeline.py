"""Image orientation from photos (and ground control) to an adjusted :class:`Orientation`.

Stages (each reports progress and honours cancel):

1. image inventory (non-image files are skipped with a warning), EXIF,
   interior-orientation priors (a given file; EXIF focal length and sensor;
   or the documented default ``f = 1.2 max(w, h)``), one camera per
   (size, make, model, focal length) group;
2. pair selection (exhaustive for small blocks, EXIF GNSS footprints, or a
   low-resolution retrieval pass);
3. SIFT features at the working resolution (cached) and robust two-view
   verification of the selected pairs;
4. tracks, decimated on a grid per image by multiplicity;
5. incremental reconstruction with bundle adjustment (:mod:`.incremental`);
6. datum: GCPs with check points, else EXIF GNSS priors, else an arbitrary
   frame (:mod:`.georef`); final adjustment;
7. the orientation (JSON model), tie points and the report.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import FormatError, InputError, MissingFileError
from ..geometry.camera import Camera
from ..geometry.frame import (
    LocalFrame,
    choose_offset,
    crs_to_text,
    parse_crs,
    require_metric,
    transform_points,
)
from ..orientation import GCP, Image, Orientation, SparsePoints
from ..progress import Progress, Steps, SubProgress, as_progress, check
from ..report import Report
from .bundle import BundleConfig, BundleProblem, bundle_adjust
from .georef import Block, GeorefConfig, GeorefResult, block_from_reconstruction, georeference, validate_gcps
from .incremental import IncrementalConfig, reconstruct
from .report import orientation_report

ALL_INTRINSICS = ("f", "cx", "cy", "k1", "k2", "p1", "p2")


@dataclass
class OrientConfig:
    """Options of :func:`orient_images`."""

    #: Larger image side at which features are detected, pixels.
    working_size: int = 2000
    #: Features per image.
    max_features: int = 8000
    #: Self-calibrate the interior orientation (else it is held).
    self_calibration: bool = True
    #: Intrinsics estimated by self-calibration (subset of f, cx, cy, k1, k2, k3, p1, p2); with a
    #: given interior orientation file and this default, only ``f`` is refined (the file is a calibration).
    refine_intrinsics: tuple[str, ...] = ALL_INTRINSICS
    #: Tie-point decimation grid cell, pixels at full resolution (None: from the block size, see
    #: :func:`decimation_cell`).
    decimation_cell_px: float | None = None
    #: Every image pair keeps at least this many of its shared tie points through the decimation
    #: (the links of weakly connected images; see :func:`~.tracks.decimate_tracks`).
    min_pair_tracks: int = 150
    #: Pair selection strategy: auto, exhaustive, gps, retrieval.
    pair_strategy: str = "auto"
    #: The second matching pass pairs every image left out by the reconstruction with at most this
    #: many others, nearest (GPS) or most similar (retrieval) first (:func:`second_pass_pairs`);
    #: 0 pairs it with all. Bounded, the pass stays linear in the block size.
    second_pass_partners: int = 40
    #: Refine the tie-point observations by least-squares matching against a master image at the
    #: working resolution after the adjustment, then adjust again (:mod:`truortho.core.gcp.tiepoints`;
    #: keeps every registered image's grey working image in memory).
    refine_tie_points: bool = False
    incremental: IncrementalConfig = field(default_factory=IncrementalConfig)
    georef: GeorefConfig = field(default_factory=GeorefConfig)


@dataclass
class OrientationRun:
    """Products of :func:`orient_images`.

    Attributes
    ----------
    orientation : Orientation
    report : Report
    tie_xyz : (P, 3)
        Tie points in the world CRS (or the arbitrary frame).
    tie_multiplicity, tie_error, tie_rgb : (P,), (P,), (P, 3)
        Images per point, mean reprojection error (px), colour.
    gcp_residuals : list of dict
        ``name, role, x, y, z, dx, dy, dz, views`` (adjusted/triangulated minus surveyed).
    """

    orientation: Orientation
    report: Report
    tie_xyz: np.ndarray
    tie_multiplicity: np.ndarray
    tie_error: np.ndarray
    tie_rgb: np.ndarray
    gcp_residuals: list[dict]


def read_k_matrix(path) -> np.ndarray:
    """A 3x3 calibration matrix from a text file (3 rows of 3 numbers)."""
    try:
        rows = [ln.split() for ln in open(path, encoding="utf-8").read().splitlines() if ln.strip()]
        K = np.array([[float(v) for v in r] for r in rows])
    except (OSError, UnicodeDecodeError, ValueError) as err:
        raise FormatError(path, f"expected a 3x3 matrix of numbers: {err}") from None
    if K.shape != (3, 3) or not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
        raise FormatError(
            path, f"expected a 3x3 calibration matrix with positive focal lengths, got shape {K.shape}"
        )
    return K


def _camera_priors(paths, infos, exifs, camera_file, warnings):
    """Cameras (list) and the camera index of every image."""
    from ..exif import focal_prior_px

    if camera_file:
        if not os.path.isfile(camera_file):
            raise MissingFileError(camera_file, "interior orientation file (CAMERA) not found")
        if str(camera_file).lower().endswith((".yaml", ".yml", ".json")):
            from ..formats.opk import read_interior

            cams, w = read_interior(camera_file)
            warnings += w
            cam_list = list(cams.values())
            if len(cam_list) != 1:
                raise InputError(
                    f"{camera_file}: {len(cam_list)} cameras defined; exactly one is supported here"
                )
            cam = cam_list[0]
        else:
            K = read_k_matrix(camera_file)
            cam = Camera(infos[0].width, infos[0].height, K[0, 0], K[1, 1], K[0, 2], K[1, 2], id="camera")
        for p, info in zip(paths, infos, strict=True):
            if (info.width, info.height) != (cam.width, cam.height):
                raise InputError(
                    f"{p}: image size {info.width}x{info.height} differs from the camera's "
                    f"{cam.width}x{cam.height} in {camera_file}"
                )
        return (
            [cam],
            np.zeros(len(paths), dtype=np.int64),
            {"interior": f"file {os.path.basename(camera_file)}"},
        )
    groups: dict[tuple, int] = {}
    cams: list[Camera] = []
    index = np.zeros(len(paths), dtype=np.int64)
    sources = {}
    for k, (info, ex) in enumerate(zip(infos, exifs, strict=True)):
        key = (
            info.width,
            info.height,
            ex.make if ex else None,
            ex.model if ex else None,
            ex.focal_mm if ex else None,
        )
        if key not in groups:
            f, source = focal_prior_px(ex, info.width, info.height)
            name = f"camera{len(cams) + 1}" if not (ex and ex.model) else f"{ex.model} {len(cams) + 1}"
            cams.append(
                Camera(info.width, info.height, f, f, (info.width - 1) / 2, (info.height - 1) / 2, id=name)
            )
            groups[key] = len(cams) - 1
            sources[name] = source
            if source == "default":
                warnings.append(
                    f"{name}: no usable EXIF focal length; starting from f = 1.2 x max(w, h) = {f:.0f} px "
                    "(refined by self-calibration)"
                )
        index[k] = groups[key]
    return cams, index, {"interior": sources}


def _inventory(paths, warnings):
    from ..imagery import image_info

    ok_paths, infos = [], []
    for p in paths:
        try:
            infos.append(image_info(p))
            ok_paths.append(os.fspath(p))
        except (FormatError, MissingFileError) as err:
            warnings.append(f"skipped {os.path.basename(os.fspath(p))}: not a readable image ({err})")
    if len(ok_paths) < 2:
        raise InputError(f"IMAGES: at least two images are needed, found {len(ok_paths)} readable image(s)")
    return ok_paths, infos


def _gps_local(exifs, crs_text_, warnings):
    """EXIF GNSS positions in the CRS (world), NaN where absent; the CRS used."""
    have = [e is not None and e.has_gps and e.altitude is not None for e in exifs]
    if sum(have) < 3:
        return None, crs_text_
    lat = np.array([e.latitude if h else np.nan for e, h in zip(exifs, have, strict=True)])
    lon = np.array([e.longitude if h else np.nan for e, h in zip(exifs, have, strict=True)])
    alt = np.array([e.altitude if h else np.nan for e, h in zip(exifs, have, strict=True)])
    if crs_text_ is None:
        from pyproj.aoi import AreaOfInterest
        from pyproj.database import query_utm_crs_info

        lon0, lat0 = float(np.nanmean(lon)), float(np.nanmean(lat))
        # AreaOfInterest(west, south, east, north): a point at the block's mean position
        aoi = AreaOfInterest(lon0, lat0, lon0, lat0)
        info = query_utm_crs_info(datum_name="WGS 84", area_of_interest=aoi)
        crs_text_ = f"EPSG:{info[0].code}" if info else None
        if crs_text_ is None:
            return None, None
        warnings.append(f"no CRS given: using {crs_text_} (UTM zone of the GNSS positions)")
    has = np.array(have)
    xyz = np.full((len(exifs), 3), np.nan)
    # only the images with a position: pyproj's error check refuses NaN coordinates
    xyz[has] = transform_points(np.column_stack([lon, lat, alt])[has], "EPSG:4979", crs_text_)
    return xyz, crs_text_


#: Decimation keeps about this many grid cells per image in total over the block ...
TIE_CELL_BUDGET = 150_000
#: ... but never fewer than the first or more than the second per image.
TIE_CELLS_PER_IMAGE = (2500, 10000)


def decimation_cell(max_size_px: float, n_images: int) -> float:
    """Grid cell (pixels) of the tie-point decimation for a block of ``n_images``.

    Decimation bounds the adjustment's size on large blocks; small blocks can afford more
    tie points, which makes their orientation more precise. The grid has
    ``clip(TIE_CELL_BUDGET / n_images, *TIE_CELLS_PER_IMAGE)`` cells per image (50 x 50 cells
    for 60 images or more, 100 x 100 for 15 or fewer), and a cell is never smaller than 8 px.
    """
    lo, hi = TIE_CELLS_PER_IMAGE
    cells = min(hi, max(lo, TIE_CELL_BUDGET / max(int(n_images), 1)))
    return max(float(max_size_px) / math.sqrt(cells), 8.0)


@dataclass(frozen=True)
class OrientInputs:
    """Stage 1 of :func:`orient_images`: the images, their EXIF and camera priors.

    ``paths``/``infos``/``names``/``exifs`` of the N image files kept; ``cams`` the camera models
    and ``image_camera`` (N,) the camera of every image; ``crs`` the checked CRS text (or None).
    """

    paths: list[str]
    infos: list
    names: list[str]
    exifs: list
    cams: Any
    image_camera: np.ndarray
    cam_info: Any
    crs: str | None


@dataclass(frozen=True)
class OrientMatches:
    """Stages 2-3: features of every image, the pairs tried and their verified matches."""

    features: Any
    feature_stats: dict
    cache: str | None
    selection: Any
    results: list
    match_stats: dict
    n_verified: int
    sizes: np.ndarray
    per_image_cams: list


@dataclass(frozen=True)
class OrientReconstruction:
    """Stages 4-5: the tracks of the model and the incremental reconstruction.

    ``matches``/``n_verified`` include a second matching pass for unregistered images;
    ``refine`` the intrinsics the adjustment refines.
    """

    rec: Any
    tracks: Any
    results: list
    n_verified: int
    refine: tuple


@dataclass(frozen=True)
class OrientGeoref:
    """Stage 6: the block adjusted in its frame (GCPs, GNSS, or free), with its offset and CRS."""

    block: Block
    track_ids: np.ndarray
    georef_config: GeorefConfig
    offset: np.ndarray
    gps_local: np.ndarray | None
    geo: Any
    bundle: Any
    crs: str | None


def read_inputs(paths, camera_file, gcps: list[GCP], crs, warnings: list[str], step, prog) -> OrientInputs:
    """Inventory, GCP names, EXIF and camera priors (stage 1 of :func:`orient_images`).

    Raises
    ------
    InputError
        Duplicate file names, GCPs without a CRS, a non-metric CRS, unreadable priors.
    """
    from ..exif import read_exif

    if crs is not None:
        pc = parse_crs(crs)
        require_metric(pc, "CRS")
        crs = crs_to_text(pc)
    paths, infos = _inventory(list(paths), warnings)
    names = [os.path.basename(p) for p in paths]
    if len(set(names)) != len(names):
        raise InputError("IMAGES: two images share a file name; GCP measurements refer to images by name")
    if gcps:
        warnings += validate_gcps(gcps, set(names))
        if crs is None:
            raise InputError("GCPS: ground control needs a CRS (give CRS or a GCP layer with a CRS)")
    exifs = []
    for k, p in enumerate(paths):
        check(prog)
        step.update(k / len(paths), "reading EXIF")
        exifs.append(read_exif(p))
    cams, image_camera, cam_info = _camera_priors(paths, infos, exifs, camera_file, warnings)
    return OrientInputs(paths, infos, names, exifs, cams, image_camera, cam_info, crs)


def choose_pairs(inputs: OrientInputs, cfg: OrientConfig, work_dir, step):
    """The pairs to match (:func:`~.pairs.select_pairs`: exhaustive, EXIF GNSS footprints or retrieval).

    Chosen before the features: none of the strategies needs them (retrieval has its own
    low-resolution pass), and the pair count sets the matching's share of the progress.
    """
    from .pairs import PairConfig, select_pairs

    cache = os.path.join(work_dir, "features") if work_dir else None
    sizes = np.array([[i.width, i.height] for i in inputs.infos])
    focals = np.array([inputs.cams[c].fx for c in inputs.image_camera])
    return select_pairs(
        inputs.paths, inputs.exifs, sizes, focals, PairConfig(strategy=cfg.pair_strategy), cache, step
    )


#: Relative costs of the orientation's stages per image (features, tracks, reconstruction,
#: datum and final adjustment, report) and per selected pair (matching and two-view verification),
#: at the default working size and feature count. They split the progress bar between the stages
#: so that the time-left estimate (:class:`~truortho.core.progress.EtaProgress`) holds from the
#: first minute: with fixed shares it read "about 15 min left" for the 19 minutes that 6,915 pairs
#: took. Measured on the 406-photo 3 MP scale block (bench_scale): features 0.66 s per image,
#: matching 0.165 s per pair, tracks to the final adjustment 0.6 s per image.
STAGE_COSTS = {
    "features": 4.0, "pair": 1.0, "tracks": 0.2, "reconstruction": 2.6, "datum": 0.8, "report": 0.1,
}  # fmt: skip


def stage_weights(n_images: int, n_pairs: int) -> list[float]:
    """Progress weights of features, matching, tracks, reconstruction, datum and report."""
    c = STAGE_COSTS
    n = max(int(n_images), 1)
    pairs = max(int(n_pairs), 1)
    per_image = [c[k] * n for k in ("tracks", "reconstruction", "datum", "report")]
    return [c["features"] * n, c["pair"] * pairs, *per_image]


def match_images(inputs: OrientInputs, cfg: OrientConfig, work_dir, sel, steps, times: dict) -> OrientMatches:
    """SIFT features (cached in ``work_dir``) and verified matches of the pairs ``sel`` (stages 2-3).

    ``sel`` is :func:`choose_pairs`' selection; ``steps`` are the features' and the matching's
    progress steps; ``times`` gets their wall times.

    Raises
    ------
    InputError
        No pair could be matched.
    """
    from .features import FeatureConfig, extract_all
    from .matching import match_pairs

    t = time.perf_counter()
    fcfg = FeatureConfig(max_dimension=cfg.working_size, max_features=cfg.max_features)
    cache = os.path.join(work_dir, "features") if work_dir else None
    features, fstats = extract_all(inputs.paths, fcfg, cache, steps[0])
    times["features"] = time.perf_counter() - t

    t = time.perf_counter()
    sizes = np.array([[i.width, i.height] for i in inputs.infos])
    per_image_cams = [inputs.cams[c] for c in inputs.image_camera]
    results, mstats = match_pairs(features, sel.pairs, per_image_cams, progress=steps[1])
    n_verified = sum(r.ok for r in results)
    times["matching"] = time.perf_counter() - t
    if n_verified == 0:
        raise InputError(
            "IMAGES: no image pair could be matched; the images do not overlap "
            f"({sel.n_pairs} pairs tried, strategy {sel.strategy})"
        )
    return OrientMatches(features, fstats, cache, sel, results, mstats, n_verified, sizes, per_image_cams)


def second_pass_pairs(sel, missing, partners: int) -> list[tuple[int, int]]:
    """Pairs ``(i, j)``, ``i < j``, of a second matching pass for the images ``missing``.

    Every missing image is paired with the images it was not paired with yet, the
    ``partners`` nearest by GPS position (``sel.details["local_xy"]``) or most similar by
    retrieval (``sel.details["similarity"]``) first; with neither, or ``partners`` 0, with all
    of them. Matching a left-out image against the whole block made the pass quadratic in the
    block size (a few left-out images of a 1,000-image block: thousands of pairs).
    """
    if int(partners) < 0:
        raise InputError(f"second_pass_partners must be 0 (all) or positive, got {partners!r}")
    n = int(sel.n_images)
    tried = {(int(a), int(b)) for a, b in sel.pairs}
    xy = sel.details.get("local_xy")
    sim = sel.details.get("similarity")
    out: set[tuple[int, int]] = set()
    for m in (int(v) for v in missing):
        others = np.array([j for j in range(n) if j != m and (min(m, j), max(m, j)) not in tried], np.int64)
        if partners > 0 and len(others) > partners:
            if xy is not None:
                key = np.linalg.norm(np.asarray(xy)[others] - np.asarray(xy)[m], axis=1)
                others = others[np.argsort(key, kind="stable")[:partners]]
            elif sim is not None:
                key = -np.asarray(sim)[m, others]
                others = others[np.argsort(key, kind="stable")[:partners]]
        out |= {(min(m, int(j)), max(m, int(j))) for j in others}
    return sorted(out)


def skipped_pairs_of(results, missing) -> set[int]:
    """Indices of the ``results`` (:class:`~.matching.PairMatches`) of pairs with an image in
    ``missing`` that the coarse pass took as not overlapping (``skipped``): the second pass
    matches them whole, since a left-out image may need exactly such a weak link."""
    lost = {int(v) for v in missing}
    return {k for k, r in enumerate(results) if r.skipped and (r.i in lost or r.j in lost)}


def second_pass_plan(sel, results, missing, partners: int):
    """The second matching pass for the images ``missing`` (left out by the reconstruction).

    Returns
    -------
    new : list of (i, j)
        Pairs of a missing image with images it was not paired with yet
        (:func:`second_pass_pairs`), to be matched as in the first pass: a pair whose coarse pass
        finds no overlap is skipped. On copr (3 photos left out, 114 new pairs) matching them whole
        kept the reconstruction stage at 186 s, as in the first pass 57 s (orientation 275 ->
        131 s with the features cached, one loaded machine), with 41 of 41 photos registered and
        the same check points both ways.
    whole : list of (i, j)
        The missing images' first-pass pairs that the coarse pass took as not overlapping
        (:func:`skipped_pairs_of`), to be matched whole: a left-out image may need exactly such
        a weak link.
    kept : list
        ``results`` without those pairs (their new results replace them).
    """
    new = second_pass_pairs(sel, missing, partners)
    retry = skipped_pairs_of(results, missing)
    whole = sorted({(int(results[k].i), int(results[k].j)) for k in retry})
    kept = [r for k, r in enumerate(results) if k not in retry]
    return new, whole, kept


def reconstruct_block(
    inputs: OrientInputs,
    matches: OrientMatches,
    cfg: OrientConfig,
    camera_file,
    warnings: list[str],
    steps,
    prog,
    times: dict,
) -> OrientReconstruction:
    """Tracks, incremental reconstruction and a second matching pass for left-out images (stages 4-5).

    ``steps`` are the tracks' and the reconstruction's progress steps. Sets the intrinsics that
    ``cfg.incremental`` refines (a given camera file is a calibration, kept fixed).

    Raises
    ------
    InputError
        Fewer than two images registered.
    """
    from .matching import MatchConfig, match_pairs
    from .tracks import tracks_from_pairs

    paths, names, image_camera, cams = inputs.paths, inputs.names, inputs.image_camera, inputs.cams
    features, results, n_verified = matches.features, matches.results, matches.n_verified
    t = time.perf_counter()
    cell = cfg.decimation_cell_px or decimation_cell(float(matches.sizes.max()), len(paths))
    tracks = tracks_from_pairs(features, results, cell, cfg.min_pair_tracks)
    steps[0].update(1.0, f"{tracks.n_tracks} tie points after decimation")
    times["tracks"] = time.perf_counter() - t

    t = time.perf_counter()
    inc = cfg.incremental
    refine = tuple(cfg.refine_intrinsics)
    if camera_file and refine == ALL_INTRINSICS:
        # a given interior orientation is a calibration: kept fixed unless a subset is asked for
        refine = ()
    inc.refine_intrinsics = refine
    if not cfg.self_calibration:
        inc.refine_intrinsics = ()
        inc.refine_focal_early = False
    elif camera_file:
        inc.refine_focal_early = False
    sel = matches.selection
    # a second matching pass may follow: the final adjustments wait for it (made once, at the end);
    # the reconstruction's progress is then split: registration, that matching, the rest
    may_retry = sel.strategy != "exhaustive"
    parts = Steps(steps[1], [7, 1, 2])
    rec = reconstruct(
        tracks.track,
        tracks.image,
        tracks.xy,
        image_camera,
        cams,
        inc,
        parts[0] if may_retry else steps[1],
        features,
        tracks.feature,
        finalize=not may_retry,
    )
    missing = np.flatnonzero(~rec.registered)
    extra: list[tuple[int, int]] = []
    whole: list[tuple[int, int]] = []
    if len(missing) and may_retry and rec.registered.sum() >= 2:
        # second chance for the images left out (second_pass_plan)
        extra, whole, results = second_pass_plan(sel, results, missing, cfg.second_pass_partners)
    if extra or whole:
        check(prog)
        n_more = len(extra) + len(whole)
        parts[1].update(0.0, f"matching {len(missing)} unregistered image(s) against others ({n_more} pairs)")
        sub = Steps(parts[1], [max(len(extra), 1), max(len(whole), 1)])
        cams_ = matches.per_image_cams
        more, _ = match_pairs(features, np.array(extra).reshape(-1, 2), cams_, progress=sub[0])
        again, _ = match_pairs(
            features,
            np.array(whole).reshape(-1, 2),
            matches.per_image_cams,
            MatchConfig(overlap_min_coarse=0),
            progress=sub[1],
        )
        results = results + more + again
        n_verified = sum(r.ok for r in results)
        tracks = tracks_from_pairs(features, results, cell, cfg.min_pair_tracks)
        # go on from the block registered so far (its poses; every track triangulated anew)
        rec = reconstruct(
            tracks.track, tracks.image, tracks.xy, image_camera, cams, inc, parts[2], features,
            tracks.feature, start=rec,
        )  # fmt: skip
        warnings.append(
            f"second matching pass for {len(missing)} image(s): {n_more} more pairs, "
            f"{int(rec.registered.sum())} images registered"
        )
    elif not rec.stats.get("finalized", True):
        # its own observations (with those guided registration added): points and inliers are kept
        rec = reconstruct(
            rec.obs_track, rec.obs_image, rec.obs_xy, image_camera, cams, inc, parts[2], features,
            rec.obs_feature, start=rec, register=False,
        )  # fmt: skip
    times["reconstruction"] = time.perf_counter() - t
    n_reg = int(rec.registered.sum())
    if n_reg < 2:
        raise InputError(f"orientation failed: {rec.stats.get('failure', 'no initial pair')}")
    for k in np.flatnonzero(~rec.registered):
        warnings.append(f"image {names[k]} could not be oriented (too few tie points with the block)")
    warnings += _guided_messages(rec.stats.get("guided", []), names)
    # the observations of the model: the tracks plus the matches added by guided registration
    tracks = _model_tracks(tracks, rec)
    return OrientReconstruction(rec, tracks, results, n_verified, refine)


def georeference_block(
    inputs: OrientInputs,
    r: OrientReconstruction,
    gcps: list[GCP],
    cfg: OrientConfig,
    warnings: list[str],
    step,
) -> OrientGeoref:
    """The block in its frame: GCPs, else EXIF GNSS, else free (stage 6 of :func:`orient_images`).

    The local offset is chosen from the GCPs or the GNSS positions; without usable control the
    block is adjusted free, in an arbitrary frame without CRS (and a warning).
    """
    rec, tracks = r.rec, r.tracks
    block, track_ids = block_from_reconstruction(
        rec, tracks.track, tracks.image, tracks.xy, inputs.names, inputs.cams, inputs.image_camera
    )
    gcfg = cfg.georef
    gcfg.refine_intrinsics = r.refine if cfg.self_calibration else ()
    crs = inputs.crs
    gps_world, crs = _gps_local(inputs.exifs, crs, warnings) if not gcps else (None, crs)
    offset = np.zeros(3)
    if gcps:
        offset = choose_offset(np.array([g.xyz for g in gcps]))
    elif gps_world is not None:
        offset = choose_offset(gps_world[np.all(np.isfinite(gps_world), axis=1)])
    gps_local = None if gps_world is None else (gps_world - offset)[rec.registered]
    geo = georeference(block, gcps, offset, gps_local, gcfg, step)
    if geo.method == "none":
        bundle = _adjust_free(block, gcfg)
        crs_out = None
        offset = np.zeros(3)
        if crs is not None:
            warnings.append(
                "no usable ground control or GNSS: the orientation is in an arbitrary frame, without CRS"
            )
    else:
        bundle = geo.bundle
        crs_out = crs
    return OrientGeoref(block, track_ids, gcfg, offset, gps_local, geo, bundle, crs_out)


def report_block(
    inputs: OrientInputs,
    m: OrientMatches,
    r: OrientReconstruction,
    g: OrientGeoref,
    orientation: Orientation,
    tie: dict,
    bundle,
    geo,
    times: dict,
    warnings: list[str],
    tie_refinement: dict | None,
) -> tuple[Report, list[dict]]:
    """The last stage: the run's statistics and report, and the GCP / check-point residual rows.

    ``bundle`` and ``geo`` are the final adjustment and datum (``g``'s, or those after the
    tie-point refinement).

    Returns
    -------
    (Report, list of dict)
        The orientation report (tables, figures, warnings, data) and one row per control or check
        point with its residuals and ``role``.
    """
    names = inputs.names
    sel, fstats, mstats = m.selection, m.feature_stats, m.match_stats
    rec, tracks, n_verified = r.rec, r.tracks, r.n_verified
    block = g.block
    stats = {
        "summary": {
            "pairs tried": f"{sel.n_pairs} of {sel.n_exhaustive} ({sel.strategy})",
            "verified pairs": n_verified,
            "tie points before decimation": tracks.stats.get("decimation", {}).get(
                "tracks_before", tracks.n_tracks
            ),
            "wall time [s]": round(times["total"], 1),
        },
        "timings": times,
        "features": {k: v for k, v in fstats.items() if k != "seconds_per_image"},
        "pairs": {
            "strategy": sel.strategy,
            "tried": sel.n_pairs,
            "exhaustive": sel.n_exhaustive,
            "verified": n_verified,
        },
        "matching": mstats,
        "tracks": tracks.stats,
        "reconstruction": rec.stats,
        "cameras": inputs.cam_info,
        "warnings": warnings,
    }
    if tie_refinement is not None:
        stats["tie_refinement"] = tie_refinement
    reg_idx = np.flatnonzero(rec.registered)
    rep = orientation_report(
        "TruOrtho orientation report",
        names,
        rec.registered,
        orientation.frame.to_world(np.array([im.C for im in orientation.images])),
        tie["xyz"],
        tie["multiplicity"],
        bundle,
        block.obs_image,
        block.obs_xy,
        geo if geo.method != "none" else GeorefResult("none", warnings=geo.warnings),
        stats,
        block.cameras,
    )
    rep.data["registered_images"] = [names[i] for i in reg_idx]
    residuals = [{**row, "role": "gcp"} for row in geo.gcp_table] + [
        {**row, "role": "check"} for row in geo.check_table
    ]
    return rep, residuals


def orient_images(
    paths,
    camera_file=None,
    gcps: list[GCP] | None = None,
    crs: str | None = None,
    config: OrientConfig | None = None,
    work_dir=None,
    progress: Progress | None = None,
) -> OrientationRun:
    """Orient a block of images (see the module docstring).

    The stages: :func:`read_inputs` -> :func:`choose_pairs` -> :func:`match_images` ->
    :func:`reconstruct_block` -> :func:`georeference_block`, then the orientation, the tie points
    and the report.

    Parameters
    ----------
    paths : list of path
        Image files (other files are skipped with a warning).
    camera_file : path, optional
        Orthority interior file (YAML/JSON) or a 3x3 K matrix text file.
    gcps : list of GCP, optional
        World coordinates in ``crs``, with image measurements by image file name.
    crs : str, optional
        CRS of the GCPs and the output (default: the UTM zone of EXIF GNSS, else none).
    work_dir : path, optional
        Feature cache.
    """
    cfg = config or OrientConfig()
    prog = as_progress(progress)
    # inventory and pair selection take the first 3 %; the pair count then splits the rest
    head = Steps(SubProgress(prog, 0.0, 0.03), [1, 1])
    t_start = time.perf_counter()
    times: dict[str, float] = {}
    warnings: list[str] = []
    gcps = list(gcps or [])
    t = time.perf_counter()
    inputs = read_inputs(paths, camera_file, gcps, crs, warnings, head[0], prog)
    times["inventory"] = time.perf_counter() - t
    paths = inputs.paths
    t = time.perf_counter()
    sel = choose_pairs(inputs, cfg, work_dir, head[1])
    times["pair selection"] = time.perf_counter() - t
    steps = Steps(SubProgress(prog, 0.03, 1.0), stage_weights(len(paths), sel.n_pairs))
    m = match_images(inputs, cfg, work_dir, sel, (steps[0], steps[1]), times)
    r = reconstruct_block(inputs, m, cfg, camera_file, warnings, (steps[2], steps[3]), prog, times)
    rec, tracks = r.rec, r.tracks
    n_reg = int(rec.registered.sum())

    t = time.perf_counter()
    g = georeference_block(inputs, r, gcps, cfg, warnings, steps[4])
    block, track_ids, offset, geo, bundle, crs_out = g.block, g.track_ids, g.offset, g.geo, g.bundle, g.crs
    gcfg, gps_local = g.georef_config, g.gps_local
    times["georeferencing"] = time.perf_counter() - t
    tie_refinement = None
    if cfg.refine_tie_points and len(block.obs_xy):
        t = time.perf_counter()
        tie_refinement, bundle, geo = _refine_and_readjust(
            block, paths, cfg, bundle, geo, gcps, offset, gps_local, gcfg, prog
        )
        times["tie refinement"] = time.perf_counter() - t

    orientation, tie = _build_orientation(
        block, track_ids, tracks, m.features, bundle, paths, rec, crs_out, offset, gcps
    )
    steps[5].update(1.0, "report")
    times["total"] = time.perf_counter() - t_start
    rep, residuals = report_block(
        inputs, m, r, g, orientation, tie, bundle, geo, times, warnings, tie_refinement
    )
    prog.update(1.0, f"oriented {n_reg} of {len(paths)} images")
    return OrientationRun(
        orientation, rep, tie["xyz"], tie["multiplicity"], tie["error"], tie["rgb"], residuals
    )


def _model_tracks(tracks, rec):
    """Tracks with the observations of the reconstruction (input ones first, then guided matches)."""
    from .tracks import Tracks

    if rec.obs_track is None or len(rec.obs_track) == len(tracks.track):
        return tracks
    return Tracks(
        rec.obs_track, rec.obs_image, rec.obs_feature, rec.obs_xy, tracks.n_tracks, dict(tracks.stats)
    )


def _guided_messages(entries: list[dict], names: list[str]) -> list[str]:
    """One report line per image registered by guided matching (its verification numbers)."""
    out = []
    for e in entries:
        if not e.get("registered"):
            continue
        sc = e.get("scale_search", {})
        out.append(
            f"image {names[e['image']]} registered by guided matching: relative orientation to "
            f"{names[e['partner']]} ({e['pair_points']} points, median intersection angle "
            f"{e['pair_median_angle_deg']:.1f} deg), baseline length from {e['guided_inliers']} guided "
            f"matches of block points ({sc.get('expected_chance_matches', float('nan')):.2f} expected by "
            f"chance, log10 NFA {sc.get('log10_nfa', float('nan')):.1f}), reprojection RMS "
            f"{e['rms_px']:.2f} px"
        )
    return out


def _refine_and_readjust(
    block: Block, paths, cfg: OrientConfig, bundle, geo, gcps, offset, gps_local, gcfg, prog
):
    """LSM refinement of the tie-point observations, then the same adjustment again.

    Returns (statistics with the figures before and after, bundle, georeferencing result).
    """
    from ..gcp.tiepoints import refine_tie_points
    from ..imagery import image_info, luminance, read_image, scaled_size

    by_name = {os.path.basename(p): p for p in paths}
    images, scales = [], []
    for k, name in enumerate(block.image_names):
        check(prog)
        prog.update(0.97, f"tie refinement: reading {name} ({k + 1} of {len(block.image_names)})")
        info = image_info(by_name[name])
        s = min(1.0, cfg.working_size / max(info.width, info.height))
        _, _, sx, sy = scaled_size(info.width, info.height, s)
        images.append(luminance(read_image(by_name[name], scale=s)))
        scales.append((sx, sy))
    before = {"sigma0": float(bundle.sigma0), "check_rmse": dict(geo.check_rmse)}
    ref = refine_tie_points(block, images, np.array(scales))
    del images
    block.obs_xy = ref.obs_xy
    if geo.method == "none":
        bundle = _adjust_free(block, gcfg)
    else:
        geo = georeference(block, gcps, offset, gps_local, gcfg)
        bundle = geo.bundle
    stats = {
        **ref.stats,
        "sigma0_before": before["sigma0"],
        "sigma0_after": float(bundle.sigma0),
        "check_rmse_before": before["check_rmse"],
        "check_rmse_after": dict(geo.check_rmse),
    }
    return stats, bundle, geo


def _adjust_free(block: Block, gcfg: GeorefConfig):
    pb = BundleProblem(
        intrinsics=block.intrinsics,
        image_camera=block.image_camera,
        rotations=block.rotations,
        centers=block.centers,
        points=block.points,
        obs_image=block.obs_image,
        obs_point=block.obs_point,
        obs_xy=block.obs_xy,
        refine_intrinsics=gcfg.refine_intrinsics,
    )
    res = bundle_adjust(
        pb,
        BundleConfig(
            max_iterations=gcfg.max_iterations,
            loss="huber",
            loss_scale=gcfg.loss_scale_px,
            function_tolerance=gcfg.function_tolerance,
        ),
    )
    block.rotations, block.centers, block.points = res.rotations, res.centers, res.points
    for c, cam in enumerate(block.cameras):
        block.cameras[c] = Camera.from_params(res.intrinsics[c], cam.width, cam.height, cam.id)
    return res


def _build_orientation(block, track_ids, tracks, features, bundle, paths, rec, crs, offset, gcps):
    names = block.image_names
    root = os.path.commonpath([os.path.dirname(os.path.abspath(p)) for p in paths])
    rel = {os.path.basename(p): os.path.relpath(os.path.abspath(p), root).replace(os.sep, "/") for p in paths}
    cameras = {c.id: c for c in block.cameras}
    images = [
        Image(n, block.cameras[block.image_camera[k]].id, block.rotations[k], block.centers[k], rel[n])
        for k, n in enumerate(names)
    ]
    # colours and errors per point
    n_pt = len(block.points)
    rgb_sum = np.zeros((n_pt, 3))
    n_obs = len(block.obs_image)
    err = np.linalg.norm(bundle.residuals[:n_obs], axis=1)
    err_sum = np.bincount(block.obs_point, weights=np.nan_to_num(err), minlength=n_pt)
    # block observations are the reconstruction's valid track observations, in order
    obs_sel = np.flatnonzero(rec.obs_valid)
    feat = tracks.feature[obs_sel]
    img_full = tracks.image[obs_sel]
    colours = np.zeros((n_obs, 3))
    for k in np.unique(img_full):
        sel = img_full == k
        colours[sel] = features[k].colors[feat[sel]]
    np.add.at(rgb_sum, block.obs_point, colours)
    cnt = np.bincount(block.obs_point, minlength=n_pt).astype(np.float64)
    cnt1 = np.maximum(cnt, 1)
    rgb = rgb_sum / cnt1[:, None]
    mean_err = err_sum / cnt1
    pts = SparsePoints(block.points, rgb, mean_err, block.obs_point, block.obs_image, block.obs_xy)
    frame = LocalFrame(crs, offset)
    o = Orientation(
        frame,
        cameras,
        images,
        pts,
        list(gcps),
        root,
        {
            "generator": "truortho:orientimages",
            "unregistered": [os.path.basename(paths[i]) for i in np.flatnonzero(~rec.registered)],
        },
    )
    tie = {
        "xyz": frame.to_world(block.points),
        "multiplicity": cnt.astype(np.int64),
        "error": mean_err,
        "rgb": np.clip(np.round(rgb), 0, 255).astype(np.uint8),
    }
    return o, tie
