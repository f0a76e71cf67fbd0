"""The simulated test bed: the workcell, the model robot, the true robot and its camera.

Everything the real site would provide, with its truth known: tests and the demo drive the
whole calibration loop against it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.errors import VideocalError
from calib_core.frames import concat
from calib_core.robot.model import RobotModel
from calib_core.robot.visuals import RobotVisuals
from calib_core.scene import SceneItem
from videocal_sim.sim_camera import CameraLook, SimulatedCamera
from videocal_sim.true_robot import RobotErrors, TrueRobot
from calib_core.workcell import Workcell, load_workcell


@dataclass
class TestBed:
    """A simulated site. ``joints_deg`` holds the commanded joints (what the controller reports)."""

    workcell: Workcell
    model_robot: RobotModel
    true_robot: TrueRobot
    intrinsics: Intrinsics
    visuals: RobotVisuals
    joints_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    extra_items: list[SceneItem] = field(default_factory=list)
    """Things put into the real cell for a while (a calibration board): the camera sees them, the CAD does not."""
    true_components: list[SceneItem] | None = None
    """Where the cell's components really are (``None``: where the workcell file says; the cold cell
    moves each by its survey error)."""
    camera_look: CameraLook | None = None
    """How the camera's images look when :meth:`camera` is not told (``None``: :class:`CameraLook`'s defaults;
    :func:`videocal_sim.real_look.make_less_kind`: a workshop's)."""
    _model_visuals: RobotVisuals | None = field(default=None, repr=False)

    __test__ = False  # not a pytest test class despite its name

    @classmethod
    def create(
        cls, workcell: Workcell | None = None, errors: RobotErrors | None = None, intrinsics: Intrinsics | None = None
    ) -> TestBed:
        """The bundled workcell with typical robot errors (seed 0) unless told otherwise."""
        cell = workcell or load_workcell()
        model = cell.load_robot()
        true = TrueRobot(model, RobotErrors.typical(0, n_joints=model.n_joints) if errors is None else errors)
        if intrinsics is None and cell.intrinsics_path is None:
            raise VideocalError(
                f"{cell.path}: field 'camera': the workcell names no camera file (camera.intrinsics): calibrate the "
                "camera first (videocal calibrate-intrinsics)"
            )
        intr = intrinsics or load_intrinsics(cell.intrinsics_path)
        return cls(
            cell, model, true, intr, RobotVisuals.from_robot(true.robot), np.array(cell.home_joints_deg, dtype=float)
        )

    def true_scene(self, q_commanded_deg: ArrayLike) -> list[SceneItem]:
        """Workcell plus the true robot's links where they really are at commanded joints."""
        q_true = self.true_robot.true_joints(q_commanded_deg)
        base = self.true_robot.base_true2base_model
        links = self.visuals.scene_items(q_true)
        for item in links:
            item.item2world = concat(item.item2world, base)
        components = self.workcell.components if self.true_components is None else self.true_components
        return list(components) + links + list(self.extra_items)

    def visuals_for_model(self) -> RobotVisuals:
        """The modelled robot's visuals (the CAD view draws the model, not the truth)."""
        if self._model_visuals is None:
            self._model_visuals = RobotVisuals.from_robot(self.model_robot)
        return self._model_visuals

    def true_cam2world(self, q_commanded_deg: ArrayLike) -> np.ndarray:
        return self.true_robot.fk(q_commanded_deg, "camera")

    def model_cam2world(self, q_commanded_deg: ArrayLike) -> np.ndarray:
        return self.model_robot.fk(q_commanded_deg, "camera")

    def camera(
        self,
        *,
        fps: float = 15.0,
        look: CameraLook | None = None,
        seed: int = 0,
        intrinsics: Intrinsics | None = None,
        live: bool = False,
    ) -> SimulatedCamera:
        """The test bed's camera, following ``joints_deg``; ``live``: video for the window (frames of
        a moving robot point-sampled, :attr:`SimulatedCamera.coarse_while_moving`)."""
        return SimulatedCamera(
            intrinsics or self.intrinsics,
            self.true_scene,
            self.true_cam2world,
            lambda: self.joints_deg.copy(),
            fps=fps,
            look=look or self.camera_look,
            seed=seed,
            coarse_while_moving=live,
        )
