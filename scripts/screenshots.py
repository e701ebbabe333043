"""Pictures for the user guide, made from the products of a demo run (issue 20).

    bash scripts/demo.sh                                  # products in build/demo/products
    xvfb-run -a .venv/bin/python -P scripts/screenshots.py [--products build/demo/products]

Writes into docs/img/:

* ``pipeline-dialog.png``: the dialog of ``truortho:pipeline`` as the toolbox opens it;
* ``demo-layers.png``: the layers the pipeline loads (hillshaded DSM, true orthophoto, occlusion
  mask, seamlines), styled as the plugin styles them, rendered by QGIS's map renderer;
* ``report.png``: the top of the products' ``report.html`` in headless Chromium (no network: the
  report embeds its plots), when ``chromium`` is installed (``apt install chromium``).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
IMG = ROOT / "docs" / "img"


def _qgis():
    from qgis.core import QgsApplication

    app = QgsApplication([], True)
    app.initQgis()
    plugins = os.path.join(QgsApplication.pkgDataPath(), "python", "plugins")
    if plugins not in sys.path:
        sys.path.append(plugins)
    from processing.core.Processing import Processing

    Processing.initialize()
    from truortho.processing.provider import TruOrthoProvider

    provider = TruOrthoProvider()
    QgsApplication.processingRegistry().addProvider(provider)
    return app, provider


def pipeline_dialog(out: Path, products: Path | None) -> None:
    """The toolbox's dialog of truortho:pipeline, filled as for the demo."""
    import qgis.utils
    from processing.gui.AlgorithmDialog import AlgorithmDialog
    from qgis.core import QgsApplication
    from qgis.gui import QgsMapCanvas
    from qgis.PyQt.QtWidgets import QMainWindow

    window = QMainWindow()
    canvas = QgsMapCanvas(window)

    class _Iface:  # the little of QGIS's interface the Processing dialog asks for
        def mainWindow(self):  # noqa: N802 - QGIS API
            return window

        def mapCanvas(self):  # noqa: N802 - QGIS API
            return canvas

        def messageBar(self):  # noqa: N802 - QGIS API
            return None

    qgis.utils.iface = _Iface()
    alg = QgsApplication.processingRegistry().createAlgorithmById("truortho:pipeline")
    dialog = AlgorithmDialog(alg)
    dialog.resize(900, 760)
    sample = ROOT / "sample" / "copr"
    values = {"IMAGES": str(sample / "images"), "RESOLUTION": 0.1}
    if products is not None:
        values["OUTPUT_FOLDER"] = str(products)
    dialog.setParameters(values)
    dialog.show()
    QgsApplication.processEvents()
    dialog.grab().save(str(out))
    dialog.close()


def demo_layers(out: Path, products: Path, size: tuple[int, int] = (1400, 0)) -> None:
    """The pipeline's layers as the plugin loads and styles them, rendered to a PNG."""
    from qgis.core import (
        QgsFillSymbol,
        QgsMapRendererParallelJob,
        QgsMapSettings,
        QgsRasterLayer,
        QgsRectangle,
        QgsVectorLayer,
    )
    from qgis.PyQt.QtCore import QSize
    from qgis.PyQt.QtGui import QColor

    from truortho.processing.styles import apply_style

    ortho = QgsRasterLayer(str(products / "trueortho.tif"), "True orthophoto")
    dsm = QgsRasterLayer(str(products / "dsm.tif"), "DSM")
    occl = QgsRasterLayer(str(products / "occlusion.tif"), "Occlusion")
    seams = QgsVectorLayer(str(products / "seamlines.gpkg"), "Seamlines", "ogr")
    for layer, kind in ((ortho, "ortho"), (dsm, "dsm"), (occl, "occlusion")):
        if not layer.isValid() or not apply_style(layer, kind):
            raise SystemExit(f"{layer.source()}: not a valid {kind} product")
    symbol = QgsFillSymbol.createSimple(
        {"color": "0,0,0,0", "outline_color": "255,230,0", "outline_width": "0.4"}
    )
    seams.renderer().setSymbol(symbol)
    # left half: the true ortho with occlusion and seamlines; right half: the DSM hillshade
    ext = ortho.extent()
    w = size[0]
    h = max(1, round(w / 2 * ext.height() / max(ext.width(), 1e-9)))  # each half keeps the extent's shape
    images = []
    for layers in ([seams, occl, ortho], [dsm]):
        ms = QgsMapSettings()
        ms.setLayers(layers)
        ms.setDestinationCrs(ortho.crs())
        ms.setBackgroundColor(QColor(255, 255, 255))
        ms.setOutputSize(QSize(w // 2, h))
        ms.setExtent(QgsRectangle(ext))
        job = QgsMapRendererParallelJob(ms)
        job.start()
        job.waitForFinished()
        images.append(job.renderedImage())
    from qgis.PyQt.QtGui import QImage, QPainter

    canvas = QImage(w, h, QImage.Format_ARGB32)
    canvas.fill(QColor(255, 255, 255))
    painter = QPainter(canvas)
    painter.drawImage(0, 0, images[0])
    painter.drawImage(w // 2, 0, images[1])
    painter.end()
    canvas.save(str(out))


def report(out: Path, products: Path) -> bool:
    """The top of report.html in headless Chromium; False when Chromium is not installed."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if exe is None:
        print("report.png: chromium not installed (apt install chromium); skipped")
        return False
    html = products / "report.html"
    with tempfile.TemporaryDirectory(prefix="truortho-shot-") as profile:
        cmd = [
            exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            f"--user-data-dir={profile}", "--window-size=1200,1600", f"--screenshot={out}",
            html.resolve().as_uri(),
        ]  # fmt: skip
        subprocess.run(cmd, check=True, capture_output=True, timeout=120)
    return out.is_file()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--products", default=str(ROOT / "build" / "demo" / "products"))
    ap.add_argument("--output", default=str(IMG), help="folder of the pictures")
    args = ap.parse_args(argv)
    products = Path(args.products)
    if not (products / "trueortho.tif").is_file():
        raise SystemExit(f"{products}: no trueortho.tif; run bash scripts/demo.sh first")
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    app, _provider = _qgis()
    pipeline_dialog(out / "pipeline-dialog.png", None)
    demo_layers(out / "demo-layers.png", products)
    report(out / "report.png", products)
    for name in ("pipeline-dialog.png", "demo-layers.png", "report.png"):
        if (out / name).is_file():
            print(f"wrote {out / name}")
    del app
    return 0


if __name__ == "__main__":
    sys.exit(main())
