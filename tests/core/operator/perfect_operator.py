"""An operator whose clicks land where the truth says: each feature picked on the model and on its true image."""

import numpy as np

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.robot import solve_ik

FEATURES = ("plate_top_left", "plate_top_right", "plate_bottom_left", "plate_bottom_right", "pin_tip", "boss_top_left")


def pick_all(core, bed, q, features=FEATURES) -> None:
    """Pick each of ``features`` of the task's component on the model and on its true image at commanded joints
    ``q``."""
    fixture = core.workcell.component(core.task.component)
    true_cam = bed.true_cam2world(q)
    for name in features:
        if name not in fixture.features:
            continue
        p = apply(fixture.item2world, fixture.features[name])
        core.picking.pick_model_point(fixture.name, name, p)
        core.picking.pick_image_point(project(apply(invert(true_cam), p[None]), core.intrinsics)[0])
        core.picking.accept_pair()


def task_joints(core) -> np.ndarray:
    return solve_ik(core.robot, core.task.approach2base, core.cell.home_joints).q_deg
