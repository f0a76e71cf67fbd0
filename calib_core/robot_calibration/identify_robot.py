"""The one driver of a robot identification: board views and frames of surveyed components in, the
calibrated robot out. The window (after a calibration run), ``videocal calibrate-robot FILE`` and the
simulator's cold cell all call :func:`identify_robot`, so the three locate components and weigh views
the same way.

A component's frame is located here, not where it was taken: Find points' edge fit takes a second or
two, too long between the moves of a run. A component not located is a warning of the result (named,
with Find points' reason), never a silent gap.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.cell_views import cell_view
from calib_core.robot_calibration.calibrated_robot import RobotCalibration
from calib_core.robot_calibration.identification import identify
from calib_core.robot_calibration.observations import PoseView

Progress = Callable[[int, int, str], None]
"""``progress(done, total, text)``: told before each component's location and before the fit."""


@dataclass(frozen=True)
class CellFrame:
    """A settled frame ``image`` (H, W) or (H, W, 3) taken at ``joints_deg`` (model joints, deg/mm)
    viewing the surveyed ``component``; ``name`` labels it in warnings and the per-view RMS."""

    component: str
    joints_deg: np.ndarray
    image: np.ndarray
    name: str = ""


@dataclass(frozen=True)
class IdentifiedRobot:
    """``result`` (its warnings name every component frame not located); ``views`` the fit's views in its
    order (the board's, then the located components'); how many ``board_views`` and located
    ``cell_views`` went into it; ``not_located`` the reasons, one per frame left out."""

    result: RobotCalibration
    views: list
    board_views: int
    cell_views: int
    not_located: list[str] = field(default_factory=list)


def identify_robot(
    robot: RobotModel,
    intrinsics: Intrinsics,
    workcell,
    board_views: Sequence[PoseView],
    cell_frames: Sequence[CellFrame] = (),
    *,
    visuals=None,
    extras: Sequence = (),
    with_intrinsics: bool = False,
    progress: Progress | None = None,
) -> IdentifiedRobot:
    """Identify ``robot`` (as it is now: nominal, or calibrated before, is the start) from
    ``board_views`` (detected ChArUco corners at their joints) and ``cell_frames`` (each component
    located by its edges through ``intrinsics`` against what the modelled camera would see: the
    cell's components, the robot's ``visuals`` and ``extras`` put up in the cell, such as the board).
    ``visuals`` default to the robot's own meshes."""
    say = progress or (lambda done, total, text: None)
    total = len(cell_frames) + 1
    located, missed = _locate(robot, intrinsics, workcell, cell_frames, visuals, extras, say, total)
    say(total - 1, total, f"identifying the robot from {len(board_views)} board and {len(located)} component views ...")
    views = list(board_views) + located
    result = identify(robot, intrinsics, views, with_intrinsics=with_intrinsics)
    if missed:
        result = replace(result, warnings=list(result.warnings) + missed)
    return IdentifiedRobot(result, views, len(board_views), len(located), missed)


def _locate(robot, intrinsics, workcell, frames: Sequence[CellFrame], visuals, extras, say: Progress, total: int):
    located, missed = [], []
    if not frames:
        return located, missed
    from calib_core.render.model_view import ModelView  # VTK loads only when a component is to be located
    from calib_core.robot.visuals import RobotVisuals

    visuals = visuals if visuals is not None else RobotVisuals.from_robot(robot)
    view = ModelView(intrinsics)
    try:
        for k, f in enumerate(frames):
            name = f.name or f"cell_{k + 1:02d}_{f.component}"
            say(k, total, f"locating {f.component} in view {k + 1} of {len(frames)} ...")
            q = np.asarray(f.joints_deg, dtype=float)
            item = workcell.component(f.component)
            expected = view.of_cell(workcell.components, visuals, q, item.item2world, extras=list(extras))
            found = cell_view(name, f.image, q, workcell, f.component, robot, intrinsics, expected)
            (missed if isinstance(found, str) else located).append(found)
    finally:
        view.close()
    return located, missed
