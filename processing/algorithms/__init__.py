"""All TruOrtho Processing algorithms: the provider registers ``ALGORITHMS``.

Add a new algorithm by importing its class here and appending it to the list.
"""

from __future__ import annotations

from .detecttargets import DetectTargetsAlgorithm
from .dsmfilter import DsmFilterAlgorithm
from .environment import EnvironmentAlgorithm
from .exportorientation import ExportOrientationAlgorithm
from .importgcps import ImportGcpsAlgorithm
from .importorientation import ImportOrientationAlgorithm
from .mesh import MeshAlgorithm
from .orientimages import OrientImagesAlgorithm
from .osgm import OsgmAlgorithm
from .pipeline import PipelineAlgorithm
from .pointcloud import DsmToPointCloudAlgorithm, MergePointCloudsAlgorithm
from .trueortho import TrueOrthoAlgorithm

ALGORITHMS: list[type] = [
    PipelineAlgorithm,
    EnvironmentAlgorithm,
    ImportOrientationAlgorithm,
    ExportOrientationAlgorithm,
    ImportGcpsAlgorithm,
    DetectTargetsAlgorithm,
    OrientImagesAlgorithm,
    OsgmAlgorithm,
    TrueOrthoAlgorithm,
    DsmFilterAlgorithm,
    MeshAlgorithm,
    DsmToPointCloudAlgorithm,
    MergePointCloudsAlgorithm,
]
