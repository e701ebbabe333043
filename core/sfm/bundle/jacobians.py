"""Residuals and analytic Jacobians of the collinearity equations with distortion.

For one observation of point ``X`` in an image with pose ``(R, C)`` and
intrinsics ``p = [fx, fy, cx, cy, k1, k2, k3, p1, p2]``::

    Xc = R (X - C),  x = Xc0 / Xc2,  y = Xc1 / Xc2
    r  = distort(p, x, y) - x_obs                      (pixels, 2-vector)

Derivatives (chain rule, all analytic):

* rotation, left increment ``R <- exp([d]x) R``: ``dXc/dd = -[Xc]x``;
* centre: ``dXc/dC = -R``; point: ``dXc/dX = R``;
* ``d(x, y)/dXc = [[1/z, 0, -x/z], [0, 1/z, -y/z]]``;
* ``d(u, v)/d(x, y)`` = focal lengths times the distortion Jacobian;
* intrinsics, columns in :data:`~.problem.INTRINSIC_NAMES` order: ``f``
  (``fx`` with ``fy = fx * (fy/fx)``: ``du/df = x''``, ``dv/df = y'' fy/fx``),
  ``cx``, ``cy``, ``k1..k3`` (``f r^2k x``), ``p1``, ``p2``.

The camera Jacobian of one observation has 14 columns
``[d_rot(3), C(3), f, cx, cy, k1, k2, k3, p1, p2]``; the point Jacobian 3.
An observation whose point is not in front of the camera (``z <= 0``) is
*invalid*: zero residual and Jacobian, flag False.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...jit import njit, pjit, prange
from .problem import N_CAMCOLS


@njit
def _observe(X, R, C, p, obs, r, Jc, Jp, with_jac):
    """Residual (and Jacobians when ``with_jac``) of one observation; returns validity."""
    d0 = X[0] - C[0]
    d1 = X[1] - C[1]
    d2 = X[2] - C[2]
    xc = R[0, 0] * d0 + R[0, 1] * d1 + R[0, 2] * d2
    yc = R[1, 0] * d0 + R[1, 1] * d1 + R[1, 2] * d2
    zc = R[2, 0] * d0 + R[2, 1] * d1 + R[2, 2] * d2
    if not zc > 0.0:
        r[0] = 0.0
        r[1] = 0.0
        if with_jac:
            Jc[:, :] = 0.0
            Jp[:, :] = 0.0
        return False
    iz = 1.0 / zc
    x = xc * iz
    y = yc * iz
    fx, fy = p[0], p[1]
    k1, k2, k3, p1, p2 = p[4], p[5], p[6], p[7], p[8]
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    r[0] = fx * xd + p[2] - obs[0]
    r[1] = fy * yd + p[3] - obs[1]
    if not with_jac:
        return True
    drad = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
    # d(u, v)/d(x, y)
    a00 = fx * (radial + 2.0 * x * x * drad + 2.0 * p1 * y + 6.0 * p2 * x)
    a01 = fx * (2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y)
    a10 = fy * (2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y)
    a11 = fy * (radial + 2.0 * y * y * drad + 6.0 * p1 * y + 2.0 * p2 * x)
    # d(u, v)/dXc = A @ [[1/z, 0, -x/z], [0, 1/z, -y/z]]
    b00 = a00 * iz
    b01 = a01 * iz
    b02 = -(a00 * x + a01 * y) * iz
    b10 = a10 * iz
    b11 = a11 * iz
    b12 = -(a10 * x + a11 * y) * iz
    # point: B @ R ; centre: -B @ R
    for k in range(3):
        jp0 = b00 * R[0, k] + b01 * R[1, k] + b02 * R[2, k]
        jp1 = b10 * R[0, k] + b11 * R[1, k] + b12 * R[2, k]
        Jp[0, k] = jp0
        Jp[1, k] = jp1
        Jc[0, 3 + k] = -jp0
        Jc[1, 3 + k] = -jp1
    # rotation: B @ (-[Xc]x), -[Xc]x = [[0, z, -y], [-z, 0, x], [y, -x, 0]] (camera coords)
    Jc[0, 0] = -b01 * zc + b02 * yc
    Jc[0, 1] = b00 * zc - b02 * xc
    Jc[0, 2] = -b00 * yc + b01 * xc
    Jc[1, 0] = -b11 * zc + b12 * yc
    Jc[1, 1] = b10 * zc - b12 * xc
    Jc[1, 2] = -b10 * yc + b11 * xc
    # intrinsics
    r4 = r2 * r2
    Jc[0, 6] = xd
    Jc[1, 6] = yd * fy / fx
    Jc[0, 7] = 1.0
    Jc[1, 7] = 0.0
    Jc[0, 8] = 0.0
    Jc[1, 8] = 1.0
    Jc[0, 9] = fx * x * r2
    Jc[1, 9] = fy * y * r2
    Jc[0, 10] = fx * x * r4
    Jc[1, 10] = fy * y * r4
    Jc[0, 11] = fx * x * r4 * r2
    Jc[1, 11] = fy * y * r4 * r2
    Jc[0, 12] = fx * 2.0 * x * y
    Jc[1, 12] = fy * (r2 + 2.0 * y * y)
    Jc[0, 13] = fx * (r2 + 2.0 * x * x)
    Jc[1, 13] = fy * 2.0 * x * y
    return True


@pjit
def _linearize(points, rots, cents, intr, img_cam, obs_img, obs_pt, obs_xy, r, Jc, Jp, valid):
    """Residuals ``r`` (n_obs, 2), ``Jc`` (n_obs, 2, 14), ``Jp`` (n_obs, 2, 3), ``valid``."""
    for o in prange(obs_img.shape[0]):
        i = obs_img[o]
        valid[o] = _observe(
            points[obs_pt[o]], rots[i], cents[i], intr[img_cam[i]], obs_xy[o], r[o], Jc[o], Jp[o], True
        )


@pjit
def _residuals(points, rots, cents, intr, img_cam, obs_img, obs_pt, obs_xy, r, valid):
    """Residuals only (no Jacobians), same layout as :func:`_linearize`."""
    dummy_c = np.empty((2, N_CAMCOLS))
    dummy_p = np.empty((2, 3))
    for o in prange(obs_img.shape[0]):
        i = obs_img[o]
        valid[o] = _observe(
            points[obs_pt[o]], rots[i], cents[i], intr[img_cam[i]], obs_xy[o], r[o], dummy_c, dummy_p, False
        )


def observation_jacobians(points, rotations, centers, intrinsics, image_camera, obs_image, obs_point, obs_xy):
    """Residuals and Jacobians of observations (public wrapper of the kernel).

    Parameters
    ----------
    points : (n_pt, 3); rotations : (n_img, 3, 3); centers : (n_img, 3)
        Local frame, world-to-camera rotations.
    intrinsics : (n_cam, 9); image_camera : (n_img,) int
    obs_image, obs_point : (n_obs,) int; obs_xy : (n_obs, 2) pixels

    Returns
    -------
    r : (n_obs, 2)
        ``project - observed``, pixels.
    Jc : (n_obs, 2, 14)
        Derivatives by ``[d_rot(3), C(3), f, cx, cy, k1, k2, k3, p1, p2]``.
    Jp : (n_obs, 2, 3)
        Derivatives by the point.
    valid : (n_obs,) bool
        Point in front of the camera.
    """
    from .problem import BundleProblem

    pb = BundleProblem(intrinsics, image_camera, rotations, centers, points, obs_image, obs_point, obs_xy)
    pb.validate()
    n = pb.n_observations
    if n == 0:
        raise InputError("observation_jacobians: no observations")
    r = np.zeros((n, 2))
    Jc = np.zeros((n, 2, N_CAMCOLS))
    Jp = np.zeros((n, 2, 3))
    valid = np.zeros(n, dtype=np.bool_)
    _linearize(
        pb.points,
        pb.rotations,
        pb.centers,
        pb.intrinsics,
        pb.image_camera,
        pb.obs_image,
        pb.obs_point,
        pb.obs_xy,
        r,
        Jc,
        Jp,
        valid,
    )
    return r, Jc, Jp, valid
