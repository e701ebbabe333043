"""Normal equations with the points eliminated (Schur complement), numba kernels.

With ``A = J^T W J`` split into the camera block ``U``, the point blocks
``V_j`` (3x3) and the coupling ``W``, and ``g = -J^T W r`` into ``(g_c,
g_p)``, the damped step ``(A + lambda D) h = g`` is solved as

    S h_c = g_c - sum_j W_j V_j*^-1 g_pj,   S = U* - sum_j W_j V_j*^-1 W_j^T
    h_pj  = V_j*^-1 (g_pj - W_j^T h_c)

(``*`` = damped). ``S`` is accumulated per pair of images that see a common
point ("slots"; 14x14 blocks in the per-image column order of
:class:`~.problem.Layout` ``image_cols``) and scattered into a dense matrix or
a scipy.sparse CSR matrix. The accumulation is one serial kernel looping over
points (no Python loop over observations); the back-substitution is parallel
over points.
"""

from __future__ import annotations

import numba
import numpy as np
import scipy.sparse as sp

from ...jit import njit, pjit, prange
from .problem import N_CAMCOLS

#: Bounds of the Marquardt scaling diagonal (as Ceres).
D_MIN, D_MAX = 1e-6, 1e32


@njit
def _pair_keys(obs_img, pt_ptr, pt_obs, n_img):
    """All keys ``i * n_img + k`` (i <= k) of images sharing a point, with repeats."""
    n = 0
    for j in range(pt_ptr.shape[0] - 1):
        L = pt_ptr[j + 1] - pt_ptr[j]
        n += L * (L + 1) // 2
    keys = np.empty(n, dtype=np.int64)
    m = 0
    for j in range(pt_ptr.shape[0] - 1):
        for t in range(pt_ptr[j], pt_ptr[j + 1]):
            it = obs_img[pt_obs[t]]
            for u in range(t, pt_ptr[j + 1]):
                iu = obs_img[pt_obs[u]]
                keys[m] = min(it, iu) * n_img + max(it, iu)
                m += 1
    return keys


@njit
def _inv3(A, out):
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    scale = abs(A[0, 0]) + abs(A[1, 1]) + abs(A[2, 2])
    if not (det > 1e-14 * scale * scale * scale) or scale == 0.0:
        out[:, :] = 0.0
        return False
    inv = 1.0 / det
    out[0, 0] = c00 * inv
    out[1, 0] = c01 * inv
    out[2, 0] = c02 * inv
    out[0, 1] = (A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]) * inv
    out[1, 1] = (A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]) * inv
    out[2, 1] = (A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]) * inv
    out[0, 2] = (A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]) * inv
    out[1, 2] = (A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]) * inv
    out[2, 2] = (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]) * inv
    return True


@njit
def _schur_range(
    j0,
    j1,
    Jc,
    Jp,
    r,
    w,
    image_cols,
    act,
    n_act,
    obs_img,
    pt_ptr,
    pt_obs,
    prior_w,
    prior_res,
    lam,
    keys,
    n_img,
    W,
    T,
    B,
    gc,
    sg,
    dU,
    Vinv,
    gp,
    Dp,
):
    """Accumulate points ``j0 <= j < j1`` into ``B``, ``gc``, ``sg``, ``dU`` (not zeroed here)."""
    V = np.zeros((3, 3))
    g = np.zeros(3)
    n_sing = 0
    for j in range(j0, j1):
        s0 = pt_ptr[j]
        L = pt_ptr[j + 1] - s0
        V[:, :] = 0.0
        for a in range(3):
            V[a, a] = prior_w[j, a]
            g[a] = -prior_w[j, a] * prior_res[j, a]
        for t in range(L):
            o = pt_obs[s0 + t]
            wo = w[o]
            for b in range(3):
                for a in range(N_CAMCOLS):
                    W[t, b, a] = wo * (Jc[o, 0, a] * Jp[o, 0, b] + Jc[o, 1, a] * Jp[o, 1, b])
            if wo == 0.0:
                continue
            for a in range(3):
                g[a] -= wo * (Jp[o, 0, a] * r[o, 0] + Jp[o, 1, a] * r[o, 1])
                for b in range(3):
                    V[a, b] += wo * (Jp[o, 0, a] * Jp[o, 0, b] + Jp[o, 1, a] * Jp[o, 1, b])
            i = obs_img[o]
            cols = image_cols[i]
            Bs = B[np.searchsorted(keys, i * n_img + i)]
            for aa in range(n_act[i]):
                a = act[i, aa]
                ja0 = wo * Jc[o, 0, a]
                ja1 = wo * Jc[o, 1, a]
                gc[cols[a]] -= ja0 * r[o, 0] + ja1 * r[o, 1]
                dU[cols[a]] += ja0 * Jc[o, 0, a] + ja1 * Jc[o, 1, a]
                for bb in range(n_act[i]):
                    b = act[i, bb]
                    Bs[a, b] += ja0 * Jc[o, 0, b] + ja1 * Jc[o, 1, b]
        for a in range(3):
            Dp[j, a] = min(max(V[a, a], D_MIN), D_MAX)
            V[a, a] += lam * Dp[j, a]
            gp[j, a] = g[a]
        if not _inv3(V, Vinv[j]):
            n_sing += 1
            continue
        for t in range(L):
            for a in range(N_CAMCOLS):
                for b in range(3):
                    T[t, a, b] = (
                        W[t, 0, a] * Vinv[j, 0, b] + W[t, 1, a] * Vinv[j, 1, b] + W[t, 2, a] * Vinv[j, 2, b]
                    )
        for t in range(L):
            it = obs_img[pt_obs[s0 + t]]
            cols_t = image_cols[it]
            for aa in range(n_act[it]):
                a = act[it, aa]
                sg[cols_t[a]] += T[t, a, 0] * g[0] + T[t, a, 1] * g[1] + T[t, a, 2] * g[2]
            for u in range(L):
                iu = obs_img[pt_obs[s0 + u]]
                if iu < it:
                    continue
                Bs = B[np.searchsorted(keys, it * n_img + iu)]
                Wu = W[u]
                for aa in range(n_act[it]):
                    a = act[it, aa]
                    t0 = T[t, a, 0]
                    t1 = T[t, a, 1]
                    t2 = T[t, a, 2]
                    for b in range(
                        N_CAMCOLS
                    ):  # all 14 (contiguous, vectorised); held columns are dropped later
                        Bs[a, b] -= t0 * Wu[0, b] + t1 * Wu[1, b] + t2 * Wu[2, b]
    return n_sing


