"""A widget that shows an image with zoom, pan, a cross-hair cursor and vector overlays.

Image coordinates follow OpenCV: the centre of the top-left pixel is (0, 0). Clicks are
reported in image pixels (floats). The wheel zooms about the cursor, the right or middle
button drags to pan, a left click picks. Overlays are drawn in image coordinates on top.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QFont, QFontMetricsF, QImage, QMouseEvent, QPainter, QPen, QWheelEvent
from PySide6.QtWidgets import QSizePolicy, QWidget


@dataclass
class Overlay:
    """Things drawn over the image, in image pixels. ``points``: (u, v, label, color);
    ``segments``: (u0, v0, u1, v1, color); ``text``: a caption at the top left."""

    points: list[tuple[float, float, str, QColor]] = field(default_factory=list)
    segments: list[tuple[float, float, float, float, QColor]] = field(default_factory=list)
    text: str = ""
    image: np.ndarray | None = None  # RGBA overlay (same size as the image), e.g. CAD edges
    image_opacity: float = 0.7
    banner: str = ""  # a warning across the bottom (what is drawn is from an earlier state)


def qimage_from_array(array: np.ndarray) -> QImage:
    """A QImage sharing nothing with ``array`` (h, w, 3 RGB or 4 RGBA, uint8)."""
    a = np.ascontiguousarray(array)
    h, w = a.shape[:2]
    fmt = QImage.Format.Format_RGBA8888 if a.shape[2] == 4 else QImage.Format.Format_RGB888
    return QImage(a.data, w, h, a.strides[0], fmt).copy()


class _Shrunk:
    """An image shrunk to the size it is drawn at, kept until the image or that size changes. A
    1280 x 960 camera frame drawn into a pane a third of its size costs Qt's smooth transform ~15 ms
    a frame; OpenCV's area resize ~1 ms."""

    def __init__(self) -> None:
        self.clear()

    def clear(self) -> None:
        self._size: tuple[int, int] | None = None
        self._image: QImage | None = None

    def get(self, array: np.ndarray, width_px: int, height_px: int) -> QImage:
        size = (max(1, width_px), max(1, height_px))
        if self._image is None or self._size != size:
            self._size, self._image = size, qimage_from_array(cv2.resize(array, size, interpolation=cv2.INTER_AREA))
        return self._image


