"""The GCP measurement panel (issue 19): a dock to measure ground control points in photos.

Choose an image folder, a GCP point layer and (optionally) an orientation; the table shows every
GCP x image with the state of its measurement; the image view places or moves the current GCP's
measurement where it is clicked. With an orientation, each GCP is predicted in the images that see
it and every image opens at the predicted spot. Measurements are saved as the observation table
the Processing algorithms read (CSV ``gcp,image,x,y,sigma_x,sigma_y,source``) or as ODM
``gcp_list.txt``, and kept in the project as a table layer. The logic is
:class:`truortho.core.gcp.measurements.MeasurementSet` (QGIS-free); this module is the Qt glue.
"""

from __future__ import annotations

import os

from qgis.core import (
    Qgis,
    QgsFeature,
    QgsMapLayerProxyModel,
    QgsProject,
    QgsVectorLayer,
)
from qgis.gui import QgsMapLayerComboBox, QgsMessageBar
from qgis.PyQt.QtCore import QEvent, QObject, Qt
from qgis.PyQt.QtGui import QBrush, QColor
from qgis.PyQt.QtWidgets import (
    QAbstractItemView,
    QDockWidget,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from ..core.errors import TruOrthoError
from ..core.gcp.measurements import MEASURED, PREDICTED, GroundPoint, MeasurementSet, list_images
from ..processing.i18n import tr
from .image_view import ImageView

#: Cell colours of the GCP x image table.
STATE_COLOURS = {MEASURED: QColor(120, 220, 120), PREDICTED: QColor(240, 190, 240)}
STATE_TEXT = {MEASURED: "●", PREDICTED: "○"}
#: Zoom (screen pixels per image pixel) at which an image opens on a measured or predicted point.
DETAIL_ZOOM = 2.0
LAYER_FIELDS = (
    ("gcp", "string"),
    ("image", "string"),
    ("x", "double"),
    ("y", "double"),
    ("sigma_x", "double"),
    ("sigma_y", "double"),
    ("source", "string"),
)


class _Keys(QObject):
    """Keyboard shortcuts of the panel, handled on its own widgets (QGIS's Ctrl+Z stays QGIS's
    elsewhere): claims the keys at ShortcutOverride so no window shortcut steals them."""

    def __init__(self, panel: GcpPanel) -> None:
        super().__init__(panel)
        self.panel = panel

    def _action(self, event):
        key, mods = event.key(), event.modifiers() & ~Qt.KeypadModifier
        ctrl = mods & Qt.ControlModifier
        shift = mods & Qt.ShiftModifier
        p = self.panel
        if ctrl and key == Qt.Key_Z:
            return p.redo if shift else p.undo
        if ctrl and key == Qt.Key_Y:
            return p.redo
        if key == Qt.Key_PageDown:
            return (lambda: p.next_gcp(1)) if ctrl else (lambda: p.next_image(1))
        if key == Qt.Key_PageUp:
            return (lambda: p.next_gcp(-1)) if ctrl else (lambda: p.next_image(-1))
        if not mods and key in (Qt.Key_Delete, Qt.Key_Backspace):
            return p.delete_current
        if not mods and key == Qt.Key_F:
            return p.view.fit
        return None

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt API
        if event.type() == QEvent.ShortcutOverride and self._action(event) is not None:
            event.accept()
            return True
        if event.type() == QEvent.KeyPress:
            action = self._action(event)
            if action is not None:
                action()
                return True
        return False


class GcpPanel(QDockWidget):
    """Dock widget to measure GCPs in photos (see the module docstring)."""

    def __init__(self, iface=None, parent=None) -> None:
        super().__init__(tr("GCP measurements"), parent)
        self.setObjectName("TruOrthoGcpPanel")
        self.iface = iface
        self.model: MeasurementSet | None = None
        self.orientation = None
        self.folder: str | None = None
        self.current_gcp: str | None = None
        self.current_image: str | None = None
        self.last_message: tuple[str, str] | None = None
        self.table_layer: QgsVectorLayer | None = None
        #: The last observation table saved (CSV): the file behind the table layer when there is one.
        self.csv_path: str | None = None
        self._layer_csv: str | None = None
        self._build()

    # ------------------------------------------------------------ widgets
    def _button(self, text: str, tip: str, slot) -> QToolButton:
        b = QToolButton()
        b.setText(text)
        b.setToolTip(tip)
        b.setToolButtonStyle(Qt.ToolButtonTextOnly)
        b.clicked.connect(lambda _checked=False: slot())
        return b

    def _build(self) -> None:
        body = QWidget()
        lay = QVBoxLayout(body)
        lay.setContentsMargins(4, 4, 4, 4)
        self.message_bar = QgsMessageBar()
        lay.addWidget(self.message_bar)

        form = QFormLayout()
        self.folder_edit = QLineEdit()
        self.folder_edit.setPlaceholderText(tr("Folder of the photos"))
        row = QHBoxLayout()
        row.addWidget(self.folder_edit)
        row.addWidget(self._button("…", tr("Choose the image folder"), self._browse_folder))
        form.addRow(tr("Images"), row)
        self.layer_combo = QgsMapLayerComboBox()
        self.layer_combo.setFilters(QgsMapLayerProxyModel.PointLayer)
        self.layer_combo.setAllowEmptyLayer(True)
        form.addRow(tr("GCP layer"), self.layer_combo)
        self.orientation_edit = QLineEdit()
        self.orientation_edit.setPlaceholderText(
            tr("Optional: orientation to predict the GCPs in the images")
        )
        row = QHBoxLayout()
        row.addWidget(self.orientation_edit)
        row.addWidget(self._button("…", tr("Choose an orientation file"), self._browse_orientation))
        form.addRow(tr("Orientation"), row)
        lay.addLayout(form)

        row = QHBoxLayout()
        self.load_button = self._button(
            tr("Load"), tr("Read the images, the GCPs and the orientation"), self.load
        )
        row.addWidget(self.load_button)
        row.addStretch(1)
        self.undo_button = self._button(tr("Undo"), tr("Undo (Ctrl+Z)"), self.undo)
        self.redo_button = self._button(tr("Redo"), tr("Redo (Ctrl+Shift+Z)"), self.redo)
        self.delete_button = self._button(
            tr("Delete"),
            tr("Delete the measurement of the current GCP in this image (Del)"),
            self.delete_current,
        )
        self.refine_button = self._button(
            tr("Refine"),
            tr("Measure the current GCP in its other images by least-squares matching from this image's "
               "measurement (needs an orientation)"),
            self.refine_current,
        )  # fmt: skip
        for b in (self.refine_button, self.undo_button, self.redo_button, self.delete_button):
            row.addWidget(b)
        lay.addLayout(row)

        split = QSplitter(Qt.Vertical)
        self.table = QTableWidget()
        self.table.setEditTriggers(QAbstractItemView.NoEditTriggers)
        self.table.setSelectionMode(QAbstractItemView.SingleSelection)
        self.table.cellClicked.connect(self._cell_clicked)
        self.table.currentCellChanged.connect(lambda r, c, _r, _c: self._cell_clicked(r, c))
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeToContents)
        split.addWidget(self.table)
        viewer = QWidget()
        vl = QVBoxLayout(viewer)
        vl.setContentsMargins(0, 0, 0, 0)
        nav = QHBoxLayout()
        nav.addWidget(self._button("◀", tr("Previous image (Page Up)"), lambda: self.next_image(-1)))
        nav.addWidget(self._button("▶", tr("Next image (Page Down)"), lambda: self.next_image(1)))
        nav.addWidget(self._button("▲", tr("Previous GCP (Ctrl+Page Up)"), lambda: self.next_gcp(-1)))
        nav.addWidget(self._button("▼", tr("Next GCP (Ctrl+Page Down)"), lambda: self.next_gcp(1)))
        nav.addWidget(self._button(tr("Fit"), tr("Show the whole image (F)"), lambda: self.view.fit()))
        self.status = QLabel()
        nav.addWidget(self.status, 1)
        vl.addLayout(nav)
        self.view = ImageView()
        self.view.setToolTip(tr("Click: place the current GCP; drag: pan; wheel: zoom"))
        self.view.pixelClicked.connect(self.place_at)
        self.view.zoomChanged.connect(lambda _z: self._update_status())
        vl.addWidget(self.view, 1)
        split.addWidget(viewer)
        split.setStretchFactor(1, 3)
        lay.addWidget(split, 1)

        row = QHBoxLayout()
        tip = tr("Load measurements from a CSV table or gcp_list.txt")
        row.addWidget(self._button(tr("Open table…"), tip, self._browse_load))
        row.addWidget(
            self._button(tr("Save table…"), tr("Save the observation table (CSV)"), self._browse_save_csv)
        )
        row.addWidget(
            self._button(tr("Save gcp_list…"), tr("Save as ODM gcp_list.txt"), self._browse_save_list)
        )
        row.addWidget(
            self._button(tr("Add table layer"),
                         tr("Keep the measurements as a table layer in the project: the saved CSV table, "
                            "rewritten as you measure (a temporary layer until a table is saved)"),
                         self.add_table_layer)
        )  # fmt: skip
        row.addStretch(1)
        lay.addLayout(row)
        self.setWidget(body)

        self._keys = _Keys(self)
        for w in (self, body, self.table, self.view, self.view.viewport()):
            w.installEventFilter(self._keys)
        self._update_buttons()

    # ------------------------------------------------------------ messages
    def show_message(self, text: str, level=Qgis.Warning) -> None:
        """Show ``text`` in the panel's message bar (kept in :attr:`last_message`)."""
        names = {
            Qgis.Info: "info",
            Qgis.Warning: "warning",
            Qgis.Critical: "critical",
            Qgis.Success: "success",
        }
        self.last_message = (names.get(level, "info"), text)
        self.message_bar.clearWidgets()
        self.message_bar.pushMessage(tr("GCP measurements"), text, level, 8)

    # ------------------------------------------------------------ loading
    def _browse_folder(self) -> None:
        d = QFileDialog.getExistingDirectory(self, tr("Image folder"), self.folder_edit.text())
        if d:
            self.folder_edit.setText(d)

    def _browse_orientation(self) -> None:
        f, _ = QFileDialog.getOpenFileName(
            self, tr("Orientation"), self.orientation_edit.text(),
            tr("Orientations (*.json *.txt);;All files (*)"),
        )  # fmt: skip
        if f:
            self.orientation_edit.setText(f)

    def gcp_points(self, layer) -> list[GroundPoint]:
        """The GCPs of a point layer (names, coordinates and heights as the algorithms read them)."""
        from ..processing.layers import crs_text, read_gcp_layer

        crs = crs_text(layer.crs()) if layer.crs().isValid() else None
        records = read_gcp_layer(layer, None, QgsProject.instance().transformContext())
        return [GroundPoint(g.name, tuple(g.xyz), crs, g.role == "check") for g in records]

    def load(self) -> bool:
        """Read the folder, the GCP layer and the orientation; False (with a message) on bad input.

        Measurements of GCPs and images that still exist are kept (an undoable change).
        """
        from qgis.core import QgsProcessingException

        folder = self.folder_edit.text().strip()
        layer = self.layer_combo.currentLayer()
        if not folder:
            self.show_message(tr("Choose the folder of the photos first."))
            return False
        if layer is None:
            self.show_message(tr("Choose a GCP point layer first (fields: name, optional role and z)."))
            return False
        try:
            photos = list_images(folder)
            gcps = self.gcp_points(layer)
            if not gcps:
                raise QgsProcessingException(tr("GCP layer {!r} has no point").format(layer.name()))
            orientation = None
            opath = self.orientation_edit.text().strip()
            if opath:
                from ..core.exchange import read_orientation

                orientation = read_orientation(opath)
            model = MeasurementSet(gcps, photos)
            n_pred = model.predict_from(orientation) if orientation is not None else 0
        except (TruOrthoError, QgsProcessingException, OSError) as err:
            self.show_message(str(err), Qgis.Critical)
            return False
        if self.model is not None:
            keep = [m for m in self.model.measurements() if m.gcp in {g.name for g in gcps}
                    and m.image in {p.name for p in photos}]  # fmt: skip
            model.replace_all(keep, "reload")
            model.clear_history()  # an undo must not empty the table just reloaded
        self.model, self.orientation, self.folder = model, orientation, folder
        self._fill_table()
        text = tr("{} GCPs, {} images").format(len(gcps), len(photos))
        if orientation is not None:
            text += tr("; {} predicted positions").format(n_pred)
        self.show_message(text, Qgis.Info)
        first = model.gcps[0].name
        images = model.images_of(first)
        self.select(first, images[0] if images else photos[0].name)
        return True

    # ------------------------------------------------------------ table
    def _fill_table(self) -> None:
        m = self.model
        assert m is not None
        self.table.blockSignals(True)
        self.table.clear()
        self.table.setRowCount(len(m.gcps))
        self.table.setColumnCount(len(m.photos))
        self.table.setVerticalHeaderLabels([g.name + (" ✓" if g.check else "") for g in m.gcps])
        self.table.setHorizontalHeaderLabels([os.path.splitext(p.name)[0] for p in m.photos])
        for c, p in enumerate(m.photos):
            self.table.horizontalHeaderItem(c).setToolTip(p.name)
        for r, g in enumerate(m.gcps):
            self.table.verticalHeaderItem(r).setToolTip(
                tr("{}: X {:.3f}, Y {:.3f}, Z {:.3f}{}").format(
                    g.name, *g.xyz, tr(" (check point)") if g.check else ""
                )
            )
            for c in range(len(m.photos)):
                item = QTableWidgetItem()
                item.setTextAlignment(Qt.AlignCenter)
                self.table.setItem(r, c, item)
        self.table.blockSignals(False)
        self._refresh_table()

    def _refresh_table(self) -> None:
        m = self.model
        if m is None:
            return
        for r, g in enumerate(m.gcps):
            for c, p in enumerate(m.photos):
                item = self.table.item(r, c)
                state = m.state(g.name, p.name)
                item.setText(STATE_TEXT.get(state, ""))
                colour = STATE_COLOURS.get(state)
                item.setBackground(QBrush(colour) if colour is not None else QBrush())
                meas = m.get(g.name, p.name)
                item.setToolTip(
                    f"{g.name} / {p.name}: "
                    + (f"x {meas.x:.2f}, y {meas.y:.2f} ({meas.source})" if meas else self._state_name(state))
                )

    @staticmethod
    def _state_name(state: str) -> str:
        return tr("predicted") if state == PREDICTED else tr("not measured")

    def cell_of(self, gcp: str, image: str) -> tuple[int, int]:
        assert self.model is not None
        return (
            [g.name for g in self.model.gcps].index(gcp),
            [p.name for p in self.model.photos].index(image),
        )

    def _cell_clicked(self, row: int, col: int) -> None:
        if self.model is None or row < 0 or col < 0:
            return
        g, p = self.model.gcps[row].name, self.model.photos[col].name
        if (g, p) != (self.current_gcp, self.current_image):
            self.select(g, p)

    # ------------------------------------------------------------ navigation
    def select(self, gcp: str, image: str) -> None:
        """Make ``gcp`` on ``image`` current: open the image at its measurement or prediction."""
        m = self.model
        if m is None:
            return
        try:
            m.gcp(gcp)
            photo = m.photo(image)
        except TruOrthoError as err:
            self.show_message(str(err))
            return
        self.current_gcp = gcp
        if image != self.current_image or self.view.path != photo.path:
            self.current_image = image
            if not self.view.set_image(photo.path):
                self.show_message(tr("Cannot read the image {}").format(photo.path), Qgis.Critical)
                return
            self.view.fit()
        self._draw_markers()
        target = m.get(gcp, image) or m.prediction(gcp, image)
        if target is not None:
            self.view.set_zoom(max(self.view.zoom(), DETAIL_ZOOM), (target.x, target.y))
        r, c = self.cell_of(gcp, image)
        self.table.blockSignals(True)
        self.table.setCurrentCell(r, c)
        self.table.blockSignals(False)
        self._update_status()
        self._update_buttons()

    def next_image(self, step: int = 1) -> None:
        """The next (``step`` = -1: previous) image of the current GCP: among those where it is
        measured or predicted when there are any, else among all."""
        m = self.model
        if m is None or self.current_gcp is None:
            return
        names = m.images_of(self.current_gcp) or [p.name for p in m.photos]
        if self.current_image in names:
            k = (names.index(self.current_image) + step) % len(names)
        else:
            order = [p.name for p in m.photos]
            pos = order.index(self.current_image) if self.current_image in order else -1
            after = (
                [n for n in names if order.index(n) > pos]
                if step > 0
                else [n for n in names if order.index(n) < pos]
            )
            k = (
                names.index(after[0] if step > 0 else after[-1])
                if after
                else (0 if step > 0 else len(names) - 1)
            )
        self.select(self.current_gcp, names[k])

    def next_gcp(self, step: int = 1) -> None:
        """The next (previous) GCP, on the current image when it sees it, else on its first image."""
        m = self.model
        if m is None:
            return
        names = [g.name for g in m.gcps]
        k = (names.index(self.current_gcp) + step) % len(names) if self.current_gcp in names else 0
        g = names[k]
        images = m.images_of(g)
        if self.current_image is not None and (not images or self.current_image in images):
            image = self.current_image
        else:
            image = images[0]
        self.select(g, image)

    # ------------------------------------------------------------ editing
    def place_at(self, x: float, y: float) -> bool:
        """Place (or move) the current GCP's measurement on the current image at pixel ``(x, y)``."""
        m = self.model
        if m is None or self.current_gcp is None or self.current_image is None:
            self.show_message(tr("Load the images and the GCPs first."))
            return False
        try:
            m.place(self.current_gcp, self.current_image, x, y)
        except TruOrthoError as err:
            self.show_message(str(err))
            return False
        self._changed()
        return True

    def delete_current(self) -> bool:
        m = self.model
        if m is None or self.current_gcp is None or self.current_image is None:
            return False
        done = m.delete(self.current_gcp, self.current_image)
        if done:
            self._changed()
        return done

    def refine_current(self) -> bool:
        """Refine: the current GCP in its other images by MGCM from the measurement on the current image."""
        from ..core.gcp.measurements import refine_gcp

        m = self.model
        if m is None or self.current_gcp is None or self.current_image is None:
            self.show_message(tr("Load the images and the GCPs first."))
            return False
        if self.orientation is None:
            self.show_message(tr("Refining needs an orientation: choose one and load again."))
            return False
        try:
            report = refine_gcp(m, self.orientation, self.current_gcp, self.current_image)
        except (TruOrthoError, OSError) as err:
            self.show_message(str(err))
            return False
        if not report:
            self.show_message(tr("Refinement failed: {}").format(report.reason or tr("no image matched")))
            return False
        self._changed()
        text = tr("{} refined in {} images").format(self.current_gcp, len(report.refined))
        if report.failed:
            text += tr("; not in {}").format(", ".join(f"{k} ({v})" for k, v in report.failed.items()))
        self.show_message(text, Qgis.Success if not report.failed else Qgis.Warning)
        return True

    def undo(self) -> bool:
        if self.model is None or not self.model.undo():
            return False
        self._changed()
        return True

    def redo(self) -> bool:
        if self.model is None or not self.model.redo():
            return False
        self._changed()
        return True

    def _changed(self) -> None:
        self._refresh_table()
        self._draw_markers()
        self._update_status()
        self._update_buttons()
        self._sync_layer()

    def _draw_markers(self) -> None:
        m = self.model
        self.view.clear_markers()
        if m is None or self.current_image is None:
            return
        pred = m.prediction(self.current_gcp, self.current_image) if self.current_gcp else None
        if pred is not None:
            self.view.add_marker(pred.x, pred.y, "predicted", self.current_gcp or "")
        for meas in m.measurements():
            if meas.image == self.current_image:
                self.view.add_marker(
                    meas.x, meas.y, "measured", meas.gcp, current=meas.gcp == self.current_gcp
                )

    def _update_status(self) -> None:
        m = self.model
        if m is None or self.current_gcp is None:
            self.status.setText("")
            return
        done, predicted = m.counts(self.current_gcp)
        meas = m.get(self.current_gcp, self.current_image or "")
        where = f"x {meas.x:.2f}, y {meas.y:.2f}" if meas else tr("not measured")
        self.status.setText(
            tr("{} on {}: {} — {} measured, {} to do — zoom {:.2f}").format(
                self.current_gcp, self.current_image, where, done, predicted, self.view.zoom()
            )
        )

    def _update_buttons(self) -> None:
        m = self.model
        self.refine_button.setEnabled(bool(m and self.orientation is not None))
        self.undo_button.setEnabled(bool(m and m.can_undo))
        self.redo_button.setEnabled(bool(m and m.can_redo))
        self.undo_button.setToolTip(tr("Undo (Ctrl+Z)") + (f": {m.undo_label()}" if m and m.can_undo else ""))
        self.redo_button.setToolTip(
            tr("Redo (Ctrl+Shift+Z)") + (f": {m.redo_label()}" if m and m.can_redo else "")
        )

    # ------------------------------------------------------------ files
    def _browse_save_csv(self) -> None:
        f, _ = QFileDialog.getSaveFileName(
            self, tr("Save the observation table"), self._default("gcp_observations.csv"), tr("CSV (*.csv)")
        )
        if f:
            self.save_csv(f)

    def _browse_save_list(self) -> None:
        f, _ = QFileDialog.getSaveFileName(self, tr("Save gcp_list.txt"), self._default("gcp_list.txt"),
                                           tr("gcp_list (*.txt)"))  # fmt: skip
        if f:
            self.save_gcp_list(f)

    def _browse_load(self) -> None:
        f, _ = QFileDialog.getOpenFileName(self, tr("Open measurements"), self._default(""),
                                           tr("Observation tables (*.csv *.txt)"))  # fmt: skip
        if f:
            self.load_table(f)

    def _default(self, name: str) -> str:
        return os.path.join(self.folder or os.getcwd(), name)

    def _file_op(self, what, *args) -> bool:
        if self.model is None:
            self.show_message(tr("Load the images and the GCPs first."))
            return False
        try:
            what(*args)
        except (TruOrthoError, OSError) as err:
            self.show_message(str(err), Qgis.Critical)
            return False
        return True

    def save_csv(self, path: str) -> bool:
        """Save the observation table (CSV); False with a message on failure (the old file is kept)."""
        ok = self._file_op(lambda p: self.model.save_csv(p), path)  # type: ignore[union-attr]
        if ok:
            self.csv_path = path
            self.show_message(tr("Saved {} measurements to {}").format(len(self.model), path), Qgis.Success)
        return ok

    def save_gcp_list(self, path: str) -> bool:
        """Save ODM gcp_list.txt; False with a message on failure (the old file is kept)."""
        ok = self._file_op(lambda p: self.model.save_gcp_list(p), path)  # type: ignore[union-attr]
        if ok:
            self.show_message(tr("Saved {} measurements to {}").format(len(self.model), path), Qgis.Success)
        return ok

    def load_table(self, path: str) -> bool:
        """Replace the measurements by those of a CSV table or a gcp_list.txt (undoable)."""

        def read(p: str) -> None:
            assert self.model is not None
            if p.lower().endswith(".csv"):
                self.model.load_csv(p)
            else:
                self.model.load_gcp_list(p)

        ok = self._file_op(read, path)
        if ok:
            self._changed()
            if self.current_gcp and self.current_image:
                self.select(self.current_gcp, self.current_image)
            self.show_message(tr("Loaded {} measurements from {}").format(len(self.model), path), Qgis.Info)
        return ok

    # ------------------------------------------------------------ table layer
    def add_table_layer(self) -> QgsVectorLayer | None:
        """The measurements as a table layer in the project, kept up to date by the panel.

        After *Save table…* it is the saved CSV (an ordinary file layer, stored with the project),
        which the panel rewrites (atomically) after every change; before, a memory layer.
        """
        if self.model is None:
            self.show_message(tr("Load the images and the GCPs first."))
            return None
        if self._layer_alive() and (self._layer_csv == self.csv_path or self.csv_path is None):
            return self.table_layer
        if self._layer_alive():  # a memory layer, now that a table is saved: replace it by the file
            QgsProject.instance().removeMapLayer(self.table_layer.id())  # type: ignore[union-attr]
        layer = None
        if self.csv_path:
            layer = QgsVectorLayer(self.csv_path, tr("GCP observations"), "ogr")
            if not layer.isValid():
                self.show_message(tr("Cannot open {} as a table layer").format(self.csv_path), Qgis.Critical)
                layer = None
        self._layer_csv = self.csv_path if layer is not None else None
        if layer is None:
            uri = "None?" + "&".join(f"field={n}:{t}" for n, t in LAYER_FIELDS)
            layer = QgsVectorLayer(uri, tr("GCP observations"), "memory")
        self.table_layer = layer
        self._sync_layer()
        QgsProject.instance().addMapLayer(layer)
        return layer

    def _layer_alive(self) -> bool:
        layer = self.table_layer
        if layer is None:
            return False
        try:
            return QgsProject.instance().mapLayer(layer.id()) is layer
        except RuntimeError:  # deleted on the C++ side
            self.table_layer = None
            return False

    def _sync_layer(self) -> None:
        layer, m = self.table_layer, self.model
        if layer is None or m is None:
            return
        try:
            provider = layer.dataProvider()
        except RuntimeError:
            self.table_layer = None
            return
        if self._layer_csv is not None:
            try:
                m.save_csv(self._layer_csv)
            except (TruOrthoError, OSError) as err:
                self.show_message(str(err), Qgis.Critical)
                return
            provider.reloadData()
            layer.triggerRepaint()
            return
        provider.deleteFeatures([f.id() for f in layer.getFeatures()])
        feats = []
        for meas in m.measurements():
            f = QgsFeature(layer.fields())
            f.setAttributes([meas.gcp, meas.image, meas.x, meas.y, meas.sigma_x, meas.sigma_y, meas.source])
            feats.append(f)
        provider.addFeatures(feats)
        layer.triggerRepaint()
