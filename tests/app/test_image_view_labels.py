"""Marks' labels over the camera image: where Find points proposes features close together (a boss,
the pin's tip and a plate corner within 30 px at the task location), no label hides another."""

import numpy as np
from PySide6.QtCore import QRectF
from PySide6.QtGui import QColor, QFont, QFontMetricsF, QImage

from app.gui.image_view import ImageView, Overlay, _free_label_box, _inset_box


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


def test_the_live_inset_leaves_the_corner_where_marks_are(qapp):
    """Over a held frame the live inset sits bottom right; with proposals (their marks or labels) there it
    takes the next free corner, and with them everywhere the corner covering the fewest."""
    bounds = QRectF(0, 0, 800, 600)
    alone = _inset_box(bounds, 180, 135, [])
    assert alone.right() > 700 and alone.bottom() > 500
    marks = [QRectF(730, 490, 20, 20), QRectF(560, 470, 130, 14)]  # a mark, and a label reaching into the corner
    moved = _inset_box(bounds, 180, 135, marks)
    assert moved.left() < 100 and moved.bottom() > 500 and not any(moved.intersects(m) for m in marks)
    corners = [QRectF(x, y, 20, 20) for x in (50, 100, 700, 750) for y in (100, 500)]
    between = _inset_box(bounds, 180, 135, corners)  # every corner taken: the middle of an edge
    assert not any(between.intersects(m) for m in corners) and 150 < between.center().y() < 450
    everywhere = [QRectF(x, y, 20, 20) for x in range(0, 800, 60) for y in range(0, 600, 60)] + [
        QRectF(700, 500, 20, 20)
    ]
    fewest = _inset_box(bounds, 180, 135, everywhere)
    right_bottom = QRectF(bounds.right() - 188, bounds.bottom() - 169, 180, 135)
    assert sum(fewest.intersects(m) for m in everywhere) < sum(right_bottom.intersects(m) for m in everywhere)


def _blue_pixels(qtbot, labelled: bool) -> int:
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(640, 480)
    view.set_image(np.full((480, 640, 3), 40, np.uint8))
    blue = QColor("#50c8ff")
    view.set_overlay(
        Overlay(points=[(320 + 3 * k, 240 + 2 * k, f"feature_{k}" if labelled else "", blue) for k in range(6)])
    )
    view.show()
    qtbot.waitExposed(view)
    image = view.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    pixels = (
        np.frombuffer(image.constBits(), np.uint8)
        .reshape(image.height(), image.bytesPerLine())[:, : 3 * image.width()]
        .reshape(image.height(), image.width(), 3)
    )
    return int(((pixels[..., 2] > 200) & (pixels[..., 0] < 150)).sum())


def test_a_view_with_crowded_marks_draws_four_labels_round_them(qtbot):
    """Six marks within 15 px: four labels find a free place (the other two are left out), so the
    labels' ink is about four times one label's (later marks cover a little of it), not six times and
    not one (drawn on top of each other, as before the placement)."""
    marks_only = _blue_pixels(qtbot, labelled=False)
    with_labels = _blue_pixels(qtbot, labelled=True)
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(640, 480)
    view.set_image(np.full((480, 640, 3), 40, np.uint8))
    view.set_overlay(Overlay(points=[(100, 100, "feature_0", QColor("#50c8ff"))]))
    view.show()
    qtbot.waitExposed(view)
    image = view.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    pixels = (
        np.frombuffer(image.constBits(), np.uint8)
        .reshape(image.height(), image.bytesPerLine())[:, : 3 * image.width()]
        .reshape(image.height(), image.width(), 3)
    )
    one_mark_and_label = int(((pixels[..., 2] > 200) & (pixels[..., 0] < 150)).sum())
    one_label = one_mark_and_label - marks_only / 6
    ink = with_labels - marks_only
    assert 2.5 * one_label < ink < 4.8 * one_label, (ink, one_label)
