"""Marks' labels over the camera image: where Find points proposes features close together (a boss,
the pin's tip and a plate corner within 30 px at the task location), no label hides another."""

import numpy as np
from PySide6.QtCore import QRectF
from PySide6.QtGui import QColor, QFont, QFontMetricsF, QImage

from app.gui.image_view import ImageView, Overlay, _free_label_box


def test_labels_of_crowded_marks_take_free_places_and_never_overlap(qapp):
    metrics = QFontMetricsF(QFont())
    taken = []
    for x, y in ((100, 100), (104, 102), (98, 97), (102, 99), (101, 101)):
        box = _free_label_box(metrics, x, y, "boss_bottom_left", taken)
        if box is not None:
            assert not any(box.intersects(other) for other in taken)
            taken.append(box)
    assert len(taken) == 4  # four places round a mark; the fifth crowded label is left out, its mark stays
    # a lone mark's label sits above right of it, where it always was
    lone = _free_label_box(metrics, 300, 300, "pin_tip", [])
    assert lone.left() > 300 and lone.bottom() < 300
    # at the widget's right edge it goes to the left of the mark rather than be cut off
    bounds = QRectF(0, 0, 320, 240)
    at_edge = _free_label_box(metrics, 310, 100, "plate_top_right", [], bounds)
    assert bounds.contains(at_edge) and at_edge.right() < 310


def test_a_view_with_crowded_labels_draws_every_mark(qtbot):
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(640, 480)
    view.set_image(np.full((480, 640, 3), 40, np.uint8))
    blue = QColor("#50c8ff")
    view.set_overlay(Overlay(points=[(320 + 3 * k, 240 + 2 * k, f"feature_{k}", blue) for k in range(6)]))
    view.show()
    qtbot.waitExposed(view)
    image = view.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    pixels = np.frombuffer(image.constBits(), np.uint8).reshape(image.height(), image.bytesPerLine())[:, : 3 * image.width()].reshape(image.height(), image.width(), 3)
    bluish = (pixels[..., 2] > 200) & (pixels[..., 0] < 150)
    assert bluish.sum() > 200  # the marks and the labels that found a place are drawn