@pjit
def _schur(
    Jc,
    Jp,
    r,
    w,
    image_cols,
    act,
    n_act,
    obs_img,
    pt_ptr,
    pt_obs,
    prior_w,
    prior_res,
    lam,
    keys,
    n_img,
    max_track,
    Bt,
    gct,
    sgt,
    dUt,
    Vinv,
    gp,
    Dp,
):
    """Parallel accumulation over chunks of points (one private ``Bt[c]``, ``gct[c]``... each),
    summed into chunk 0 at the end; returns the number of points with a singular damped block."""
    n_chunks = Bt.shape[0]
    n_pt = pt_ptr.shape[0] - 1
    sing = np.zeros(n_chunks, dtype=np.int64)
    for c in prange(n_chunks):
        Bt[c] = 0.0
        gct[c] = 0.0
        sgt[c] = 0.0
        dUt[c] = 0.0
        W = np.zeros((max_track, 3, N_CAMCOLS))
        T = np.zeros((max_track, N_CAMCOLS, 3))
        sing[c] = _schur_range(
            c * n_pt // n_chunks,
            (c + 1) * n_pt // n_chunks,
            Jc,
            Jp,
            r,
            w,
            image_cols,
            act,
            n_act,
            obs_img,
            pt_ptr,
            pt_obs,
            prior_w,
            prior_res,
            lam,
            keys,
            n_img,
            W,
            T,
            Bt[c],
            gct[c],
            sgt[c],
            dUt[c],
            Vinv,
            gp,
            Dp,
        )
    for c in range(1, n_chunks):
        Bt[0] += Bt[c]
        gct[0] += gct[c]
        sgt[0] += sgt[c]
        dUt[0] += dUt[c]
    return sing.sum()


