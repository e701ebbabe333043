"""Regenerate the Processing model shipped with the plugin: processing/models/truortho_chain.model3.

The model chains the TruOrtho algorithms: Orient images -> Dense matching (OSGM) -> Filter DSM ->
True orthophoto and Mesh. It is built with QGIS's model API in a headless QgsApplication with the
TruOrtho provider registered (so every child algorithm's parameters are known), then saved with
``QgsProcessingModelAlgorithm.toFile`` in the XML format of the running QGIS (3.22).

    source scripts/env.sh && python -P scripts/make_model.py [--output PATH]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ["QT_HASH_SEED"] = "0"  # fixed XML attribute order: the same model gives the same file

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_OUTPUT = ROOT / "processing" / "models" / "truortho_chain.model3"

NAME = "truortho_chain"
GROUP = "TruOrtho"

HELP = {
    "ALG_DESC": (
        "The whole TruOrtho chain in one run: orients the images of a folder (bundle block adjustment, "
        "optionally with ground control), matches them densely (object-space semi-global matching) "
        "into a DSM with a confidence raster and a point cloud, filters the DSM (outliers, holes, "
        "smoothing), and computes a true orthophoto (with occlusion mask and seamlines) and a mesh "
        "from the filtered DSM. Every step is also available as its own algorithm with more options."
    ),
    "ALG_CREATOR": "TruOrtho",
    "ALG_HELP_CREATOR": "TruOrtho",
    "IMAGES": "Folder of the images (non-image files are skipped with a warning in the report).",
    "GCPS": (
        "Optional ground control and check points: point layer with 'name', 'role' (gcp|check), PointZ "
        "or 'z' (e.g. from Import GCP list)."
    ),
    "OBSERVATIONS": (
        "Optional image measurements of the GCPs: table with 'gcp', 'image', 'x', 'y' (pixels), e.g. from "
        "Import GCP list. Needed with GCPS."
    ),
    "CRS": "CRS of all outputs (default: the GCP layer's, else the UTM zone of the EXIF GNSS positions).",
    "RESOLUTION": (
        "Cell size of the DSM and the true orthophoto, metres; 0 = the median ground sample distance "
        "of the near-nadir images."
    ),
    "orientation": "The adjusted orientation (TruOrtho JSON).",
    "report": "HTML report of the adjustment (and a JSON file of the same name).",
    "dsm": "The filtered DSM (GeoTIFF, float32).",
    "pointcloud": "The dense point cloud (.laz or .las).",
    "mesh": "Mesh of the filtered DSM (.ply or .obj).",
    "trueortho": "The true orthophoto (GeoTIFF with alpha band).",
    "occlusion": "Occlusion mask: 1 where no image sees the cell, 0 where seen, 255 = no surface.",
    "seamlines": "Seamlines: one polygon per source image, the cells it colours.",
}


def build_model():
    """The model as a QgsProcessingModelAlgorithm (needs a running QgsApplication with the provider)."""
    from qgis.core import (
        QgsProcessing,
        QgsProcessingModelAlgorithm,
        QgsProcessingModelChildAlgorithm,
        QgsProcessingModelChildParameterSource,
        QgsProcessingModelOutput,
        QgsProcessingModelParameter,
        QgsProcessingParameterCrs,
        QgsProcessingParameterFile,
        QgsProcessingParameterNumber,
        QgsProcessingParameterVectorLayer,
    )
    from qgis.PyQt.QtCore import QPointF

    Src = QgsProcessingModelChildParameterSource  # noqa: N806 - QGIS class alias

    model = QgsProcessingModelAlgorithm(NAME, GROUP, GROUP)
    model.setHelpContent(HELP)

    # ---------------------------------------------------------------- inputs
    inputs = [
        QgsProcessingParameterFile("IMAGES", "Image folder", behavior=QgsProcessingParameterFile.Folder),
        QgsProcessingParameterVectorLayer(
            "GCPS", "Ground control points", [QgsProcessing.TypeVectorPoint], optional=True
        ),
        QgsProcessingParameterVectorLayer(
            "OBSERVATIONS", "GCP image measurements (table)", [QgsProcessing.TypeVector], optional=True
        ),
        QgsProcessingParameterCrs("CRS", "Output CRS", optional=True),
        QgsProcessingParameterNumber(
            "RESOLUTION",
            "Resolution (m; 0 = median ground sample distance)",
            QgsProcessingParameterNumber.Double,
            0.0,
            minValue=0.0,
        ),
    ]
    for i, param in enumerate(inputs):
        param.setHelp(HELP[param.name()])
        comp = QgsProcessingModelParameter(param.name())
        comp.setPosition(QPointF(120.0 + 200.0 * i, 60.0))
        model.addModelParameter(param, comp)

    def child(child_id, alg_id, description, x, y, sources, outputs):
        alg = QgsProcessingModelChildAlgorithm(alg_id)
        alg.setChildId(child_id)
        alg.setDescription(description)
        alg.setPosition(QPointF(x, y))
        if alg.algorithm() is None:
            raise SystemExit(f"make_model: algorithm {alg_id} is not registered")
        for name, source in sources.items():
            alg.addParameterSources(name, [source])
        # other mandatory inputs get the algorithm's default as a static value (a model must set them);
        # optional ones stay unset, so the algorithm applies its own default when it runs
        for param in alg.algorithm().parameterDefinitions():
            if param.isDestination() or param.name() in sources or param.flags() & param.FlagOptional:
                continue
            alg.addParameterSources(param.name(), [Src.fromStaticValue(param.defaultValue())])
        model_outputs = {}
        for name, (child_output, description) in outputs.items():
            out = QgsProcessingModelOutput(name, description)
            out.setChildId(child_id)
            out.setChildOutputName(child_output)
            out.setMandatory(True)  # every output is written: to a temporary file unless a path is given
            out.setDefaultValue(QgsProcessing.TEMPORARY_OUTPUT)
            out.setPosition(QPointF(x + 260.0, y + 40.0 * len(model_outputs)))
            model_outputs[name] = out
        alg.setModelOutputs(model_outputs)
        model.addChildAlgorithm(alg)

    child(
        "orientimages",
        "truortho:orientimages",
        "Orient images",
        200.0,
        220.0,
        {
            "IMAGES": Src.fromModelParameter("IMAGES"),
            "GCPS": Src.fromModelParameter("GCPS"),
            "OBSERVATIONS": Src.fromModelParameter("OBSERVATIONS"),
            "CRS": Src.fromModelParameter("CRS"),
        },
        {"orientation": ("ORIENTATION", "Orientation (JSON)"), "report": ("REPORT", "Report (HTML)")},
    )
    child(
        "osgm",
        "truortho:osgm",
        "Dense matching (OSGM)",
        200.0,
        360.0,
        {
            "ORIENTATION": Src.fromChildOutput("orientimages", "ORIENTATION"),
            "RESOLUTION": Src.fromModelParameter("RESOLUTION"),
        },
        {"pointcloud": ("POINT_CLOUD", "Point cloud")},
    )
    child(
        "dsmfilter",
        "truortho:dsmfilter",
        "Filter DSM",
        200.0,
        500.0,
        {
            "INPUT": Src.fromChildOutput("osgm", "DSM"),
            "CONFIDENCE": Src.fromChildOutput("osgm", "CONFIDENCE"),
        },
        {"dsm": ("OUTPUT", "Filtered DSM")},
    )
    child(
        "trueortho",
        "truortho:trueortho",
        "True orthophoto",
        200.0,
        640.0,
        {
            "ORIENTATION": Src.fromChildOutput("orientimages", "ORIENTATION"),
            "SURFACE": Src.fromChildOutput("dsmfilter", "OUTPUT"),
            "RESOLUTION": Src.fromModelParameter("RESOLUTION"),
        },
        {
            "trueortho": ("OUTPUT", "True orthophoto"),
            "occlusion": ("OCCLUSION", "Occlusion mask"),
            "seamlines": ("SEAMLINES", "Seamlines"),
        },
    )
    child(
        "mesh",
        "truortho:mesh",
        "Mesh",
        600.0,
        640.0,
        {"INPUT": Src.fromChildOutput("dsmfilter", "OUTPUT")},
        {"mesh": ("OUTPUT", "Mesh")},
    )
    return model


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default=str(DEFAULT_OUTPUT), help=f"model file (default {DEFAULT_OUTPUT})")
    args = ap.parse_args(argv)

    from qgis.core import QgsApplication

    app = QgsApplication([], False)
    app.initQgis()
    try:
        from truortho.processing.provider import TruOrthoProvider

        provider = TruOrthoProvider()
        QgsApplication.processingRegistry().addProvider(provider)
        model = build_model()
        errors = model.validate()[1]
        if errors:
            raise SystemExit("make_model: the model is not valid:\n" + "\n".join(errors))
        out = Path(args.output)
        out.parent.mkdir(parents=True, exist_ok=True)
        if not model.toFile(str(out)):
            raise SystemExit(f"make_model: could not write {out}")
        print(f"wrote {out}")
    finally:
        app.exitQgis()
    return 0


if __name__ == "__main__":
    sys.exit(main())