class ImageView(QWidget):
    """Shows one image; emits ``clicked(u, v)`` in image pixels and ``hovered(u, v)``."""

    clicked = Signal(float, float)
    hovered = Signal(float, float)
    dragged = Signal(float, float)
    """While a grabbed point is dragged: where it is now (image px)."""
    drag_finished = Signal(float, float, bool)
    """A grabbed point let go: where (image px), and whether it moved at all (no: a click on it)."""

    def __init__(self, parent=None, *, placeholder: str = "no image", loupe: bool = False):
        super().__init__(parent)
        self.loupe = loupe
        self.setMouseTracking(True)
        self.setCursor(Qt.CursorShape.CrossCursor)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMinimumSize(160, 120)
        self._qimage: QImage | None = None  # the full-size image, made when first needed
        self._shrunk = _Shrunk()
        self._array: np.ndarray | None = None
        self.grabber = None
        """``grabber(u, v, radius_px) -> bool``: a left press there takes hold of a point (a drag) instead of a
        click."""
        self._grab_from: QPointF | None = None
        self._overlay_image: QImage | None = None
        self._overlay_shrunk = _Shrunk()
        self.overlay = Overlay()
        self.placeholder = placeholder
        self._zoom = 1.0  # relative to fit-to-window
        self._centre: QPointF | None = None  # image point shown at the widget centre
        self._drag_from: QPointF | None = None
        self._mouse: QPointF | None = None
        self._inset: QImage | None = None
        self._inset_label = ""

    # --- content -------------------------------------------------------------------------
    def set_image(self, array: np.ndarray | None) -> None:
        if array is not None:
            new_size = (array.shape[1], array.shape[0])
            if self._array is None or (self._array.shape[1], self._array.shape[0]) != new_size:
                self._centre = None
        self._array = array
        self._qimage = None
        self._shrunk.clear()
        self.update()

    @property
    def _image(self) -> QImage | None:
        if self._qimage is None and self._array is not None:
            self._qimage = qimage_from_array(self._array)
        return self._qimage

    @property
    def image_array(self) -> np.ndarray | None:
        return self._array

    def set_inset(self, array: np.ndarray | None, label: str = "", width_px: int = 180) -> None:
        """A small second image in the bottom-right corner (the live video while a still is held)."""
        if array is None:
            self._inset = None
        else:
            h, w = array.shape[:2]
            small = cv2.resize(array, (width_px, max(1, int(round(h * width_px / w)))), interpolation=cv2.INTER_AREA)
            self._inset = qimage_from_array(small)
        self._inset_label = label
        self.update()

    def set_overlay(self, overlay: Overlay) -> None:
        self.overlay = overlay
        self._overlay_image = None if overlay.image is None else qimage_from_array(overlay.image)
        self._overlay_shrunk.clear()
        self.update()

    def reset_view(self) -> None:
        self._zoom, self._centre = 1.0, None
        self.update()

    def set_zoom(self, zoom: float, about_image_point: QPointF | None = None) -> None:
        self._zoom = float(np.clip(zoom, 0.5, 40.0))
        if about_image_point is not None:
            self._centre = about_image_point
        self.update()

    @property
    def zoom(self) -> float:
        return self._zoom

    # --- geometry ----------------------------------------------------------------------------
    def _scale(self) -> float:
        if self._image is None:
            return 1.0
        fit = min(self.width() / self._image.width(), self.height() / self._image.height())
        return fit * self._zoom

    def _centre_point(self) -> QPointF:
        if self._centre is None and self._image is not None:
            return QPointF((self._image.width() - 1) / 2.0, (self._image.height() - 1) / 2.0)
        return self._centre or QPointF(0, 0)

    def widget_to_image(self, x: float, y: float) -> tuple[float, float]:
        """Image pixel (OpenCV convention) under widget point (x, y)."""
        s = self._scale()
        c = self._centre_point()
        # Pixel centre k sits at widget coordinate (k + 0.5 - (c + 0.5)) * s + W/2.
        return (x - self.width() / 2.0) / s + c.x(), (y - self.height() / 2.0) / s + c.y()

    def image_to_widget(self, u: float, v: float) -> tuple[float, float]:
        s = self._scale()
        c = self._centre_point()
        return (u - c.x()) * s + self.width() / 2.0, (v - c.y()) * s + self.height() / 2.0

    # --- painting --------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(24, 25, 28))
        if self._image is None:
            p.setPen(QColor(150, 150, 150))
            p.drawText(self.rect(), Qt.AlignmentFlag.AlignCenter, self.placeholder)
            return
        s = self._scale()
        x0, y0 = self.image_to_widget(-0.5, -0.5)
        target = QRectF(x0, y0, self._image.width() * s, self._image.height() * s)
        shown_w, shown_h = int(round(target.width())), int(round(target.height()))
        if s < 1.0:  # shown smaller than it is: draw it pre-shrunk, 1:1
            p.drawImage(target.topLeft(), self._shrunk.get(self._array, shown_w, shown_h))
        else:
            p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, s < 2.0)
            p.drawImage(target, self._image)
        if self._overlay_image is not None:
            p.setOpacity(self.overlay.image_opacity)
            if s < 1.0:
                p.drawImage(target.topLeft(), self._overlay_shrunk.get(self.overlay.image, shown_w, shown_h))
            else:
                p.drawImage(target, self._overlay_image)
            p.setOpacity(1.0)
        p.setRenderHint(QPainter.RenderHint.Antialiasing, True)
        for u0, v0, u1, v1, color in self.overlay.segments:
            p.setPen(QPen(color, 1.6))
            a, b = self.image_to_widget(u0, v0), self.image_to_widget(u1, v1)
            p.drawLine(QPointF(*a), QPointF(*b))
        font = QFont(self.font())
        font.setPointSizeF(9.0)
        font.setBold(True)
        p.setFont(font)
        metrics = QFontMetricsF(font)
        taken: list[QRectF] = []  # labels already placed: a crowded corner of the image keeps them readable
        for u, v, label, color in self.overlay.points:
            x, y = self.image_to_widget(u, v)
            p.setPen(QPen(QColor(0, 0, 0, 160), 3.0))
            p.drawEllipse(QPointF(x, y), 5.0, 5.0)
            p.setPen(QPen(color, 1.8))
            p.drawEllipse(QPointF(x, y), 5.0, 5.0)
            p.drawLine(QPointF(x - 8, y), QPointF(x - 3, y))
            p.drawLine(QPointF(x + 3, y), QPointF(x + 8, y))
            box = _free_label_box(metrics, x, y, label, taken, QRectF(self.rect())) if label else None
            if box is not None:
                taken.append(box)
                p.setPen(QColor(0, 0, 0))
                p.drawText(box.bottomLeft() + QPointF(1, -metrics.descent() + 1), label)
                p.setPen(color)
                p.drawText(box.bottomLeft() + QPointF(0, -metrics.descent()), label)
        if self._mouse is not None and self.underMouse():
            self._paint_crosshair(p)
            if self.loupe:
                self._paint_loupe(p)
        if self.overlay.text:
            p.setPen(QColor(230, 230, 230))
            p.drawText(QRectF(8, 6, self.width() - 16, 40), Qt.AlignmentFlag.AlignLeft, self.overlay.text)
        if self.overlay.banner:
            flags = int(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter) | int(Qt.TextFlag.TextWordWrap)
            needed = p.boundingRect(QRectF(8, 0, self.width() - 16, 1000), flags, self.overlay.banner).height() + 8
            box = QRectF(0, self.height() - needed, self.width(), needed)
            p.fillRect(box, QColor(120, 70, 0, 220))
            p.setPen(QColor(255, 235, 200))
            p.drawText(box.adjusted(8, 0, -8, 0), flags, self.overlay.banner)
        if self._inset is not None:
            marks = [
                QRectF(x - 10, y - 10, 20, 20)
                for x, y in (self.image_to_widget(u, v) for u, v, _, _ in self.overlay.points)
            ]
            w = min(float(self._inset.width()), 0.22 * self.width())  # a small pane keeps most of its frame
            box = _inset_box(QRectF(self.rect()), w, w * self._inset.height() / self._inset.width(), marks + taken)
            # The inset steps aside while the cursor is over it: a pick under it stays possible.
            if self._mouse is None or not box.contains(self._mouse) or not self.underMouse():
                p.setOpacity(0.9)
                p.drawImage(box, self._inset)
                p.setOpacity(1.0)
                p.setPen(QPen(QColor(255, 214, 10), 1.5))
                p.drawRect(box)
                p.drawText(
                    box.adjusted(4, 2, 0, 0), Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop, self._inset_label
                )

    def _paint_crosshair(self, p: QPainter) -> None:
        u, v = self.widget_to_image(self._mouse.x(), self._mouse.y())
        x, y = self.image_to_widget(round(u), round(v))  # snaps to the pixel a click would pick
        p.setPen(QPen(QColor(255, 255, 0, 200), 1.0))
        p.drawLine(QPointF(0, y), QPointF(x - 6, y))
        p.drawLine(QPointF(x + 6, y), QPointF(self.width(), y))
        p.drawLine(QPointF(x, 0), QPointF(x, y - 6))
        p.drawLine(QPointF(x, y + 6), QPointF(x, self.height()))

    def _stretched_patch(self, cu: int, cv_: int, radius_px: int) -> np.ndarray | None:
        """The (2r+1)^2 pixels around (cu, cv) with their 2nd to 98th percentile stretched over 0-255,
        black outside the image; ``None`` without an image array or where the patch is flat."""
        a = self._array
        if a is None or a.ndim != 3:
            return None
        h, w = a.shape[:2]
        out = np.zeros((2 * radius_px + 1, 2 * radius_px + 1, 3), np.uint8)
        y0, y1, x0, x1 = (
            max(cv_ - radius_px, 0),
            min(cv_ + radius_px + 1, h),
            max(cu - radius_px, 0),
            min(cu + radius_px + 1, w),
        )
        if y0 >= y1 or x0 >= x1:
            return out
        crop = a[y0:y1, x0:x1, :3].astype(np.float32)
        lo, hi = np.percentile(crop, 2), np.percentile(crop, 98)
        if hi - lo < 4:
            return None
        out[y0 - (cv_ - radius_px) : y1 - (cv_ - radius_px), x0 - (cu - radius_px) : x1 - (cu - radius_px)] = np.clip(
            (crop - lo) * (255.0 / (hi - lo)), 0, 255
        ).astype(np.uint8)
        return out

    def _paint_loupe(self, p: QPainter, radius_px: int = 10, size: int = 150) -> None:
        """A magnified inset of the pixels around the cursor, in the corner away from it."""
        u, v = self.widget_to_image(self._mouse.x(), self._mouse.y())
        cu, cv_ = int(round(u)), int(round(v))
        src = QRectF(
            cu - radius_px, cv_ - radius_px, 2 * radius_px + 1, 2 * radius_px + 1
        )  # QImage pixel k spans [k, k + 1)
        x = 8 if self._mouse.x() > self.width() / 2 else self.width() - size - 8
        target = QRectF(x, self.height() - size - 8, size, size)
        p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
        p.fillRect(target, QColor(0, 0, 0))
        patch = self._stretched_patch(cu, cv_, radius_px)
        if patch is not None:  # contrast stretched: a faint boss's rim shows in the loupe
            p.drawImage(target, qimage_from_array(patch), QRectF(0, 0, patch.shape[1], patch.shape[0]))
        else:
            p.drawImage(target, self._image, src)
        p.setPen(QPen(QColor(255, 255, 0), 1.0))
        cx, cy = target.center().x(), target.center().y()
        cell = size / (2 * radius_px + 1)
        p.drawRect(QRectF(cx - cell / 2, cy - cell / 2, cell, cell))
        p.setPen(QPen(QColor(200, 200, 200), 1.0))
        p.drawRect(target)
        p.drawText(
            QRectF(target.x() + 4, target.y() + 2, size, 16),
            Qt.AlignmentFlag.AlignLeft,
            f"({cu}, {cv_}) x{cell:.0f}, contrast stretched",
        )

    # --- interaction ------------------------------------------------------------------------
    def wheelEvent(self, event: QWheelEvent) -> None:
        if self._image is None:
            return
        pos = event.position()
        u, v = self.widget_to_image(pos.x(), pos.y())
        factor = 1.25 if event.angleDelta().y() > 0 else 0.8
        old_zoom = self._zoom
        self._zoom = float(np.clip(self._zoom * factor, 0.5, 40.0))
        # Keep the image point under the cursor where it is.
        s = self._scale()
        self._centre = QPointF(u - (pos.x() - self.width() / 2.0) / s, v - (pos.y() - self.height() / 2.0) / s)
        if old_zoom != self._zoom:
            self.update()

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() in (Qt.MouseButton.RightButton, Qt.MouseButton.MiddleButton):
            self._drag_from = event.position()
        elif event.button() == Qt.MouseButton.LeftButton and self._image is not None:
            u, v = self.widget_to_image(event.position().x(), event.position().y())
            if self.grabber is not None and self.grabber(u, v, 8.0 / self._scale()):
                self._grab_from = event.position()
                return
            self.clicked.emit(u, v)

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        self._mouse = event.position()
        if self._grab_from is not None and self._image is not None:
            self.dragged.emit(*self.widget_to_image(self._mouse.x(), self._mouse.y()))
        if self._drag_from is not None and self._image is not None:
            delta = event.position() - self._drag_from
            s = self._scale()
            c = self._centre_point()
            self._centre = QPointF(c.x() - delta.x() / s, c.y() - delta.y() / s)
            self._drag_from = event.position()
        if self._image is not None:
            self.hovered.emit(*self.widget_to_image(self._mouse.x(), self._mouse.y()))
        self.update()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        self._drag_from = None
        if self._grab_from is not None and event.button() == Qt.MouseButton.LeftButton:
            moved = (event.position() - self._grab_from).manhattanLength() > 2
            self._grab_from = None
            self.drag_finished.emit(*self.widget_to_image(event.position().x(), event.position().y()), moved)

    def leaveEvent(self, event) -> None:
        self._mouse = None
        self.update()


