"""Feature tracks from pairwise matches, and tie-point decimation.

Tracks
------
Every feature ``(image, feature)`` is a node, every verified match an edge;
a track is a connected component with at least two nodes (union-find via
``scipy.sparse.csgraph.connected_components``). A component holding two
*different* features of one image is **inconsistent** (a mismatch chained
through other images) and dropped whole, as OpenSfM and COLMAP do by default.

Decimation
----------
:func:`decimate_tracks` thins the tie points to at most one winner per cell
of a regular grid (``cell_px`` full-resolution pixels) of every image. In
each cell the observation whose track has the **highest multiplicity** wins;
ties go to the smaller feature scale (finer localisation; feature index when
no scales are given). The kept set is a set of *tracks*: a track is kept
when it wins at least one cell of at least one image, and is then kept with
**all** its observations, so a tie point never disappears from some of the
images it was measured in (a cell can thus hold several kept observations).

Cell winners favour long tracks, so a pair of images whose only common
points are two-view tracks (a weakly connected image at the edge of a block,
a small overlap between strips) can lose most of its links although they are
the only thing that ties it to the block. With ``min_pair_tracks`` every
image pair keeps at least ``min(n, min_pair_tracks)`` of the ``n`` tracks it
shared before the decimation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass
class Tracks:
    """Observations of tie points, sorted by track then image.

    Attributes
    ----------
    track, image, feature : (M,) int64
        Track id (0..n_tracks-1), image index and feature index of every observation.
    xy : (M, 2) float64
        Pixel coordinates (our convention), full resolution.
    n_tracks : int
    stats : dict
        ``components``, ``inconsistent`` (dropped tracks), ``n_tracks``,
        ``n_observations``, ``histogram`` (``hist[k]`` = tracks of
        multiplicity k).
    """

    track: np.ndarray
    image: np.ndarray
    feature: np.ndarray
    xy: np.ndarray
    n_tracks: int
    stats: dict

    @property
    def multiplicity(self) -> np.ndarray:
        """(n_tracks,) number of images of every track."""
        return np.bincount(self.track, minlength=self.n_tracks)

    def histogram(self) -> np.ndarray:
        """``hist[k]`` = number of tracks seen in k images."""
        return np.bincount(self.multiplicity) if self.n_tracks else np.zeros(1, np.int64)

    def subset(self, keep_tracks) -> Tracks:
        """The tracks flagged in ``keep_tracks`` ((n_tracks,) bool), renumbered in order."""
        keep = np.asarray(keep_tracks, bool)
        new_id = np.cumsum(keep) - 1
        sel = keep[self.track]
        t = Tracks(
            new_id[self.track[sel]], self.image[sel], self.feature[sel], self.xy[sel], int(keep.sum()), {}
        )
        t.stats = {**self.stats, **_counts(t)}
        return t


def _counts(t: Tracks) -> dict:
    return {"n_tracks": t.n_tracks, "n_observations": len(t.track), "histogram": t.histogram().tolist()}


def build_tracks(n_features, pair_matches, keypoints=None) -> Tracks:
    """Tracks from pairwise (verified) matches.

    Parameters
    ----------
    n_features : sequence of int
        Number of features of every image.
    pair_matches : iterable of (i, j, matches)
        ``matches`` (K, 2) int: feature indices in images i and j.
    keypoints : list of (N_i, 2) arrays, optional
        Feature positions per image; fills ``Tracks.xy`` (NaN when None).

    Returns
    -------
    Tracks
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nf = np.asarray(n_features, dtype=np.int64).reshape(-1)
    if np.any(nf < 0):
        raise InputError("build_tracks: n_features must be non-negative")
    n_img = len(nf)
    offset = np.concatenate([[0], np.cumsum(nf)])
    a_list, b_list = [], []
    for i, j, m in pair_matches:
        i, j = int(i), int(j)
        m = np.asarray(m, dtype=np.int64).reshape(-1, 2)
        if not (0 <= i < n_img and 0 <= j < n_img) or i == j:
            raise InputError(f"build_tracks: invalid image pair ({i}, {j}) for {n_img} images")
        if len(m) and (m.min() < 0 or m[:, 0].max() >= nf[i] or m[:, 1].max() >= nf[j]):
            raise InputError(f"build_tracks: match of pair ({i}, {j}) refers to a missing feature")
        a_list.append(offset[i] + m[:, 0])
        b_list.append(offset[j] + m[:, 1])
    a = np.concatenate(a_list) if a_list else np.zeros(0, np.int64)
    b = np.concatenate(b_list) if b_list else np.zeros(0, np.int64)
    empty = Tracks(
        np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 2)), 0, {}
    )
    if len(a) == 0:
        empty.stats = {"components": 0, "inconsistent": 0, **_counts(empty)}
        return empty
    # only nodes touched by a match take part: compress them
    nodes, inv = np.unique(np.concatenate([a, b]), return_inverse=True)
    g = coo_matrix((np.ones(len(a), np.int8), (inv[: len(a)], inv[len(a) :])), shape=(len(nodes), len(nodes)))
    n_comp, label = connected_components(g, directed=False)
    image = np.asarray(np.searchsorted(offset, nodes, side="right"), np.int64) - 1
    feature = nodes - offset[image]
    # inconsistent components: one image twice
    order = np.lexsort((image, label))
    lab_s, img_s = label[order], image[order]
    dup = (lab_s[1:] == lab_s[:-1]) & (img_s[1:] == img_s[:-1])
    bad = np.zeros(n_comp, bool)
    bad[lab_s[1:][dup]] = True
    size = np.bincount(label, minlength=n_comp)
    good = ~bad & (size >= 2)
    keep = good[lab_s]
    order = order[keep]
    new_id = np.cumsum(good) - 1
    track = new_id[label[order]]
    img, feat = image[order], feature[order]
    xy = np.full((len(order), 2), np.nan)
    if keypoints is not None:
        if len(keypoints) != n_img:
            raise InputError(f"build_tracks: {len(keypoints)} keypoint arrays for {n_img} images")
        for k in np.unique(img):
            s = img == k
            xy[s] = np.asarray(keypoints[k], np.float64)[feat[s]]
    t = Tracks(track, img, feat, xy, int(good.sum()), {})
    t.stats = {"components": int(n_comp), "inconsistent": int(bad.sum()), **_counts(t)}
    return t


