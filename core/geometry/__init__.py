"""Geometry of TruOrtho: the conventions, stated once.

Every module of the project refers here; importers convert to these
conventions at the border (when a file is read) and exporters from them
(when one is written), never anywhere else.

World and local frame
---------------------
* The *world* frame is the orientation's CRS: a projected (metric) CRS with
  easting X, northing Y and height Z, all in metres. Geographic CRSs (degrees)
  are rejected for computation.
* Computation happens in a *local* frame: ``local = world - offset`` with one
  3-vector ``offset`` per orientation (:class:`~.frame.LocalFrame`). The
  offset is chosen near the block centre so float64 keeps sub-millimetre
  precision for UTM-size coordinates. GCP coordinates are stored in the world
  frame; camera centres, sparse points and everything numerical are local.

Camera axes (OpenCV / COLMAP / OpenSfM convention)
--------------------------------------------------
x to the right of the image, y down the image, z forward along the viewing
direction. A point in front of the camera has z > 0.

Rotation
--------
``R`` (3x3, orthonormal, det +1) rotates *world to camera*:
``X_cam = R @ (X_local - C)`` with ``C`` the projection centre in the local
frame. This is COLMAP's ``R`` (its translation is ``t = -R C``).

Other parametrisations (:mod:`.rotation`):

* quaternion ``(w, x, y, z)``, Hamilton, of the world-to-camera ``R``
  (COLMAP's ``QW QX QY QZ``); normalised on input, returned with ``w >= 0``;
* axis-angle (rotation vector) of the world-to-camera ``R`` (OpenSfM's
  ``rotation``, OpenCV's ``rvec``);
* omega-phi-kappa (photogrammetric, as Orthority, Pix4D and Metashape exchange
  them): ``M = Rx(omega) @ Ry(phi) @ Rz(kappa)`` rotates *camera to world*
  with camera axes x right, y up, z backwards (the "PATB" image frame); hence
  ``R = diag(1, -1, -1) @ M.T``. Angles in degrees in files, radians in code.
  Angles are relative to the grid of the CRS (grid north), not true north.

Pixels
------
Pixel coordinates are ``(x, y)`` = (column, row) in the image as stored, x to
the right, y down, and **the centre of the top-left pixel is (0, 0)** (OpenCV
and OpenSfM convention; the image spans ``[-0.5, width - 0.5]``). COLMAP puts
the top-left *corner* at (0, 0): its principal point and its observations
are shifted by -0.5 px on import (+0.5 on export). GCP image measurements use
this same convention.

Interior orientation (:mod:`.camera`)
-------------------------------------
Pinhole with Brown / OpenCV distortion, all in pixels: focal lengths ``fx``,
``fy``, principal point ``cx``, ``cy``, radial ``k1, k2, k3`` and tangential
``p1, p2``:

    x' = X/Z, y' = Y/Z, r2 = x'^2 + y'^2
    x'' = x' (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x' y' + p2 (r2 + 2 x'^2)
    y'' = y' (1 + k1 r2 + k2 r2^2 + k3 r2^3) + p1 (r2 + 2 y'^2) + 2 p2 x' y'
    u = fx x'' + cx,  v = fy y'' + cy

exactly as OpenCV's ``projectPoints`` with 5 coefficients
``(k1, k2, p1, p2, k3)``. Pixel to ray inverts the distortion iteratively
(Newton).

Units: metres, radians (in code), pixels.
"""

from .camera import Camera, pixel_to_ray, project_points, undistort_points
from .frame import LocalFrame
from .rotation import (
    axis_angle_to_matrix,
    matrix_to_axis_angle,
    matrix_to_opk,
    matrix_to_quaternion,
    opk_to_matrix,
    quaternion_to_matrix,
)

__all__ = [
    "Camera",
    "LocalFrame",
    "axis_angle_to_matrix",
    "matrix_to_axis_angle",
    "matrix_to_opk",
    "matrix_to_quaternion",
    "opk_to_matrix",
    "pixel_to_ray",
    "project_points",
    "quaternion_to_matrix",
    "undistort_points",
]
