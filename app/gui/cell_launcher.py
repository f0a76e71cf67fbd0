"""Opening a cell in a window: the cell, its site (the simulator and simulated camera of that cell,
or a real controller and camera), the operator core and the main window, in one place for the
command line and for File > Open cell."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QSettings


@dataclass(frozen=True)
class CellLauncher:
    """How windows are opened in this run: a real controller ``port`` and ``camera``, or (no port)
    the simulated site of each cell opened."""

    port: str | None = None
    camera: str | None = None
    hand_eye: Path | None = None
    settings: QSettings | None = None

    def open(self, workcell: str | Path, simulator=None):
        """A shown :class:`MainWindow` on ``workcell``. Nothing is left running if it fails."""
        from app.gui.main_window import MainWindow
        from app.gui.workbench import Workbench
        from calib_core.operator.cell import Cell
        from calib_core.operator.site import RealSite

        if self.port is None:
            from calib_core.testbed.sim_site import simulated_cell

            try:
                cell, site = simulated_cell(workcell, process=simulator)
            except BaseException:
                if simulator is not None:
                    simulator.stop()
                raise
        else:
            cell, site = Cell.open(workcell), RealSite(self.port, self.camera)
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
        window.recent_cells.remember(Path(workcell).resolve())
        return window