def decimate_tracks(
    tracks: Tracks, image_sizes, cell_px: float, feature_scale=None, min_pair_tracks: int = 0
) -> Tracks:
    """Keep the best track per grid cell of every image (see the module docstring).

    Parameters
    ----------
    tracks : Tracks
        With finite ``xy``.
    image_sizes : (n_img, 2) int
        ``(width, height)`` of every image, pixels.
    cell_px : float
        Grid cell size, pixels (full resolution).
    feature_scale : list of (N_i,) arrays, optional
        Feature scale (e.g. :attr:`Features.size`) per image, for tie-breaking.
    min_pair_tracks : int
        Links of weakly connected images are protected: an image pair that shared ``n`` tracks
        and keeps fewer than ``min(n, min_pair_tracks)`` gets its best shared tracks back
        (highest multiplicity, then finest scale) up to that number (0: no protection).

    Returns
    -------
    Tracks
        The kept tracks with all their observations; ``stats`` gains
        ``decimation`` = {cell_px, tracks_before, tracks_after, min_pair_tracks,
        tracks_restored, pairs_restored}.
    """
    if not (isinstance(cell_px, int | float) and np.isfinite(cell_px) and cell_px > 0):
        raise InputError(f"cell_px must be a positive number, got {cell_px!r}")
    if not (isinstance(min_pair_tracks, int | np.integer) and min_pair_tracks >= 0):
        raise InputError(f"min_pair_tracks must be a non-negative integer, got {min_pair_tracks!r}")
    sizes = np.asarray(image_sizes, dtype=np.float64).reshape(-1, 2)
    if tracks.n_tracks == 0:
        return tracks.subset(np.zeros(0, bool))
    if tracks.image.max() >= len(sizes):
        raise InputError(f"decimate_tracks: {len(sizes)} image sizes for image index {tracks.image.max()}")
    if not np.all(np.isfinite(tracks.xy)):
        raise InputError(
            "decimate_tracks: tracks need finite pixel coordinates (build_tracks(keypoints=...))"
        )
    ncx = np.ceil(sizes[:, 0] / cell_px).astype(np.int64)
    ncy = np.ceil(sizes[:, 1] / cell_px).astype(np.int64)
    cell_off = np.concatenate([[0], np.cumsum(ncx * ncy)])
    cx = np.clip(np.floor((tracks.xy[:, 0] + 0.5) / cell_px).astype(np.int64), 0, ncx[tracks.image] - 1)
    cy = np.clip(np.floor((tracks.xy[:, 1] + 0.5) / cell_px).astype(np.int64), 0, ncy[tracks.image] - 1)
    cell = cell_off[tracks.image] + cy * ncx[tracks.image] + cx
    mult = tracks.multiplicity[tracks.track]
    if feature_scale is not None:
        tie = np.empty(len(cell))
        for k in np.unique(tracks.image):
            s = tracks.image == k
            tie[s] = np.asarray(feature_scale[k], np.float64)[tracks.feature[s]]
    else:
        tie = tracks.feature.astype(np.float64)
    order = np.lexsort((tracks.track, tie, -mult, cell))
    first = np.ones(len(order), bool)
    first[1:] = cell[order][1:] != cell[order][:-1]
    keep = np.zeros(tracks.n_tracks, bool)
    keep[tracks.track[order[first]]] = True
    n_winners = int(keep.sum())
    n_pairs_restored = 0
    if min_pair_tracks > 0:
        # per track: smallest tie-break value over its observations (finer features first)
        track_tie = np.full(tracks.n_tracks, np.inf)
        np.minimum.at(track_tie, tracks.track, tie)
        n_pairs_restored = _restore_pair_links(tracks, keep, int(min_pair_tracks), track_tie)
    out = tracks.subset(keep)
    out.stats["decimation"] = {
        "cell_px": float(cell_px),
        "tracks_before": tracks.n_tracks,
        "tracks_after": out.n_tracks,
        "min_pair_tracks": int(min_pair_tracks),
        "tracks_restored": out.n_tracks - n_winners,
        "pairs_restored": n_pairs_restored,
    }
    return out