class SchurWorkspace:
    """Buffers and static structure of the reduced system for one problem.

    After :meth:`reduce`, ``B`` (n_slots, 14, 14) holds the blocks of ``S``
    (undamped camera part, damped point part), ``gc`` the camera gradient,
    ``sg`` the Schur correction (rhs = gc - sg), ``dU`` diag(U), and
    ``Vinv`` / ``gp`` / ``Dp`` the damped point inverses, point gradients and
    point scaling diagonals.
    """

    def __init__(self, obs_image, obs_point, image_cols, n_img, n_pt, n_cols, n_chunks=None):
        self.pt_ptr, self.pt_obs, self.max_track = point_order(obs_point, n_pt)
        self.keys = slot_keys(obs_image, self.pt_ptr, self.pt_obs, n_img)
        self.obs_image, self.image_cols, self.n_img = obs_image, image_cols, n_img
        self.n_act = (image_cols >= 0).sum(1).astype(np.int64)
        order = np.argsort(image_cols < 0, axis=1, kind="stable")
        self.act = np.ascontiguousarray(order.astype(np.int64))
        nck = n_chunks or max(1, min(numba.get_num_threads(), n_pt // 2000 or 1))
        self.Bt = np.zeros((nck, len(self.keys), N_CAMCOLS, N_CAMCOLS))
        self.gct, self.sgt, self.dUt = (np.zeros((nck, n_cols)) for _ in range(3))
        self.Vinv, self.gp, self.Dp = np.zeros((n_pt, 3, 3)), np.zeros((n_pt, 3)), np.zeros((n_pt, 3))

    def reduce(self, Jc, Jp, r, w, prior_w, prior_res, lam) -> int:
        """Accumulate at the given linearisation and damping; returns the number of singular points."""
        return int(
            _schur(
                Jc,
                Jp,
                r,
                w,
                self.image_cols,
                self.act,
                self.n_act,
                self.obs_image,
                self.pt_ptr,
                self.pt_obs,
                prior_w,
                prior_res,
                float(lam),
                self.keys,
                self.n_img,
                self.max_track,
                self.Bt,
                self.gct,
                self.sgt,
                self.dUt,
                self.Vinv,
                self.gp,
                self.Dp,
            )
        )

    @property
    def B(self):
        return self.Bt[0]

    @property
    def gc(self):
        return self.gct[0]

    @property
    def sg(self):
        return self.sgt[0]

    @property
    def dU(self):
        return self.dUt[0]


@njit
def _scatter_dense(B, keys, n_img, image_cols, S):
    S[:, :] = 0.0
    for s in range(keys.shape[0]):
        i = keys[s] // n_img
        k = keys[s] % n_img
        ci = image_cols[i]
        ck = image_cols[k]
        for a in range(N_CAMCOLS):
            if ci[a] < 0:
                continue
            for b in range(N_CAMCOLS):
                if ck[b] < 0:
                    continue
                S[ci[a], ck[b]] += B[s, a, b]
                if i != k:
                    S[ck[b], ci[a]] += B[s, a, b]


def scatter_sparse(B, keys, n_img, image_cols, n_cols) -> sp.csr_matrix:
    """CSR matrix of the reduced system from the slot blocks (duplicates summed)."""
    i = keys // n_img
    k = keys % n_img
    rows = np.broadcast_to(image_cols[i][:, :, None], B.shape)
    cols = np.broadcast_to(image_cols[k][:, None, :], B.shape)
    m = (rows >= 0) & (cols >= 0) & (B != 0)
    off = m & (i != k)[:, None, None]
    rr = np.concatenate([rows[m], cols[off]])
    cc = np.concatenate([cols[m], rows[off]])
    vv = np.concatenate([B[m], B[off]])
    return sp.coo_matrix((vv, (rr, cc)), shape=(n_cols, n_cols)).tocsr()


@pjit
def _back_substitute(Jc, Jp, w, image_cols, obs_img, pt_ptr, pt_obs, Vinv, gp, hc, hp):
    """Point steps ``h_pj = V_j*^-1 (g_pj - W_j^T h_c)``, parallel over points."""
    for j in prange(pt_ptr.shape[0] - 1):
        q0 = gp[j, 0]
        q1 = gp[j, 1]
        q2 = gp[j, 2]
        for t in range(pt_ptr[j], pt_ptr[j + 1]):
            o = pt_obs[t]
            wo = w[o]
            if wo == 0.0:
                continue
            cols = image_cols[obs_img[o]]
            e0 = 0.0
            e1 = 0.0
            for a in range(N_CAMCOLS):
                if cols[a] >= 0:
                    e0 += Jc[o, 0, a] * hc[cols[a]]
                    e1 += Jc[o, 1, a] * hc[cols[a]]
            q0 -= wo * (Jp[o, 0, 0] * e0 + Jp[o, 1, 0] * e1)
            q1 -= wo * (Jp[o, 0, 1] * e0 + Jp[o, 1, 1] * e1)
            q2 -= wo * (Jp[o, 0, 2] * e0 + Jp[o, 1, 2] * e1)
        for a in range(3):
            hp[j, a] = Vinv[j, a, 0] * q0 + Vinv[j, a, 1] * q1 + Vinv[j, a, 2] * q2


def point_order(obs_point: np.ndarray, n_pt: int) -> tuple[np.ndarray, np.ndarray, int]:
    """CSR of observations by point: ``pt_ptr`` (n_pt + 1,), ``pt_obs`` (n_obs,), max track length."""
    pt_obs = np.argsort(obs_point, kind="stable").astype(np.int64)
    counts = np.bincount(obs_point, minlength=n_pt)
    pt_ptr = np.zeros(n_pt + 1, dtype=np.int64)
    np.cumsum(counts, out=pt_ptr[1:])
    return pt_ptr, pt_obs, int(counts.max(initial=1))


def slot_keys(obs_img, pt_ptr, pt_obs, n_img) -> np.ndarray:
    """Sorted unique image-pair keys of the reduced system's blocks."""
    keys = np.unique(_pair_keys(obs_img, pt_ptr, pt_obs, n_img))
    return np.ascontiguousarray(keys, dtype=np.int64)
