"""The simulated site: a controller simulator process and a simulated camera for the cell the
operator opened. It is the only code that knows the truth (the test bed's true robot, lens and
camera mounting); the operator core sees only a link URL and a camera, as on a real site.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.errors import VideocalError
from calib_core.connectors.joint_map import JointMap
from calib_core.operator.cell import Cell
from calib_core.scene import SceneItem
from videocal_sim.sim_process import SimulatorProcess
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors
from calib_core.workcell import DEFAULT_WORKCELL, load_workcell


class SimulatedSite:
    """The devices of a simulated cell: the controller simulator (started for ``bed``'s workcell)
    and the test bed's camera, which follows the joints the controller reports."""

    def __init__(
        self, bed: TestBed, *, process: SimulatorProcess | None = None, camera_fps: float = 15.0, camera_seed: int = 0
    ):
        self.bed = bed
        self.process = process
        self.camera_fps = camera_fps
        self.camera_seed = camera_seed
        self.joint_map = JointMap.for_robot(bed.model_robot.joint_names, bed.workcell.robot_spec.controller)
        self.description = f"simulated cell {bed.workcell.name}"

    def start_controller(self) -> str:
        if self.process is None:
            self.process = SimulatorProcess(self.bed.workcell.path, self.joint_map.to_controller(self.bed.joints_deg))
        return self.process.wait_ready()

    def camera_factory(self, fps: float | None = None) -> Callable:
        return lambda: self.bed.camera(fps=fps or self.camera_fps, seed=self.camera_seed, live=True)

    def attach(self, link) -> None:
        self._link_joint_map = link.joint_map  # the connector's axes: the cell's controller map, or URDF names
        link.sample_received.connect(self._follow)

    def _follow(self, sample) -> None:
        # The physical robot is where its controller says: the simulated camera renders from there.
        self.bed.joints_deg = self._link_joint_map.to_model(sample.joints_deg)

    def put_up(self, items: list[SceneItem]) -> None:
        self.bed.extra_items = list(items)

    def close(self) -> None:
        if self.process is not None:
            self.process.stop()


def simulated_cell(
    workcell_path: str | Path = DEFAULT_WORKCELL,
    *,
    errors: RobotErrors | None = None,
    image_scale: float = 1.0,
    process: SimulatorProcess | None = None,
    camera_fps: float = 15.0,
    intrinsics: Intrinsics | None = None,
    less_kind: bool = False,
) -> tuple[Cell, SimulatedSite]:
    """The cell at ``workcell_path`` and a simulated site for it: the true robot has ``errors``
    (typical ones by default); ``image_scale`` shrinks the camera (0.5: a quarter of the pixels); ``intrinsics``:
    another
    camera than the workcell's (its lens, a fisheye), the same for the simulated camera and the cell's model."""
    workcell = load_workcell(workcell_path)
    if workcell.intrinsics_path is None and intrinsics is None:
        raise VideocalError(
            f"{workcell.path}: field 'camera': the workcell names no camera file (camera.intrinsics): the simulated "
            "camera needs one"
        )
    nominal: Intrinsics = intrinsics or load_intrinsics(workcell.intrinsics_path)
    if image_scale != 1.0:
        nominal = nominal.scaled(image_scale)
    bed = TestBed.create(workcell, errors=errors, intrinsics=nominal)
    if less_kind:
        from videocal_sim.real_look import WORKSHOP_FORM_TOLERANCE_MM, make_less_kind

        make_less_kind(bed)
        for (
            component
        ) in workcell.components:  # what the cell's drawings state of such parts (the truth's field stays unread)
            if component.kind == "component":
                component.form_tolerance_mm = WORKSHOP_FORM_TOLERANCE_MM
    cell = Cell.from_workcell(workcell, intrinsics=nominal)
    bed.joints_deg = np.array(cell.home_joints, dtype=float)
    return cell, SimulatedSite(bed, process=process, camera_fps=camera_fps)
