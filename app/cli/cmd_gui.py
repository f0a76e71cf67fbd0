"""``videocal gui``: the operator's window on a cell (the bundled one by default): with the
controller simulator and the simulated camera of that cell, or a real controller and camera."""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from pathlib import Path

from app.cli.options import resolved_path
from calib_core.bundled import DEFAULT_WORKCELL


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--workcell", type=resolved_path, default=DEFAULT_WORKCELL, help="workcell YAML (default: the bundled one)"
    )
    parser.add_argument(
        "--port",
        help="a real controller's connector URL (a serial port, socket://host:port, ros2:///joint_states, ...; see "
        "docs/connectors.md)",
    )
    parser.add_argument(
        "--camera",
        help="a real camera's spec (an OpenCV device index, a video file, a stream URL, a folder of images, "
        "aravis://ID, ...)",
    )
    parser.add_argument(
        "--site",
        choices=("auto", "sim", "real"),
        default="auto",
        help="sim: the simulated cell; real: the controller and camera of --port/--camera or the workcell's site: "
        "section; "
        "auto (default): real when either is given, else simulated",
    )
    parser.add_argument(
        "--hand-eye",
        type=resolved_path,
        help="the measured camera mounting that replaces the modelled one: videocal calibrate-hand-eye's file, "
        "easy_handeye2's .calib, or a static_transform_publisher launch file (MoveIt 2's hand-eye result)",
    )
    parser.add_argument(
        "--recording",
        type=resolved_path,
        help="open this videocal recording (.mcap), or a ROS 2 bag (a bag folder, .mcap or .db3: its images with the "
        "joints at each stamp), on the replay timeline at start",
    )
    parser.add_argument(
        "--screenshot", type=Path, help="write a PNG of the window after start-up and quit (for tests and docs)"
    )


def run(args: argparse.Namespace) -> int:
    from calib_core.plugins import SITES, load_plugin

    if _is_real(args):
        site_kind, simulator = None, None
    else:
        site_kind = load_plugin(SITES, "sim")
        # Start the controller simulator first: its start-up then overlaps the window's imports. It dies with us.
        simulator = site_kind.start_early(args.workcell)
    try:
        code = _run_window(args, site_kind, simulator)
    finally:
        if simulator is not None:
            simulator.stop()
    # Everything is closed and written (the windows' close: autosave, recording, link). Leave without the interpreter's
    # final clean-up: tearing down Qt, VTK, numba and DDS with their threads still in native code aborted the process
    # about one exit in three ("FATAL: exception not rethrown", exit -6) after a clean close.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def _is_real(args: argparse.Namespace) -> bool:
    """Whether ``gui`` drives a real cell (see ``--site``)."""
    from calib_core.errors import VideocalError
    from calib_core.workcell.loader import load_site_section

    given = args.port is not None or args.camera is not None
    if args.site == "sim":
        if given:
            raise VideocalError("--site sim brings its own controller and camera: leave out --port and --camera")
        return False
    section = load_site_section(args.workcell)
    has_section = section is not None and (section.controller or section.camera)
    if args.site == "real" and not (given or has_section):
        raise VideocalError(f"--site real needs --port or --camera, or a site: section in {args.workcell}")
    return given or bool(has_section)


def _run_window(args: argparse.Namespace, site_kind, simulator) -> int:
    from PySide6.QtCore import Qt, QTimer
    from PySide6.QtWidgets import QApplication, QLabel, QMainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("videocal")
    # SIGTERM and Ctrl+C close the window like Quit does (so the simulator and the link stop with it).
    # During start-up there is no event loop to quit yet (app.quit() then does nothing and the window came
    # up regardless): the start is abandoned instead, and what it started is stopped on the way out.
    running = False

    def quit_by_signal(signum, _frame):
        if not running:
            # Nothing is open for writing yet, and the children started so far (the simulator) die with us
            # (PR_SET_PDEATHSIG). Raising SystemExit here was not enough: raised inside a Qt callback or a
            # finaliser it was swallowed, and the start went on (exit 1 once under load).
            sys.stderr.flush()
            os._exit(128 + signum)
        app.setProperty("videocal_quit_by_signal", True)  # closing asks nothing; unsaved work stays in the autosave
        # queued, not called: between ``running = True`` and the loop taking its first event, quit() does nothing
        # and the signal would be lost
        QTimer.singleShot(0, app.quit)

    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, quit_by_signal)
    wake = QTimer()
    wake.start(200)  # lets Python run its signal handlers while Qt's loop waits
    wake.timeout.connect(lambda: None)
    # A window on screen at once; the workcell, robot, renderers and link load behind it (several seconds
    # of imports and set-up on a small machine).
    shell = QMainWindow()
    shell.setWindowTitle("videocal - loading")
    note = QLabel("Loading the workcell, the robot, the renderers and the controller link...")
    note.setAlignment(Qt.AlignmentFlag.AlignCenter)
    shell.setCentralWidget(note)
    shell.resize(1600, 1000)
    shell.show()
    app.processEvents()
    report = os.environ.get("VIDEOCAL_REPORT_SHOWN")
    if report:  # the bench measures launch-to-window from outside
        Path(report).write_text(f"{time.monotonic()}")

    from app.gui.cell_launcher import CellLauncher, real_site

    open_site = real_site(args.port, args.camera) if site_kind is None else site_kind.open_cell
    window = CellLauncher(open_site, args.hand_eye).open(args.workcell, simulator)
    window.setGeometry(shell.geometry())
    window.show()
    from app.gui.warm_up import warm_up_in_background

    warm_up_in_background(window.workbench.intrinsics)
    if args.recording is not None:
        window.files.open_recording(args.recording)
    shell.close()
    if report:
        ready = Path(report).with_suffix(".ready")
        QTimer.singleShot(0, lambda: ready.write_text(f"{time.monotonic()}"))
    if args.screenshot is not None:

        def shoot():
            window.grab().save(str(args.screenshot))
            window.close()
            app.quit()

        QTimer.singleShot(4000, shoot)
    running = True
    code = int(app.exec())
    for widget in app.topLevelWidgets():  # quit by a signal: close as Quit does (the window of a cell opened since too)
        if isinstance(widget, QMainWindow) and widget.isVisible():
            widget.close()
    return code