def _pair_track_counts(image: np.ndarray, track: np.ndarray, n_img: int, n_tracks: int, keep=None):
    """Shared tracks per image pair ``(i < j)``: sparse COO upper triangle of ``A A^T``."""
    from scipy import sparse

    sel = np.ones(len(track), bool) if keep is None else keep[track]
    A = sparse.csr_matrix(
        (np.ones(int(sel.sum()), np.int32), (image[sel], track[sel])), shape=(n_img, n_tracks)
    )
    S = sparse.triu(A @ A.T, k=1).tocsr()
    return S


def _restore_pair_links(tracks: Tracks, keep: np.ndarray, min_pair: int, track_tie: np.ndarray) -> int:
    """Give back decimated tracks of image pairs left with fewer than ``min_pair`` shared tracks.

    For every pair that shared ``n`` tracks before the decimation and keeps fewer than
    ``min(n, min_pair)``, its shared tracks of highest multiplicity (then finest scale) are
    restored until it has ``min(n, min_pair)``. Updates ``keep`` in place; returns the number of
    pairs that got tracks back.
    """
    n_img = int(tracks.image.max()) + 1
    before = _pair_track_counts(tracks.image, tracks.track, n_img, tracks.n_tracks).tocoo()
    after = _pair_track_counts(tracks.image, tracks.track, n_img, tracks.n_tracks, keep).tocsr()
    kept_n = np.asarray(after[before.row, before.col]).ravel()
    need = np.minimum(before.data, min_pair)
    deficit = np.flatnonzero(kept_n < need)
    if len(deficit) == 0:
        return 0
    # observations per image, sorted by track, for the intersections
    mult = tracks.multiplicity
    per_image = {}
    for i in np.unique(np.concatenate([before.row[deficit], before.col[deficit]])):
        per_image[int(i)] = np.unique(tracks.track[tracks.image == i])
    for k in deficit:
        i, j = int(before.row[k]), int(before.col[k])
        shared = np.intersect1d(per_image[i], per_image[j], assume_unique=True)
        missing = int(need[k]) - int(keep[shared].sum())
        if missing <= 0:  # an earlier restoration already covered this pair
            continue
        cand = shared[~keep[shared]]
        cand = cand[np.lexsort((cand, track_tie[cand], -mult[cand]))]
        keep[cand[:missing]] = True
    return len(deficit)


def tracks_from_pairs(
    features, pair_results, decimate_cell_px: float | None = None, min_pair_tracks: int = 0
) -> Tracks:
    """Tracks from :func:`~.matching.match_pairs` results (verified pairs only).

    Parameters
    ----------
    features : list of Features
    pair_results : list of PairMatches
    decimate_cell_px : float, optional
        Apply :func:`decimate_tracks` with this cell size.
    min_pair_tracks : int
        Protection of weak pair links in the decimation (see :func:`decimate_tracks`).
    """
    pm = [(r.i, r.j, r.inliers) for r in pair_results if r.ok]
    t = build_tracks([len(f) for f in features], pm, [f.xy for f in features])
    if decimate_cell_px:
        sizes = [(f.width, f.height) for f in features]
        t = decimate_tracks(t, sizes, decimate_cell_px, [f.size for f in features], min_pair_tracks)
    return t
