"""Opening a cell in a window: the cell and its site, the operator core and the main window, in one
place for the command line and for File > Open cell. Which kind of site a run uses (a real
controller and camera, or the simulated site of each cell opened) is the caller's choice: the
window never knows."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QSettings


def real_site(port: str | None, camera: str | None) -> Callable:
    """``open_site`` for a real cell: the controller ``port`` and the ``camera`` spec given on the command
    line, else those of each cell's ``site:`` section (either may be absent)."""
    from calib_core.operator.cell import Cell
    from calib_core.operator.site import RealSite

    def open_site(workcell, simulator=None):
        cell = Cell.open(workcell)
        section = cell.workcell.site
        controller = port if port is not None else (section.controller if section else None)
        spec = camera if camera is not None else (section.camera if section else None)
        # A connector's options belong to the section's own URL, not to one given on the command line.
        controller_options = section.controller_options if section and controller == section.controller else None
        camera_options = section.camera_options if section and spec == section.camera else None
        return cell, RealSite(controller, spec, controller_options=controller_options, camera_options=camera_options)

    return open_site


@dataclass(frozen=True)
class CellLauncher:
    """``open_site(workcell, simulator)`` gives ``(cell, site)`` for a workcell file (``simulator``:
    a controller process already started for it, or None); ``hand_eye``: a measured camera mounting
    for every cell opened; ``settings``: the windows' QSettings."""

    open_site: Callable
    hand_eye: Path | None = None
    settings: QSettings | None = None

    def open(self, workcell: str | Path, simulator=None):
        """A :class:`MainWindow` on ``workcell``, its controller connected and its camera running.
        Nothing is left running if it fails."""
        from app.gui.main_window import MainWindow
        from app.gui.workbench import Workbench

        try:
            cell, site = self.open_site(workcell, simulator)
        except BaseException:
            if simulator is not None:
                simulator.stop()
            raise
        workbench = Workbench(cell, site)
        try:
            if self.hand_eye is not None:
                workbench.apply_hand_eye_file(self.hand_eye)
            workbench.start_controller()
            window = MainWindow(workbench, settings=self.settings, launcher=self)
        except BaseException:
            workbench.close()
            raise
        camera = site.camera_factory()
        if camera is not None:
            window.start_camera(camera)
        window.files.recent_cells.remember(Path(workcell).resolve())
        return window
