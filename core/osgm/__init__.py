"""OSGM: object-space semi-global multi-image matching.

Semi-global matching moved from disparity space into object space: a voxel
grid over the ground (``dX = dY`` the resolution, ``dZ`` the height step),
a matching cost per voxel from *all* images that see it (each image
resampled onto the plane of the voxel's Z level; no rectification, no
pairwise depth maps), aggregation along 8 or 16 paths in XY with penalties
P1/P2 on Z changes, winner-take-all with sub-voxel refinement: a 2.5D DSM
directly. Coarse-to-fine (:mod:`.levels`) and by tiles (:mod:`.matching`),
with several reference systems for oblique images (:mod:`.systems`); the Z range and the
other defaults from the block in :mod:`.zrange`, the run in :mod:`.pipeline`.
The SGM kernels themselves are shared with the rectified matcher
(:mod:`truortho.core.sgm`).
"""

from .levels import LevelPlan, plan_levels
from .pipeline import DSM_NODATA, OsgmConfig, OsgmOutputs, OsgmResult, run_osgm
from .systems import reference_systems

__all__ = [
    "DSM_NODATA",
    "LevelPlan",
    "OsgmConfig",
    "OsgmOutputs",
    "OsgmResult",
    "plan_levels",
    "reference_systems",
    "run_osgm",
]
