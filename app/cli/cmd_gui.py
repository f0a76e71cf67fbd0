"""``videocal gui``: the operator's window with the bundled workcell, the controller simulator
(a child process on a pty) and the simulated camera, ready to calibrate; or a real port and camera."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from calib_core.workcell import DEFAULT_WORKCELL


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--workcell", type=Path, default=DEFAULT_WORKCELL, help="workcell YAML (default: the bundled one)")
    parser.add_argument("--port", help="a real controller link URL (serial port, socket://host:port, ...) instead of the simulator")
    parser.add_argument("--camera", help="a real camera: an OpenCV device index, a video file, a stream URL or a folder of images, instead of the simulated camera")
    parser.add_argument("--hand-eye", type=Path, help="a cam2flange file from videocal calibrate-hand-eye: the measured camera mounting replaces the modelled one")
    parser.add_argument("--recording", type=Path, help="open this MCAP recording on the replay timeline at start")
    parser.add_argument("--screenshot", type=Path, help="write a PNG of the window after start-up and quit (for tests and docs)")


def run(args: argparse.Namespace) -> int:
    import subprocess
    import tempfile

    simulator = None
    if not args.port:
        # Start the controller simulator first: its start-up then overlaps the window's imports.
        sim_dir = tempfile.TemporaryDirectory(prefix="videocal-sim-")
        simulator = (subprocess.Popen(
            [sys.executable, "-m", "app.cli.main", "sim-controller", "--pty", "--link", str(Path(sim_dir.name) / "controller")],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=str(Path(__file__).resolve().parents[2]),
        ), Path(sim_dir.name) / "controller")
    from PySide6.QtCore import Qt, QTimer
    from PySide6.QtWidgets import QApplication, QLabel, QMainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("videocal")
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

    from app.gui.main_window import MainWindow
    from app.gui.workbench import Workbench
    from calib_core.testbed.test_bed import TestBed
    from calib_core.workcell import load_workcell

    bed = TestBed.create(load_workcell(args.workcell))
    workbench = Workbench(bed)
    if args.hand_eye is not None:
        workbench.apply_hand_eye_file(args.hand_eye)
    if args.port:
        workbench.connect_link(args.port)
    else:
        workbench.start_simulated_controller(simulator)
    window = MainWindow(workbench)
    if args.camera:
        from calib_core.video.folder_source import ImageFolderSource
        from calib_core.video.opencv_source import OpenCVSource

        spec = args.camera
        if Path(spec).is_dir():
            window.start_camera(lambda: ImageFolderSource(spec, loop=True))
        else:
            window.start_camera(lambda: OpenCVSource(int(spec) if spec.isdigit() else spec))
    else:
        window.start_camera(lambda: bed.camera(intrinsics=bed.intrinsics, fps=15.0))
    window.setGeometry(shell.geometry())
    window.show()
    if args.recording is not None:
        window.open_recording(args.recording)
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
    return int(app.exec())
