"""An image viewer for measuring points: pan (drag), zoom (wheel), click to place, crosshair markers.

Scene coordinates are TruOrtho pixel coordinates (:mod:`truortho.core.geometry`): the pixmap is
drawn with its top-left *corner* at (-0.5, -0.5), so the centre of the top-left pixel is (0, 0)
and ``mapToScene`` of a click gives the measurement directly.
"""

from __future__ import annotations

from qgis.PyQt.QtCore import QPointF, QRectF, Qt, pyqtSignal
from qgis.PyQt.QtGui import QBrush, QColor, QImageReader, QPainter, QPainterPath, QPen, QPixmap
from qgis.PyQt.QtWidgets import (
    QGraphicsItem,
    QGraphicsPathItem,
    QGraphicsPixmapItem,
    QGraphicsScene,
    QGraphicsSimpleTextItem,
    QGraphicsView,
)

#: Marker colours: a measurement, a prediction, the current GCP's measurement.
MEASURED_COLOUR = QColor(0, 230, 60)
PREDICTED_COLOUR = QColor(255, 0, 255)
CURRENT_COLOUR = QColor(255, 230, 0)
#: A press that moves less than this many screen pixels before release is a click, not a pan.
CLICK_TOLERANCE = 4


def load_pixmap(path: str) -> QPixmap:
    """The image as stored (the EXIF orientation tag is *not* applied, as everywhere in TruOrtho)."""
    reader = QImageReader(path)
    reader.setAutoTransform(False)
    image = reader.read()
    if image.isNull():
        return QPixmap()
    return QPixmap.fromImage(image)


def _marker_path(kind: str) -> QPainterPath:
    path = QPainterPath()
    if kind == "predicted":
        path.addEllipse(QPointF(0, 0), 9, 9)
        path.moveTo(-14, 0)
        path.lineTo(-5, 0)
        path.moveTo(5, 0)
        path.lineTo(14, 0)
        path.moveTo(0, -14)
        path.lineTo(0, -5)
        path.moveTo(0, 5)
        path.lineTo(0, 14)
    else:  # a crosshair with an open centre
        for a, b in (((-16, 0), (-3, 0)), ((3, 0), (16, 0)), ((0, -16), (0, -3)), ((0, 3), (0, 16))):
            path.moveTo(*a)
            path.lineTo(*b)
    return path


class Marker(QGraphicsPathItem):
    """A constant-size (screen pixels) marker at a scene point, with a label."""

    def __init__(self, x: float, y: float, kind: str, colour: QColor, label: str = "") -> None:
        super().__init__(_marker_path(kind))
        self.kind = kind
        pen = QPen(colour, 2 if kind != "predicted" else 1.5)
        pen.setCosmetic(True)
        self.setPen(pen)
        self.setPos(QPointF(x, y))
        self.setFlag(QGraphicsItem.ItemIgnoresTransformations, True)
        self.setZValue(10 if kind != "predicted" else 5)
        if label:
            text = QGraphicsSimpleTextItem(label, self)
            text.setBrush(QBrush(colour))
            text.setPos(10, 8)


