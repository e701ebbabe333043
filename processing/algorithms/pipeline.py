"""``truortho:pipeline``: photos (+ GCPs) -> orientation, DSM, point cloud, mesh, true orthophoto, report."""

from __future__ import annotations

import os

from qgis.core import (
    QgsProcessing,
    QgsProcessingContext,
    QgsProcessingException,
    QgsProcessingOutputFile,
    QgsProcessingOutputRasterLayer,
    QgsProcessingOutputVectorLayer,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterCrs,
    QgsProcessingParameterFile,
    QgsProcessingParameterFolderDestination,
    QgsProcessingParameterNumber,
)

from ..feedback import FeedbackProgress, core_errors
from ..i18n import tr
from ..layers import crs_text, ground_control
from .base import FromConfig, TruOrthoAlgorithm, executor_default


class PipelineAlgorithm(TruOrthoAlgorithm):
    NAME = "pipeline"
    DISPLAY_NAME = "Photos to true orthophoto (whole pipeline)"
    GROUP_ID = "orthophoto"

    IMAGES = "IMAGES"
    CAMERA = "CAMERA"
    GCPS = "GCPS"
    OBSERVATIONS = "OBSERVATIONS"
    CRS = "CRS"
    RESOLUTION = "RESOLUTION"
    REUSE_ORIENTATION = "REUSE_ORIENTATION"
    RESTORE_CHROMA = "RESTORE_CHROMA"
    EDGE_COLOUR = "EDGE_COLOUR"
    EXECUTOR = "EXECUTOR"
    SCHEDULER_ADDRESS = "SCHEDULER_ADDRESS"
    OUTPUT_FOLDER = "OUTPUT_FOLDER"
    CONFIG_DEFAULTS = {
        RESOLUTION: FromConfig("workflow.WorkflowConfig", "resolution", none=0.0),
        REUSE_ORIENTATION: FromConfig("workflow.WorkflowConfig", "reuse_orientation"),
        RESTORE_CHROMA: FromConfig("ortho.pipeline.TrueOrthoConfig", "restore_chroma"),
        # EDGE_COLOUR's options are listed in the order of EDGE_COLOURS
        EDGE_COLOUR: FromConfig(
            "ortho.pipeline.TrueOrthoConfig", "edge_colour", "ortho.edgecolour.EDGE_COLOURS"
        ),
        EXECUTOR: executor_default("workflow.WorkflowConfig"),
    }
    # outputs (files named in truortho.core.workflow.PRODUCTS)
    OUTPUTS = {
        "ORIENTATION": "orientation",
        "REPORT": "report",
        "DSM": "dsm",
        "POINT_CLOUD": "pointcloud",
        "MESH": "mesh",
        "TRUE_ORTHO": "trueortho",
        "OCCLUSION": "occlusion",
        "SEAMLINES": "seamlines",
    }

    def initAlgorithm(self, config=None):  # noqa: N802 - QGIS API
        self.add(
            QgsProcessingParameterFile(
                self.IMAGES, tr("Image folder"), behavior=QgsProcessingParameterFile.Folder, optional=True
            )
        )
        self.add(
            QgsProcessingParameterFile(
                self.CAMERA, tr("Interior orientation file (optional)"), optional=True
            ),
            advanced=True,
        )
        self.add_ground_control()
        self.add(QgsProcessingParameterCrs(self.CRS, tr("Output CRS"), optional=True))
        self.add(
            QgsProcessingParameterNumber(
                self.RESOLUTION,
                tr("Resolution of the DSM and the true orthophoto (m, 0 = ground sample distance)"),
                QgsProcessingParameterNumber.Double,
                self.default(self.RESOLUTION),
                minValue=0.0,
            )
        )
        self.add(
            QgsProcessingParameterBoolean(
                self.REUSE_ORIENTATION,
                tr("Reuse an existing orientation.json in the output folder"),
                self.default(self.REUSE_ORIENTATION),
            )
        )
        self.add_restore_chroma()
        self.add_edge_colour()
        self.add_executor()
        self.add(QgsProcessingParameterFolderDestination(self.OUTPUT_FOLDER, tr("Output folder")))
        names = {
            "ORIENTATION": tr("Orientation (JSON)"),
            "REPORT": tr("Report (HTML)"),
            "DSM": tr("DSM (filtered)"),
            "POINT_CLOUD": tr("Point cloud"),
            "MESH": tr("Mesh"),
            "TRUE_ORTHO": tr("True orthophoto"),
            "OCCLUSION": tr("Occlusion mask"),
            "SEAMLINES": tr("Seamlines"),
        }
        for key, label in names.items():
            if key in ("DSM", "TRUE_ORTHO", "OCCLUSION"):
                self.addOutput(QgsProcessingOutputRasterLayer(key, label))
            elif key == "SEAMLINES":
                self.addOutput(QgsProcessingOutputVectorLayer(key, label, QgsProcessing.TypeVectorPolygon))
            else:
                self.addOutput(QgsProcessingOutputFile(key, label))

    def _images(self, parameters, context, reuse: bool, folder_out: str) -> list[str]:
        folder = self.parameterAsFile(parameters, self.IMAGES, context)
        if not folder:
            if reuse and os.path.exists(os.path.join(folder_out, "orientation.json")):
                return []
            raise QgsProcessingException(tr("IMAGES: give the folder of the photos"))
        if not os.path.isdir(folder):
            raise QgsProcessingException(tr("IMAGES: {} is not a folder").format(folder))
        return [
            os.path.join(folder, n)
            for n in sorted(os.listdir(folder))
            if os.path.isfile(os.path.join(folder, n))
        ]

    @core_errors()
    def processAlgorithm(self, parameters, context, feedback):  # noqa: N802 - QGIS API
        from ...core.ortho.pipeline import TrueOrthoConfig
        from ...core.workflow import WorkflowConfig, run_workflow

        out_folder = self.parameterAsString(parameters, self.OUTPUT_FOLDER, context)
        if not out_folder:
            raise QgsProcessingException(tr("OUTPUT_FOLDER: give a folder for the products"))
        out_folder = self.parameterAsFileOutput(parameters, self.OUTPUT_FOLDER, context) or out_folder
        reuse = self.parameterAsBool(parameters, self.REUSE_ORIENTATION, context)
        images = self._images(parameters, context, reuse, out_folder)
        crs = self.parameterAsCrs(parameters, self.CRS, context)
        gcp_layer = self.parameterAsVectorLayer(parameters, self.GCPS, context)
        obs_layer = self.parameterAsVectorLayer(parameters, self.OBSERVATIONS, context)
        gcps, crs = ground_control(gcp_layer, obs_layer, crs, context.transformContext())
        res = self.parameterAsDouble(parameters, self.RESOLUTION, context)
        if res < 0:
            raise QgsProcessingException(tr("RESOLUTION: expected a positive number of metres or 0"))
        executor_kind, address = self.executor_choice(parameters, context)
        cfg = WorkflowConfig(
            resolution=res if res > 0 else None,
            camera_file=self.parameterAsFile(parameters, self.CAMERA, context) or None,
            reuse_orientation=reuse,
            ortho=TrueOrthoConfig(
                restore_chroma=self.parameterAsBool(parameters, self.RESTORE_CHROMA, context),
                edge_colour=self.edge_colour_choice(parameters, context),
            ),
            # one executor for OSGM, the DSM filter and the true orthophoto (made and closed by run_workflow)
            executor=executor_kind,
            scheduler_address=address,
        )
        run = run_workflow(
            images,
            out_folder,
            gcps,
            crs_text(crs) if crs.isValid() else None,
            cfg,
            FeedbackProgress(feedback, eta=False),  # the workflow estimates per stage
        )
        for row in run.stats["stages"]:
            feedback.pushInfo(tr("{}: {:.1f} s, peak {:.0f} MB; {}").format(row[0], row[1], row[2], row[3]))
        feedback.pushInfo(tr("Tiles ran on: {}").format(run.stats["executor"]))
        for w in run.report.warnings if run.report is not None else []:  # also in report.html
            feedback.pushWarning(w)
        results = {key: run.paths[prod] for key, prod in self.OUTPUTS.items()}
        results[self.OUTPUT_FOLDER] = out_folder
        self._load(context, results)
        return results

    def _load(self, context, results) -> None:
        """In the GUI: load the DSM (hillshade), the true orthophoto, the occlusion mask and the seamlines."""
        from ..styles import style_on_load

        project = context.project()
        if project is None:
            return
        for key, kind, name in (
            ("DSM", "dsm", tr("DSM (TruOrtho)")),
            ("TRUE_ORTHO", "ortho", tr("True orthophoto (TruOrtho)")),
            ("OCCLUSION", "occlusion", tr("Occlusion (TruOrtho)")),
            ("SEAMLINES", None, tr("Seamlines (TruOrtho)")),
        ):
            path = results[key]
            context.addLayerToLoadOnCompletion(path, QgsProcessingContext.LayerDetails(name, project, key))
            if kind is not None:
                style_on_load(context, path, kind, name)
