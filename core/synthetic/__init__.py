"""Deterministic synthetic scenes for accuracy tests.

A scene is an analytic 2.5D height field (undulating terrain plus buildings
with flat, gable, hip and shed roofs and a tall tower, all with vertical
walls; :mod:`.surface`), textured with 3D value noise and distinct roof, wall
and ground colours (:mod:`.texture`), photographed by a nadir block and
oblique images (:mod:`.cameras`) rendered by exact ray casting with
supersampling and per-image radiometry (:mod:`.raycast`, :mod:`.render`).
Truth (DSM, true orthophoto, visibility, GCPs) is in :mod:`.truth`.

Frames: ``world = local + offset`` (``SceneConfig.offset``, CRS
``SceneConfig.crs``); surface, cameras and rays work in the local frame,
truth rasters and GCPs are given in the world frame. Conventions of
:mod:`truortho.core.geometry` throughout.

Example
-------
>>> from truortho.core.synthetic import SceneConfig, make_scene
>>> scene = make_scene(SceneConfig(seed=3))
>>> scene.write("/tmp/synthetic")                       # doctest: +SKIP
>>> dsm, gt = scene.dsm(0.25)                           # doctest: +SKIP
"""

from .cameras import look_at_rotation, make_camera, nadir_block, nadir_rotation, oblique_cameras
from .config import SceneConfig
from .raycast import cast_rays
from .render import Radiometry
from .scene import RenderResult, SyntheticScene, make_scene
from .surface import ROOF_SHAPES, Building, Surface
from .texture import GROUND, ROOF, SKY, WALL, srgb_to_lab

__all__ = [
    "GROUND",
    "ROOF",
    "ROOF_SHAPES",
    "SKY",
    "WALL",
    "Building",
    "Radiometry",
    "RenderResult",
    "SceneConfig",
    "Surface",
    "SyntheticScene",
    "cast_rays",
    "look_at_rotation",
    "make_camera",
    "make_scene",
    "nadir_block",
    "nadir_rotation",
    "oblique_cameras",
    "srgb_to_lab",
]