class ImageView(QGraphicsView):
    """Shows one image; left click (without dragging) emits :attr:`pixelClicked` in pixels.

    Drag with the left or middle button pans, the wheel zooms about the cursor.
    """

    #: x, y in TruOrtho pixel coordinates (scene coordinates).
    pixelClicked = pyqtSignal(float, float)
    #: The view's zoom changed (screen pixels per image pixel).
    zoomChanged = pyqtSignal(float)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self.setRenderHint(QPainter.SmoothPixmapTransform, False)
        self.setTransformationAnchor(QGraphicsView.AnchorUnderMouse)
        self.setResizeAnchor(QGraphicsView.AnchorViewCenter)
        self.setDragMode(QGraphicsView.NoDrag)
        self.setBackgroundBrush(QBrush(QColor(40, 40, 40)))
        self.setMouseTracking(True)
        self._pixmap_item: QGraphicsPixmapItem | None = None
        self._markers: list[Marker] = []
        self._press = None
        self._panning = False
        self.image_size: tuple[int, int] | None = None
        self.path: str | None = None

    # ------------------------------------------------------------ content
    def set_image(self, path: str | None) -> bool:
        """Show the image file ``path`` (None clears); False when it cannot be read."""
        self.clear_markers()
        if self._pixmap_item is not None:
            self.scene().removeItem(self._pixmap_item)
            self._pixmap_item = None
        self.image_size = None
        self.path = path
        if not path:
            return True
        pix = load_pixmap(path)
        if pix.isNull():
            return False
        self._pixmap_item = self.scene().addPixmap(pix)
        self._pixmap_item.setOffset(-0.5, -0.5)
        self._pixmap_item.setTransformationMode(Qt.FastTransformation)
        self.image_size = (pix.width(), pix.height())
        self._update_scene_rect()
        return True

    def _update_scene_rect(self) -> None:
        """The image plus a margin of half the viewport, so that any pixel can be centred."""
        if self.image_size is None:
            return
        w, h = self.image_size
        zoom = max(self.zoom(), 1e-3)
        vp = self.viewport().size()
        margin = max(0.05 * max(w, h), 0.5 * max(vp.width(), vp.height()) / zoom)
        self.setSceneRect(QRectF(-0.5, -0.5, w, h).adjusted(-margin, -margin, margin, margin))

    def clear_markers(self) -> None:
        for m in self._markers:
            self.scene().removeItem(m)
        self._markers = []

    def add_marker(self, x: float, y: float, kind: str, label: str = "", current: bool = False) -> Marker:
        """A marker at pixel ``(x, y)``: ``kind`` is ``measured`` or ``predicted``."""
        colour = PREDICTED_COLOUR if kind == "predicted" else (CURRENT_COLOUR if current else MEASURED_COLOUR)
        m = Marker(x, y, kind, colour, label)
        self.scene().addItem(m)
        self._markers.append(m)
        return m

    def markers(self) -> list[Marker]:
        return list(self._markers)

    # ------------------------------------------------------------ zoom
    def zoom(self) -> float:
        """Screen pixels per image pixel."""
        return self.transform().m11()

    def set_zoom(self, factor: float, centre: tuple[float, float] | None = None) -> None:
        """Zoom to ``factor`` screen pixels per image pixel, centred on pixel ``centre`` when given."""
        factor = min(max(factor, 0.02), 64.0)
        self.resetTransform()
        self.scale(factor, factor)
        self._update_scene_rect()
        if centre is not None:
            self.centerOn(QPointF(*centre))
        self.zoomChanged.emit(factor)

    def fit(self) -> None:
        """The whole image in the view."""
        if self.image_size is None:
            return
        w, h = self.image_size
        self.fitInView(QRectF(-0.5, -0.5, w, h), Qt.KeepAspectRatio)
        self._update_scene_rect()
        self.centerOn(QPointF((w - 1) / 2, (h - 1) / 2))
        self.zoomChanged.emit(self.zoom())

    def wheelEvent(self, event) -> None:  # noqa: N802 - Qt API
        steps = event.angleDelta().y() / 120.0
        if steps == 0 or self.image_size is None:
            return
        factor = 1.25**steps
        new = self.zoom() * factor
        if not 0.02 <= new <= 64.0:
            return
        self.scale(factor, factor)
        self._update_scene_rect()
        self.zoomChanged.emit(self.zoom())
        event.accept()

    def resizeEvent(self, event) -> None:  # noqa: N802 - Qt API
        super().resizeEvent(event)
        self._update_scene_rect()

    # ------------------------------------------------------------ mouse
    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        if event.button() in (Qt.LeftButton, Qt.MiddleButton):
            self._press = (event.pos(), event.button())
            self._last = event.pos()
            self._panning = event.button() == Qt.MiddleButton
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._press is not None:
            if not self._panning and (event.pos() - self._press[0]).manhattanLength() > CLICK_TOLERANCE:
                self._panning = True
                self.viewport().setCursor(Qt.ClosedHandCursor)
            if self._panning:
                d = event.pos() - self._last
                self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() - d.x())
                self.verticalScrollBar().setValue(self.verticalScrollBar().value() - d.y())
            self._last = event.pos()
            event.accept()
            return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._press is not None and event.button() == self._press[1]:
            moved = (event.pos() - self._press[0]).manhattanLength() > CLICK_TOLERANCE
            was_click = not (self._panning or moved) and event.button() == Qt.LeftButton
            self._press = None
            self._panning = False
            self.viewport().unsetCursor()
            if was_click and self.image_size is not None:
                p = self.mapToScene(event.pos())
                self.pixelClicked.emit(p.x(), p.y())
            event.accept()
            return
        super().mouseReleaseEvent(event)
