"""Screenshot of the GCP measurement dock for the docs (issue 19).

    xvfb-run -a .venv/bin/python -P scripts/screenshot_gcp_panel.py [--output docs/img/gcp-panel.png]

Renders a small synthetic block (core.synthetic: 12 nadir photos with their exact orientation and
GCPs), writes the photos and the orientation to a temporary folder, builds the panel on them with a
GCP point layer, measures one GCP in some of its images (at the true positions, as a user would by
clicking) and leaves the rest predicted, then saves ``widget.grab()`` as a PNG.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default=str(ROOT / "docs" / "img" / "gcp-panel.png"))
    ap.add_argument("--size", default="960x1080", help="panel size in screen pixels, WxH")
    args = ap.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))

    import cv2
    import numpy as np
    from qgis.core import QgsApplication, QgsFeature, QgsGeometry, QgsPoint, QgsProject, QgsVectorLayer

    from truortho.core.synthetic import SceneConfig, make_scene

    app = QgsApplication([], True)
    app.initQgis()
    try:
        from truortho.truortho_plugin.gcp_panel import GcpPanel

        scene = make_scene(SceneConfig(image_size=(480, 360), focal_px=560.0, n_oblique=0, seed=2))
        o = scene.orientation
        with tempfile.TemporaryDirectory(prefix="truortho-gcp-shot-") as tmp:
            folder = Path(tmp) / "photos"
            folder.mkdir()
            for im, rgb in zip(o.images, scene.images, strict=True):
                cv2.imwrite(str(folder / im.name), np.ascontiguousarray(rgb[:, :, ::-1]))
            o.image_root = str(folder)
            o.save(Path(tmp) / "orientation.json")

            layer = QgsVectorLayer(
                f"PointZ?crs={o.crs}&field=name:string&field=role:string", "GCPs", "memory"
            )
            feats = []
            for g in o.gcps:
                f = QgsFeature(layer.fields())
                f.setAttributes([g.name, g.role])
                f.setGeometry(QgsGeometry(QgsPoint(*g.xyz)))
                feats.append(f)
            layer.dataProvider().addFeatures(feats)
            QgsProject.instance().addMapLayer(layer)

            panel = GcpPanel()
            panel.resize(width, height)
            panel.folder_edit.setText(str(folder))
            panel.layer_combo.setLayer(layer)
            panel.orientation_edit.setText(str(Path(tmp) / "orientation.json"))
            panel.show()
            if not panel.load():
                print(panel.last_message, file=sys.stderr)
                return 1
            # the most-seen GCP: measured (at the truth, as a click would) in all its images but the one
            # where it is nearest the centre, which is shown with its prediction and another GCP measured
            busiest = max(o.gcps, key=lambda g: len(g.observations))
            w, h = scene.config.image_size
            shown = min(busiest.observations, key=lambda ob: (ob[1] - w / 2) ** 2 + (ob[2] - h / 2) ** 2)[0]
            for name, x, y in busiest.observations:
                if name != shown:
                    panel.select(busiest.name, name)
                    panel.place_at(x, y)
            for g in o.gcps:
                for name, x, y in g.observations:
                    if g is not busiest and (name == shown or name == g.observations[0][0]):
                        panel.select(g.name, name)
                        panel.place_at(x, y)
            panel.select(busiest.name, shown)
            pred = panel.model.prediction(busiest.name, shown)
            panel.view.set_zoom(1.6, (pred.x, pred.y))
            panel.message_bar.clearWidgets()
            for _ in range(5):
                app.processEvents()
            out = Path(args.output)
            out.parent.mkdir(parents=True, exist_ok=True)
            tmp_png = out.with_name(f".{out.stem}.tmp{os.getpid()}.png")
            if not panel.grab().save(str(tmp_png), "PNG"):
                print(f"could not write {tmp_png}", file=sys.stderr)
                return 1
            os.replace(tmp_png, out)
            print(f"{out}: {width} x {height}; {len(o.images)} photos, {len(o.gcps)} GCPs, "
                  f"{len(panel.model)} measured")  # fmt: skip
            panel.close()
            QgsProject.instance().removeAllMapLayers()
    finally:
        app.exitQgis()
    return 0


if __name__ == "__main__":
    sys.exit(main())
