"""``truortho:mesh``: DSM raster or point cloud -> triangle mesh (.ply / .obj)."""

from __future__ import annotations

import os

from qgis.core import (
    QgsProcessingException,
    QgsProcessingOutputNumber,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFile,
    QgsProcessingParameterFileDestination,
    QgsProcessingParameterNumber,
    QgsProcessingParameterRasterLayer,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from .base import FromConfig, TruOrthoAlgorithm
from .dsmfilter import _optional_number

POINT_CLOUD_SUFFIXES = (".las", ".laz")


class MeshAlgorithm(TruOrthoAlgorithm):
    NAME = "mesh"
    DISPLAY_NAME = "Mesh from DSM or point cloud"
    GROUP_ID = "surface"

    INPUT = "INPUT"
    ORTHO = "ORTHO"
    MAX_ERROR = "MAX_ERROR"
    MIN_STEP = "MIN_STEP"
    MAX_SLOPE = "MAX_SLOPE"
    MAX_LEAF = "MAX_LEAF"
    MAX_EDGE = "MAX_EDGE"
    FRAME = "FRAME"
    OUTPUT = "OUTPUT"
    VERTICES = "VERTICES"
    FACES = "FACES"
    WALL_FACES = "WALL_FACES"

    FRAMES = ["crs", "local"]

    CONFIG_DEFAULTS = {
        MAX_ERROR: FromConfig("surface.mesh.DsmMeshConfig", "max_error"),
        MIN_STEP: FromConfig("surface.mesh.DsmMeshConfig", "min_step"),
        MAX_SLOPE: FromConfig("surface.mesh.DsmMeshConfig", "max_slope_deg"),
        MAX_LEAF: FromConfig("surface.mesh.DsmMeshConfig", "max_leaf"),
    }
    OWN_DEFAULTS = {
        MAX_EDGE: "an argument of mesh_from_point_cloud (None = automatic), no config",
        FRAME: "output coordinates, not a meshing parameter: the CRS (first option)",
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        num = QgsProcessingParameterNumber
        self.add(
            QgsProcessingParameterFile(
                self.INPUT,
                tr("DSM raster or point cloud (LAS/LAZ, EPT ept.json)"),
                fileFilter=tr("DSM or point cloud (*.tif *.tiff *.las *.laz *.json);;All files (*.*)"),
            )
        )
        self.add(
            QgsProcessingParameterRasterLayer(self.ORTHO, tr("Orthoimage for vertex colours"), optional=True)
        )
        self.add(
            num(
                self.MAX_ERROR,
                tr("Largest vertical error (m; empty = half the DSM resolution)"),
                num.Double,
                self.default(self.MAX_ERROR),
                optional=True,
                minValue=0.0,
            )
        )
        self.add(
            num(
                self.MIN_STEP,
                tr("Smallest height step made a wall (m)"),
                num.Double,
                self.default(self.MIN_STEP),
                minValue=0.01,
            )
        )
        self.add(
            num(
                self.MAX_SLOPE,
                tr("Steepest slope kept as a surface (degrees)"),
                num.Double,
                self.default(self.MAX_SLOPE),
                minValue=1.0,
                maxValue=89.9,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MAX_LEAF,
                tr("Largest flat block (cells, power of two)"),
                num.Integer,
                self.default(self.MAX_LEAF),
                minValue=1,
                maxValue=256,
            ),
            advanced=True,
        )
        self.add(
            num(
                self.MAX_EDGE,
                tr("Point clouds: longest triangle edge (m; empty = automatic)"),
                num.Double,
                None,
                optional=True,
                minValue=0.0,
            ),
            advanced=True,
        )
        self.add(
            QgsProcessingParameterEnum(
                self.FRAME,
                tr("Coordinates"),
                [tr("CRS (world coordinates)"), tr("Local frame (world - offset, offset in the header)")],
                defaultValue=0,
            )
        )
        self.add(
            QgsProcessingParameterFileDestination(
                self.OUTPUT, tr("Mesh"), tr("PLY mesh (*.ply);;Wavefront OBJ (*.obj)")
            )
        )
        self.addOutput(QgsProcessingOutputNumber(self.VERTICES, tr("Vertices")))
        self.addOutput(QgsProcessingOutputNumber(self.FACES, tr("Faces")))
        self.addOutput(QgsProcessingOutputNumber(self.WALL_FACES, tr("Wall faces")))

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.surface.mesh import DsmMeshConfig, mesh_from_dsm, mesh_from_point_cloud
        from ...core.surface.meshio import check_mesh_path, write_mesh
        from ...core.surface.pointcloud import read_point_cloud

        src = self.parameterAsFile(parameters, self.INPUT, context)
        if not src or not os.path.exists(src):
            raise QgsProcessingException(tr("INPUT: file not found: {}").format(src))
        out = self.parameterAsFileOutput(parameters, self.OUTPUT, context)
        check_mesh_path(out, "OUTPUT")
        frame = self.FRAMES[self.parameterAsEnum(parameters, self.FRAME, context)]
        ortho = self.parameterAsRasterLayer(parameters, self.ORTHO, context)
        progress = FeedbackProgress(feedback)
        walls = 0
        lower = src.lower()
        if lower.endswith(POINT_CLOUD_SUFFIXES) or os.path.basename(lower) == "ept.json":
            if ortho is not None:
                feedback.pushWarning(tr("ORTHO is ignored for point clouds (their own colours are used)"))
            cloud = read_point_cloud(src)
            feedback.pushInfo(
                tr("{} points in {} reference systems").format(
                    len(cloud), len(set(cloud.system.tolist())) if cloud.system is not None else 1
                )
            )
            mesh = mesh_from_point_cloud(
                cloud, _optional_number(self, parameters, self.MAX_EDGE, context), progress=progress
            )
        else:
            cfg = DsmMeshConfig(
                max_error=_optional_number(self, parameters, self.MAX_ERROR, context),
                min_step=self.parameterAsDouble(parameters, self.MIN_STEP, context),
                max_slope_deg=self.parameterAsDouble(parameters, self.MAX_SLOPE, context),
                max_leaf=self.parameterAsInt(parameters, self.MAX_LEAF, context),
            )
            res = mesh_from_dsm(src, cfg, ortho.source() if ortho is not None else None, progress)
            mesh = res.mesh
            walls = res.wall_faces
            feedback.pushInfo(
                tr(
                    "{} cells -> {} vertices ({:.1%} of the cells), {} faces of which {} wall faces; "
                    "step threshold {:.2f} m, vertical error <= {:.3f} m"
                ).format(
                    res.cells,
                    mesh.n_vertices,
                    res.vertex_ratio,
                    mesh.n_faces,
                    walls,
                    res.step_threshold,
                    res.max_error,
                )
            )
        write_mesh(out, mesh, frame=frame)
        return {
            self.OUTPUT: out,
            self.VERTICES: mesh.n_vertices,
            self.FACES: mesh.n_faces,
            self.WALL_FACES: walls,
        }
