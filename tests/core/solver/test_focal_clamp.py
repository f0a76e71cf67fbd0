"""With focal lengths estimated, a solve resting on the focal search range said 'point 2 fits worst
(check that pick)': the picks were fine, the range was the cause. The reason now says so."""

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.solver import solve_pose

FILE = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960)


def _picks(scale: float, seed: int = 3):
    true = Intrinsics(scale * FILE.fu, scale * FILE.fv, FILE.cx, FILE.cy, 1280, 960)
    rng = np.random.default_rng(seed)
    T = make_transform(Rotation.from_rotvec([0.1, -0.2, 0.05]).as_matrix(), [0, 0, 500.0 * scale])
    P = rng.uniform(-75, 75, (8, 3))
    return P, project_points(P, T, true) + rng.normal(0, 0.3, (8, 2))


def test_a_focal_length_at_the_search_limit_is_named_as_the_cause():
    P, uv = _picks(6.0)  # a lens six times longer than the camera file says
    solution = solve_pose(P, uv, FILE, estimate_focal=True)
    assert solution.status.value == "failed"
    assert (
        "focal lengths ran to the edge of their search range" in solution.reason
        and "5.00 x the camera file's" in solution.reason
    )
    assert "fits worst" not in solution.reason


def test_a_focal_length_within_the_range_is_estimated():
    P, uv = _picks(1.3)
    solution = solve_pose(P, uv, FILE, estimate_focal=True)
    assert solution.status.value == "ok", solution.reason
    assert abs(solution.fu / (1.3 * FILE.fu) - 1) < 0.02
