"""The simulated site kind, as ``videocal.sites`` finds it (entry point ``sim``).

What the command line and the window ask of a site kind, and what only a simulated one can give:
views taken in a cell whose truth is known (``calibrate-intrinsics sim``, ``calibrate-hand-eye
sim``, ``calibrate-robot sim``, ``render --view true``).
"""

from __future__ import annotations

from pathlib import Path


class SimulatedSiteKind:
    """``sim``: each cell opened gets a controller simulator process and a camera on a true robot."""

    name = "sim"
    description = "the simulated cell: a controller simulator and a camera on a robot that differs from its model"

    def start_early(self, workcell_path: str | Path):
        """Start the controller simulator for ``workcell_path`` before the window's imports (its
        start-up overlaps theirs); hand the returned process to :meth:`open_cell`."""
        from videocal_sim.sim_process import SimulatorProcess

        return SimulatorProcess(workcell_path)

    def open_cell(self, workcell_path: str | Path, process=None):
        """``(Cell, Site)`` for the workcell at ``workcell_path``."""
        from videocal_sim.sim_site import simulated_cell

        return simulated_cell(workcell_path, process=process)

    def board_images(self, spec, n: int):
        """``(truth intrinsics, [(name, RGB image)])``: ``n`` views of the board by the bundled camera."""
        from videocal_sim.board_views import simulated_board_images
        from calib_core.camera.intrinsics_io import load_intrinsics
        from calib_core.workcell import load_workcell

        truth = load_intrinsics(load_workcell().intrinsics_path)
        return truth, simulated_board_images(truth, spec, n)

    def hand_eye(self, **options):
        """``(HandEyeResult, error against the truth)`` from simulated board views (options: see
        :func:`videocal_sim.hand_eye_views.calibrate_simulated_hand_eye`)."""
        from videocal_sim.hand_eye_views import calibrate_simulated_hand_eye

        return calibrate_simulated_hand_eye(**options)

    def calibrate_robot(self, views: int, seed: int, **options):
        """The cold cell's robot calibration (:func:`videocal_sim.cold_robot_calibration.calibrate_cold_cell`)."""
        from videocal_sim.cold_robot_calibration import calibrate_cold_cell

        return calibrate_cold_cell(views, seed, **options)

    def true_view(self, workcell, q_deg, intrinsics):
        """RGB image (h, w, 3) the simulated camera on the true robot sees at commanded joints ``q_deg``."""
        from videocal_sim.test_bed import TestBed

        bed = TestBed.create(workcell)
        bed.joints_deg = q_deg
        camera = bed.camera(intrinsics=intrinsics)
        try:
            return camera.read().image
        finally:
            camera.close()


SIMULATED_SITE = SimulatedSiteKind()