def _inset_box(bounds: QRectF, w: float, h: float, obstacles: list[QRectF]) -> QRectF:
    """Where the live inset (``w`` x ``h`` px) goes over the held frame: the bottom-right corner, else
    the first of the other corners and the middles of the edges that covers none of ``obstacles`` (the
    marks and their labels: a proposal or a pick must not hide behind the live video), else the place
    covering fewest."""
    right, left = bounds.right() - w - 8, bounds.left() + 8
    bottom, top = bounds.bottom() - h - 34, bounds.top() + 48  # clear of the status banner and the overlay's text
    middle_x, middle_y = (left + right) / 2, (top + bottom) / 2
    corners = [
        QRectF(x, y, w, h)
        for x, y in (
            (right, bottom),
            (left, bottom),
            (right, top),
            (left, top),
            (right, middle_y),
            (left, middle_y),
            (middle_x, bottom),
            (middle_x, top),
        )
    ]
    under = [sum(box.intersects(o) for o in obstacles) for box in corners]
    return corners[under.index(min(under))]


def _free_label_box(
    metrics: QFontMetricsF, x: float, y: float, label: str, taken: list[QRectF], bounds: QRectF | None = None
) -> QRectF | None:
    """Where a mark's label at widget (x, y) px goes: above right, below right, above left or below left
    of the mark, the first place no placed label overlaps, inside ``bounds`` (the widget) where one is;
    ``None`` when all are taken (the mark is drawn without it, its name is in the pairs table and the
    Find points list)."""
    w, h = metrics.horizontalAdvance(label) + 2, metrics.height()
    free = [
        box
        for box in (QRectF(x + dx, y + dy, w, h) for dx, dy in ((7, -8 - h), (7, 8), (-7 - w, -8 - h), (-7 - w, 8)))
        if not any(box.intersects(other) for other in taken)
    ]
    inside = [box for box in free if bounds is None or bounds.contains(box)]
    return (inside or free or [None])[0]
