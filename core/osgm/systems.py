"""Reference systems of OSGM: the nadir system and, for oblique blocks, one per viewing direction.

Oblique blocks (``oblique="auto"``): besides the nadir system, the oblique images are grouped by
viewing direction; each group defines a reference system whose Z axis points back along its mean
viewing direction. Every orientation is rotated into it (:func:`system_views`) and OSGM runs there
unchanged (:mod:`.pipeline`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..orientation import Orientation
from .matching import View
from .views import monotonic_radius2


@dataclass
class RefSystem:
    id: int
    name: str
    Q: np.ndarray  # rotation local -> system
    direction: np.ndarray  # world viewing direction (unit, towards the scene)
    images: list[int]


def _axis_rotation(direction) -> np.ndarray:
    """Rotation whose third row is ``-direction`` (system Z points back towards the cameras)."""
    z = -np.asarray(direction, np.float64)
    z /= np.linalg.norm(z)
    ref = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(ref, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.vstack([x, y, z])


def reference_systems(orientation: Orientation, mode: str, group_angle: float) -> list[RefSystem]:
    """The nadir system, plus one per group of oblique images when ``mode == "auto"``."""
    if mode not in ("none", "auto"):
        raise InputError(f"OBLIQUE: expected 'none' or 'auto', got {mode!r}")
    dirs = np.array([im.R[2] for im in orientation.images])  # optical axes in the world
    tilt = np.degrees(np.arccos(np.clip(-dirs[:, 2], -1, 1)))
    systems = [RefSystem(0, "nadir", np.eye(3), np.array([0.0, 0.0, -1.0]), list(range(len(dirs))))]
    if mode != "auto":
        return systems
    obl = [i for i in range(len(dirs)) if tilt[i] > 20.0]
    cosg = math.cos(math.radians(group_angle))
    left = set(obl)
    while left:
        groups = {i: [j for j in left if dirs[i] @ dirs[j] >= cosg] for i in left}
        i = max(groups, key=lambda k: (len(groups[k]), -k))
        members = groups[i]
        d = dirs[members].mean(axis=0)
        d /= np.linalg.norm(d)
        left -= set(members)
        users = [j for j in range(len(dirs)) if dirs[j] @ d >= math.cos(math.radians(group_angle + 15))]
        if len(users) < 2:
            continue
        az = math.degrees(math.atan2(d[0], d[1])) % 360
        systems.append(
            RefSystem(len(systems), f"oblique towards azimuth {az:.0f} deg", _axis_rotation(d), d, users)
        )
    return systems


def system_views(orientation: Orientation, system: RefSystem) -> list[View]:
    views = []
    axis = -system.Q[2]
    for i in system.images:
        im = orientation.images[i]
        cam = orientation.camera_of(im)
        views.append(
            View(i, im.R @ system.Q.T, system.Q @ im.C, cam, monotonic_radius2(cam), float(im.R[2] @ axis))
        )
    return views
