"""Synthetic camera and image blocks (local frame, OpenCV camera axes).

Headings and azimuths are degrees clockwise from grid north (+y local). A
nadir image flying along heading ``psi`` has its image top pointing forward:
``y_cam = -f`` with ``f = (sin psi, cos psi, 0)``, ``z_cam = (0, 0, -1)``,
``x_cam = y_cam x z_cam``; the rows of ``R`` are these axes.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..geometry.camera import Camera
from ..geometry.rotation import axis_angle_to_matrix
from ..orientation import Image


def make_camera(width: int, height: int, focal_px: float, principal_offset=(0.0, 0.0),
                distortion=(0.0, 0.0, 0.0, 0.0, 0.0), camera_id: str = "synthetic") -> Camera:
    """Camera with principal point ``image centre + principal_offset``.

    ``distortion = (k1, k2, p1, p2, k3)`` (OpenCV order).
    """
    k1, k2, p1, p2, k3 = (float(v) for v in distortion)
    return Camera(int(width), int(height), float(focal_px), float(focal_px),
                  (width - 1) / 2 + float(principal_offset[0]), (height - 1) / 2 + float(principal_offset[1]),
                  k1, k2, k3, p1, p2, id=camera_id)


def nadir_rotation(heading_deg: float) -> np.ndarray:
    """World-to-camera ``R`` of a nadir image flying along ``heading_deg``."""
    psi = math.radians(heading_deg)
    y = -np.array([math.sin(psi), math.cos(psi), 0.0])
    z = np.array([0.0, 0.0, -1.0])
    return np.array([np.cross(y, z), y, z])


def look_at_rotation(center, target) -> np.ndarray:
    """World-to-camera ``R`` looking from ``center`` at ``target`` with a horizontal image x axis."""
    z = np.asarray(target, dtype=np.float64) - np.asarray(center, dtype=np.float64)
    n = np.linalg.norm(z)
    if not n > 0:
        raise InputError("look_at_rotation: centre and target coincide")
    z /= n
    x = np.cross(z, [0.0, 0.0, 1.0])
    if np.linalg.norm(x) < 1e-9:
        raise InputError("look_at_rotation: vertical viewing direction; use nadir_rotation")
    x /= np.linalg.norm(x)
    return np.array([x, np.cross(z, x), z])


def _perturb(rng: np.random.Generator, R: np.ndarray, C: np.ndarray, sigma_deg: float, sigma_pos: float):
    dR = axis_angle_to_matrix(rng.normal(0.0, math.radians(sigma_deg), 3)) if sigma_deg > 0 else np.eye(3)
    dC = rng.normal(0.0, sigma_pos, 3) if sigma_pos > 0 else np.zeros(3)
    return dR @ R, C + dC


def nadir_block(area, camera: Camera, flying_height: float, ground_z: float = 0.0,
                forward_overlap: float = 0.8, side_overlap: float = 0.6, heading_deg: float = 90.0,
                attitude_sigma_deg: float = 0.8, position_sigma: float = 0.4, seed: int = 0,
                first_index: int = 0, min_strips: int = 2, min_per_strip: int = 3) -> list[Image]:
    """A snake-ordered block of nadir images covering ``area``.

    Parameters
    ----------
    area : (xmin, ymin, xmax, ymax)
        Local area the footprints must cover, metres.
    camera : Camera
        Image size and focal length define the footprint; GSD = flying_height / fx.
    flying_height : float
        Height of the projection centres above ``ground_z``, metres.
    forward_overlap, side_overlap : float
        Overlap fractions along and across track (image height along track).
    heading_deg : float
        Flight direction of the first strip; odd strips fly the opposite way
        (kappa turned by 180 degrees).
    attitude_sigma_deg, position_sigma : float
        Standard deviation of the random rotation (per axis) and position
        perturbation, seeded by ``seed``.
    first_index : int
        Images are named ``img_{first_index + k:03d}.png``.

    Returns
    -------
    list of Image
        Local-frame exterior orientations referring to ``camera.id``.
    """
    x0, y0, x1, y1 = (float(v) for v in area)
    if not (x1 > x0 and y1 > y0) or not flying_height > 0:
        raise InputError("nadir_block: need xmin < xmax, ymin < ymax and a positive flying height")
    if not (0 <= forward_overlap < 1 and 0 <= side_overlap < 1):
        raise InputError("nadir_block: overlaps must lie in [0, 1)")
    gsd = flying_height / camera.fx
    foot_along, foot_across = camera.height * gsd, camera.width * gsd
    base = (1 - forward_overlap) * foot_along
    spacing = (1 - side_overlap) * foot_across
    psi = math.radians(heading_deg)
    f = np.array([math.sin(psi), math.cos(psi)])
    right = np.array([math.cos(psi), -math.sin(psi)])
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    centre = corners.mean(axis=0)
    len_along = np.ptp(corners @ f)
    len_across = np.ptp(corners @ right)
    n_along = max(min_per_strip, math.ceil(max(len_along - foot_along, 0) / base - 1e-9) + 1)
    n_strips = max(min_strips, math.ceil(max(len_across - foot_across, 0) / spacing - 1e-9) + 1)
    if n_along * n_strips > 100000:
        raise InputError("nadir_block: more than 100000 images; check the overlaps and the area")
    rng = np.random.default_rng([seed, 21])
    images: list[Image] = []
    for j in range(n_strips):
        across = (j - (n_strips - 1) / 2) * spacing
        order = range(n_along) if j % 2 == 0 else range(n_along - 1, -1, -1)
        R0 = nadir_rotation(heading_deg + (180.0 if j % 2 else 0.0))
        for k in order:
            along = (k - (n_along - 1) / 2) * base
            xy = centre + along * f + across * right
            R, C = _perturb(rng, R0, np.array([xy[0], xy[1], ground_z + flying_height]),
                            attitude_sigma_deg, position_sigma)
            name = f"img_{first_index + len(images):03d}.png"
            images.append(Image(name, camera.id, R, C))
    return images


def oblique_cameras(target, camera: Camera, flying_height: float, n: int = 4, tilt_deg: float = 40.0,
                    first_azimuth_deg: float = 0.0, attitude_sigma_deg: float = 0.3,
                    position_sigma: float = 0.2, seed: int = 0, first_index: int = 0) -> list[Image]:
    """Oblique images looking at ``target`` from ``n`` azimuths.

    Image ``k`` looks along azimuth ``first_azimuth_deg + 360 k / n`` with
    its optical axis ``tilt_deg`` off nadir through ``target`` (local
    (x, y, z)), from ``flying_height`` above the target height; the image x
    axis is horizontal. Perturbations and names as in :func:`nadir_block`.
    """
    tx, ty, tz = (float(v) for v in target)
    if not 0 < tilt_deg < 89 or not flying_height > 0 or not 1 <= n <= 360:
        raise InputError("oblique_cameras: need 0 < tilt < 89 degrees, a positive height and 1 <= n <= 360")
    rng = np.random.default_rng([seed, 22])
    dist = flying_height * math.tan(math.radians(tilt_deg))
    images: list[Image] = []
    for k in range(n):
        az = math.radians(first_azimuth_deg + 360.0 * k / n)
        look = np.array([math.sin(az), math.cos(az)])
        C0 = np.array([tx - dist * look[0], ty - dist * look[1], tz + flying_height])
        R, C = _perturb(rng, look_at_rotation(C0, (tx, ty, tz)), C0, attitude_sigma_deg, position_sigma)
        images.append(Image(f"img_{first_index + k:03d}.png", camera.id, R, C))
    return images
