"""The GCP measurement dock (truortho_plugin/gcp_panel.py) driven like a user: clicks on the image view
(QTest mouse events at a zoom != 1, mapped view -> scene -> pixel), keys, save, reload, undo, prediction
from an orientation, bad input. (pytest-qt's qtbot is not installed; QTest is what it wraps.)"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.qgis

CRS = "EPSG:32632"
OFFSET = np.array([500000.0, 5600000.0, 0.0])


@pytest.fixture
def block(tmp_path, qgis_processing_ready):
    """Three nadir photos of 160 x 120 pixels, their orientation and a GCP PointZ memory layer."""
    import cv2
    from qgis.core import QgsFeature, QgsGeometry, QgsPoint, QgsProject, QgsVectorLayer

    from truortho.core.geometry.frame import LocalFrame
    from truortho.core.orientation import Orientation
    from truortho.core.synthetic import make_camera, nadir_block

    cam = make_camera(160, 120, 150.0, (0.7, -0.4), (-0.03, 0.0, 0.0, 0.0, 0.0))
    images = nadir_block((-10, -8, 10, 8), cam, 40.0, 0.0, 0.6, 0.3, 90.0, 0.5, 0.2, seed=3, min_strips=1)
    folder = tmp_path / "photos"
    folder.mkdir()
    rng = np.random.default_rng(0)
    for im in images:
        cv2.imwrite(str(folder / im.name), rng.integers(0, 255, (120, 160, 3), dtype=np.uint8))
    o = Orientation(LocalFrame(CRS, OFFSET), {cam.id: cam}, images, image_root=str(folder))
    o.save(tmp_path / "orientation.json")
    layer = QgsVectorLayer(f"PointZ?crs={CRS}&field=name:string&field=role:string", "gcps", "memory")
    feats = []
    for name, (x, y, z), role in (("A", (1.5, -2.0, 0.3), "gcp"), ("B", (-4.0, 3.0, 0.0), "gcp"),
                                  ("C", (3.0, 2.5, 1.0), "check")):  # fmt: skip
        f = QgsFeature(layer.fields())
        f.setAttributes([name, role])
        f.setGeometry(QgsGeometry(QgsPoint(OFFSET[0] + x, OFFSET[1] + y, z)))
        feats.append(f)
    layer.dataProvider().addFeatures(feats)
    QgsProject.instance().addMapLayer(layer)
    yield {"folder": folder, "orientation": o, "path": tmp_path / "orientation.json", "layer": layer,
           "tmp": tmp_path}  # fmt: skip
    QgsProject.instance().removeAllMapLayers()


@pytest.fixture
def panel(block):
    from truortho.truortho_plugin.gcp_panel import GcpPanel

    p = GcpPanel()
    p.resize(700, 800)
    p.show()
    p.folder_edit.setText(str(block["folder"]))
    p.layer_combo.setLayer(block["layer"])
    yield p
    p.close()
    p.deleteLater()


def _click(view, x: float, y: float):
    """A left click where image pixel (x, y) is on screen; returns the viewport point used."""
    from qgis.PyQt.QtCore import QPointF, Qt
    from qgis.PyQt.QtTest import QTest

    pt = view.mapFromScene(QPointF(x, y))
    QTest.mouseClick(view.viewport(), Qt.LeftButton, Qt.NoModifier, pt)
    return pt


def test_click_save_reload_undo(panel, block):
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    assert panel.load(), panel.last_message
    m = panel.model
    assert [g.name for g in m.gcps] == ["A", "B", "C"] and m.gcps[2].check
    assert len(m.photos) == len(block["orientation"].images) >= 3
    assert panel.table.rowCount() == 3 and panel.table.columnCount() == len(m.photos)
    image = m.photos[1].name
    panel.select("B", image)
    panel.view.set_zoom(3.0, (40.0, 30.0))
    assert panel.view.zoom() == pytest.approx(3.0)
    _click(panel.view, 41.3, 29.6)
    meas = m.get("B", image)
    assert meas is not None and meas.source == "manual"
    # a click lands on the screen pixel holding the point: at zoom 3 within 1/3 image pixel
    assert abs(meas.x - 41.3) <= 1 / 3 + 1e-9 and abs(meas.y - 29.6) <= 1 / 3 + 1e-9
    r, c = panel.cell_of("B", image)
    assert panel.table.item(r, c).text() == "●"
    assert any(mk.kind == "measured" for mk in panel.view.markers())
    # move it at another zoom (and a pan by drag in between does not place anything)
    panel.view.set_zoom(0.5, (80.0, 60.0))
    vp = panel.view.viewport()
    start = panel.view.mapFromScene(20.0, 20.0)
    QTest.mousePress(vp, Qt.LeftButton, Qt.NoModifier, start)
    from qgis.PyQt.QtCore import QPoint

    QTest.mouseMove(vp, start + QPoint(30, 20))
    QTest.mouseRelease(vp, Qt.LeftButton, Qt.NoModifier, start + QPoint(30, 20))
    assert m.get("B", image) == meas
    _click(panel.view, 100.0, 90.0)
    moved = m.get("B", image)
    assert abs(moved.x - 100.0) <= 2.0 + 1e-9 and abs(moved.y - 90.0) <= 2.0 + 1e-9
    panel.select("A", m.photos[0].name)
    panel.view.set_zoom(1.7, (60.0, 50.0))
    _click(panel.view, 60.0, 50.0)
    a = m.get("A", m.photos[0].name)
    assert abs(a.x - 60.0) <= 1 / 1.7 and abs(a.y - 50.0) <= 1 / 1.7
    # save, then reload into a fresh panel: identical measurements
    csv_path = block["tmp"] / "obs.csv"
    assert panel.save_csv(str(csv_path)), panel.last_message
    lst = block["tmp"] / "gcp_list.txt"
    assert panel.save_gcp_list(str(lst)), panel.last_message
    saved = m.measurements()
    from truortho.truortho_plugin.gcp_panel import GcpPanel

    other = GcpPanel()
    other.folder_edit.setText(str(block["folder"]))
    other.layer_combo.setLayer(block["layer"])
    assert other.load()
    assert other.load_table(str(csv_path))
    assert other.model.measurements() == saved
    assert other.load_table(str(lst))
    assert [(x.gcp, x.image, x.x, x.y) for x in other.model.measurements()] == [
        (x.gcp, x.image, x.x, x.y) for x in saved
    ]
    other.deleteLater()
    # undo with the keyboard (Ctrl+Z on the view), redo with Ctrl+Shift+Z
    panel.view.setFocus()
    QTest.keyClick(panel.view, Qt.Key_Z, Qt.ControlModifier)
    assert m.get("A", m.photos[0].name) is None
    QTest.keyClick(panel.view, Qt.Key_Z, Qt.ControlModifier)
    assert m.get("B", image) == meas  # the move undone
    QTest.keyClick(panel.view, Qt.Key_Z, Qt.ControlModifier | Qt.ShiftModifier)
    assert m.get("B", image) == moved
    assert panel.undo() and panel.undo() and not panel.undo()
    assert len(m) == 0 and panel.table.item(r, c).text() != "●"
    # a reload (Load again) keeps the measurements of GCPs and images that still exist, not undoable
    assert panel.redo() and panel.load()
    assert panel.model is not m and panel.model.measurements() == [meas] and not panel.model.can_undo


def test_bad_clicks_and_files_change_nothing(panel, block):
    assert panel.load()
    m = panel.model
    image = m.photos[0].name
    panel.select("A", image)
    panel.view.set_zoom(2.0, (10.0, 10.0))
    _click(panel.view, 10.0, 10.0)
    csv_path = block["tmp"] / "obs.csv"
    assert panel.save_csv(str(csv_path))
    good = csv_path.read_bytes()
    before = (m.measurements(), m.revision)
    # a click left of the image (the view shows a margin around it)
    panel.view.set_zoom(2.0, (0.0, 10.0))
    _click(panel.view, -3.0, 10.0)
    assert panel.last_message[0] == "warning" and "outside the image" in panel.last_message[1]
    assert (m.measurements(), m.revision) == before
    # a table naming a GCP the layer does not have, and one with an image not in the folder
    for k, row in enumerate((f"Z,{image},1,1", "A,elsewhere.png,1,1")):
        bad = block["tmp"] / f"bad{k}.csv"
        bad.write_text(f"gcp,image,x,y\n{row}\n")
        assert not panel.load_table(str(bad))
        assert panel.last_message[0] == "critical"
        assert (
            "unknown GCP 'Z'" if k == 0 else "'elsewhere.png' is not in the image folder"
        ) in panel.last_message[1]
        assert "line 2" in panel.last_message[1]
    assert (m.measurements(), m.revision) == before
    # a failed save (the target is a folder) keeps the saved table intact
    assert not panel.save_csv(str(block["tmp"]))
    assert csv_path.read_bytes() == good
    # nothing loaded: a clear message, no crash
    from truortho.truortho_plugin.gcp_panel import GcpPanel

    empty = GcpPanel()
    assert not empty.place_at(1.0, 1.0) and "Load the images" in empty.last_message[1]
    empty.folder_edit.setText(str(block["tmp"] / "missing"))
    empty.layer_combo.setLayer(block["layer"])
    assert not empty.load() and "is not a folder" in empty.last_message[1]
    empty.deleteLater()


def test_prediction_opens_images_at_the_gcp(panel, block):
    """With an orientation, every image that sees a GCP is marked predicted and opens centred on the
    projection (core.geometry.camera); Page Down walks through exactly those images."""
    from qgis.PyQt.QtCore import QPointF, Qt
    from qgis.PyQt.QtTest import QTest

    from truortho.core.geometry.camera import project_points

    panel.orientation_edit.setText(str(block["path"]))
    assert panel.load(), panel.last_message
    m, o = panel.model, block["orientation"]
    cam = next(iter(o.cameras.values()))
    g = m.gcp("A")
    X = np.array([g.xyz]) - OFFSET
    seen = []
    for im in o.images:
        uv = project_points(X, im.R, im.C, cam)[0]
        if -0.5 <= uv[0] <= 159.5 and -0.5 <= uv[1] <= 119.5:
            seen.append((im.name, uv))
    assert len(seen) >= 2
    assert m.images_of("A") == [n for n, _ in seen]
    panel.select("A", seen[0][0])
    for k, (name, uv) in enumerate(seen):
        if k:
            QTest.keyClick(panel.view, Qt.Key_PageDown)
        assert panel.current_image == name
        r, c = panel.cell_of("A", name)
        assert panel.table.item(r, c).text() == "○"
        assert panel.view.zoom() >= 2.0
        centre = panel.view.mapToScene(panel.view.viewport().rect().center())
        assert abs(centre.x() - uv[0]) < 1.0 and abs(centre.y() - uv[1]) < 1.0
        pred = [mk for mk in panel.view.markers() if mk.kind == "predicted"]
        assert len(pred) == 1 and (pred[0].pos() - QPointF(*uv)).manhattanLength() < 1e-9
    # accept the prediction with a click on it: measured, at the clicked pixel
    name, uv = seen[0]
    panel.select("A", name)
    _click(panel.view, *uv)
    got = m.get("A", name)
    assert abs(got.x - uv[0]) <= 0.5 and abs(got.y - uv[1]) <= 0.5


def test_table_layer_follows_the_measurements(panel, block):
    from qgis.core import QgsProject

    assert panel.load()
    m = panel.model
    layer = panel.add_table_layer()
    assert QgsProject.instance().mapLayer(layer.id()) is layer
    assert [f.name() for f in layer.fields()] == ["gcp", "image", "x", "y", "sigma_x", "sigma_y", "source"]
    panel.select("C", m.photos[2].name)
    assert panel.place_at(12.5, 7.25)
    rows = [f.attributes() for f in layer.getFeatures()]
    assert len(rows) == 1 and rows[0][:4] == ["C", m.photos[2].name, 12.5, 7.25] and rows[0][6] == "manual"
    assert panel.add_table_layer() is layer  # one layer, not a second one
    assert panel.undo()
    assert layer.featureCount() == 0
    # the table layer is what the Processing algorithms read
    from truortho.processing.layers import read_gcp_layer, read_observation_table

    panel.redo()
    gcps = read_gcp_layer(block["layer"], None, QgsProject.instance().transformContext())
    read_observation_table(layer, gcps, {p.name for p in m.photos})
    assert [g.observations for g in gcps if g.name == "C"] == [[(m.photos[2].name, 12.5, 7.25)]]
    # once a table is saved, the layer is that CSV file (stored with the project), rewritten as one measures
    csv_path = block["tmp"] / "kept.csv"
    assert panel.save_csv(str(csv_path))
    memory_id = layer.id()
    kept = panel.add_table_layer()
    assert kept.providerType() == "ogr" and QgsProject.instance().mapLayer(memory_id) is None  # replaced
    panel.select("A", m.photos[0].name)
    assert panel.place_at(3.125, 4.5)
    assert "A," + m.photos[0].name + ",3.125,4.5" in csv_path.read_text()
    gcps = read_gcp_layer(block["layer"], None, QgsProject.instance().transformContext())
    read_observation_table(kept, gcps, {p.name for p in m.photos})
    obs = {g.name: g.observations for g in gcps}
    assert obs["A"] == [(m.photos[0].name, 3.125, 4.5)] and obs["C"] == [(m.photos[2].name, 12.5, 7.25)]
    assert panel.undo() and kept.featureCount() == 1 and "3.125" not in csv_path.read_text()


def test_plugin_action_shows_the_dock(qgis_iface, truortho_plugin):
    truortho_plugin.iface = qgis_iface
    truortho_plugin.initGui()
    try:
        action = truortho_plugin.gcp_action
        assert action is not None and action.isCheckable()
        action.trigger()
        dock = truortho_plugin.gcp_panel
        assert dock is not None and not dock.isHidden()  # (the mock main window itself is hidden)
        action.trigger()
        assert dock.isHidden() and not action.isChecked()
    finally:
        truortho_plugin.unload_gui()
        truortho_plugin.iface = None
    assert truortho_plugin.gcp_panel is None and truortho_plugin.gcp_action is None


def test_refine_button_measures_the_other_images(tmp_path, qgis_processing_ready):
    """Refine (MGCM of core/gcp/lsm) from one measurement on four rendered photos of a textured plane:
    the other three images get 'refined' measurements within 0.15 px of the truth; one undo removes them."""
    import cv2
    from qgis.core import QgsFeature, QgsGeometry, QgsPoint, QgsProject, QgsVectorLayer
    from qgis.PyQt.QtCore import Qt
    from qgis.PyQt.QtTest import QTest

    from truortho.core.geometry.camera import project_points
    from truortho.core.geometry.frame import LocalFrame
    from truortho.core.orientation import Image, Orientation
    from truortho.core.synthetic import make_camera
    from truortho.core.synthetic.cameras import look_at_rotation, nadir_rotation
    from truortho.core.synthetic.targets import render_on_plane
    from truortho.truortho_plugin.gcp_panel import GcpPanel

    rng = np.random.default_rng(8)
    cam = make_camera(320, 240, 400.0, distortion=(-0.05, 0.01, 0, 0, 0))
    tex = cv2.GaussianBlur(rng.uniform(0, 1, (400, 400)), (0, 0), 10.0)
    tex = (tex - tex.min()) / (tex.max() - tex.min())
    Xt = np.array([0.5, 0.8, 0.0])
    folder = tmp_path / "photos"
    folder.mkdir()
    images = []
    for i, C in enumerate([[0, 0, 30], [7, 3, 29], [-5, 6, 31], [2, -8, 30]]):
        C = np.array(C, float)
        R = nadir_rotation(-30.0) if i == 0 else look_at_rotation(C, Xt)
        img = render_on_plane(tex, 0.01, (0.0, 0.0), 0.0, R, C, cam) * 220 + 15
        cv2.imwrite(str(folder / f"p{i}.png"), np.clip(np.round(img), 0, 255).astype(np.uint8))
        images.append(Image(f"p{i}.png", cam.id, R, C))
    o = Orientation(LocalFrame(CRS, OFFSET), {cam.id: cam}, images, image_root=str(folder))
    o.save(tmp_path / "orientation.json")
    truth = {im.name: project_points(Xt[None], im.R, im.C, cam)[0] for im in images}
    layer = QgsVectorLayer(f"PointZ?crs={CRS}&field=name:string", "gcps", "memory")
    f = QgsFeature(layer.fields())
    f.setAttributes(["T"])
    f.setGeometry(QgsGeometry(QgsPoint(*(Xt + OFFSET + [0.2, 0.1, 0.5]))))  # surveyed a little off
    layer.dataProvider().addFeatures([f])
    QgsProject.instance().addMapLayer(layer)
    panel = GcpPanel()
    try:
        panel.folder_edit.setText(str(folder))
        panel.layer_combo.setLayer(layer)
        panel.orientation_edit.setText(str(tmp_path / "orientation.json"))
        assert panel.load(), panel.last_message
        assert panel.model.images_of("T") == ["p0.png", "p1.png", "p2.png", "p3.png"]
        panel.select("T", "p0.png")
        assert panel.place_at(*truth["p0.png"])
        assert panel.refine_button.isEnabled()
        QTest.mouseClick(panel.refine_button, Qt.LeftButton)
        assert panel.last_message[0] == "success", panel.last_message
        for name in ("p1.png", "p2.png", "p3.png"):
            got = panel.model.get("T", name)
            assert got.source == "refined"
            assert np.hypot(got.x - truth[name][0], got.y - truth[name][1]) < 0.15
            r, c = panel.cell_of("T", name)
            assert panel.table.item(r, c).text() == "●"
        assert panel.undo() and len(panel.model) == 1
    finally:
        panel.deleteLater()
        QgsProject.instance().removeAllMapLayers()
