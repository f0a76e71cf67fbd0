"""A message too long for the status bar is cut at the fields' edge; its whole text is the bar's tooltip while it shows,
and the fields keep their own."""

from __future__ import annotations

from PySide6.QtGui import QFontMetrics


def test_a_long_message_is_whole_in_the_bars_tooltip_and_gone_with_it(qtbot, offline_window):
    win = offline_window
    bar = win.statusBar()
    text = (
        "fixture: its edges did not settle on the image (RMS 1.20 px, 96 % of 412 edge samples on their edges): its "
        "stated form tolerance, 0.5 mm, is 3.3 px in this image, above the 0.50 px a settled fit is held to: pick the "
        "points by hand"
    )
    win.show_error(text)
    assert bar.currentMessage() == text
    room = bar.width() - sum(w.width() for w in (win.status_line.link_label, win.status_line.pairs_label))
    assert QFontMetrics(bar.font()).horizontalAdvance(text) > room  # it does not fit: the bar cuts it
    assert bar.toolTip() == text
    bar.clearMessage()
    assert bar.toolTip() == ""


def test_every_field_of_the_bar_says_what_it_is_not_the_message(offline_window):
    win = offline_window
    win.show_error("the last message")
    line = win.status_line
    for label in (line.record_label, line.link_label, line.fps_label, line.pairs_label):
        assert label.toolTip() and label.toolTip() != "the last message"


def test_the_window_opens_without_a_warning_from_pyside(qtbot, qtlog, tmp_path, capfd):
    # PySide cannot connect a signal straight to a slot of a widget Qt made itself (the main window's status bar) and
    # warns at every start: through Qt's message handler (pytest-qt's, under capture), else on the process's stderr
    from app.gui.main_window import MainWindow
    from app.gui.workbench import Workbench
    from tests.app.windows import window_settings
    from videocal_sim.sim_site import simulated_cell

    capfd.readouterr()
    win = MainWindow(Workbench(*simulated_cell()), settings=window_settings(tmp_path))
    qtbot.addWidget(win)
    win.show_error("a message")
    assert "libpyside" not in capfd.readouterr().err
    assert not [r.message for r in qtlog.records if "libpyside" in r.message]
    assert win.statusBar().toolTip() == "a message"


def test_a_long_message_ends_in_an_ellipsis_before_the_fields_and_a_short_one_is_whole(offline_window):
    win = offline_window
    bar = win.statusBar()
    first_field = min(w.x() for w in (win.status_line.motion_label, win.status_line.link_label) if w.isVisible())
    long = "fixture: its edges did not settle on the image " * 6
    win.show_error(long)
    shown = bar.shown_message()
    assert shown.endswith("…") and long.startswith(shown[:-1])  # cut, and says so
    assert QFontMetrics(bar.font()).horizontalAdvance(shown) <= bar.message_room_px() < first_field
    assert bar.currentMessage() == long  # the message itself is whole (and the tooltip)
    win.show_error("stored")
    assert bar.shown_message() == "stored"
    image = bar.grab().toImage()  # it paints (a message drawn: dark text pixels left of the fields)
    assert any(image.pixelColor(x, image.height() // 2).lightness() < 100 for x in range(6, first_field))
