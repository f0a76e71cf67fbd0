"""Points on a plane (a fixture's face, a board) take the compiled fast path up to eight pairs, seeded by P3P over
every triplet (a plane leaves the DLT undetermined): where it answers, its answer is the full search's with the
modelled camera as the prior, to the micrometre, and called ``ok`` by both; where two poses fit about as well (the
plane's mirror pose) it declines and the full search ranks them by the prior."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import calib_core.solver.solve as solve_module
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.solver import SolveStatus, solve_pose

from tests.core.solver.scenes import PINHOLE_CAMERA


def _plane_scene(rng, n):
    R = Rotation.from_rotvec(rng.normal(0.0, 0.6, 3)).as_matrix()
    T = make_transform(R, np.array([rng.uniform(-60, 60), rng.uniform(-50, 50), 500.0 * rng.uniform(0.8, 1.2)]))
    P = np.column_stack([rng.uniform(-75, 75, (n, 2)), np.zeros(n)])
    return T, P, project_points(P, T, PINHOLE_CAMERA) + rng.normal(0.0, 0.5, (n, 2))


@pytest.mark.parametrize("n", [4, 5, 6, 8])
def test_a_plane_s_few_pairs_solve_on_the_fast_path_as_the_full_search_does(n, monkeypatch):
    rng = np.random.default_rng(n)
    fast_answers = declined = 0
    for _ in range(150):
        T, P, uv = _plane_scene(rng, n)
        prior = T.copy()
        prior[:3, 3] += rng.normal(0.0, 3.0, 3)  # the modelled camera, a few mm off
        answered = []
        fast = solve_module.fast_solve
        monkeypatch.setattr(solve_module, "fast_solve", lambda *a, **k: answered.append(out := fast(*a, **k)) or out)
        solution = solve_pose(P, uv, PINHOLE_CAMERA, prior=prior)
        monkeypatch.setattr(solve_module, "fast_path_applies", lambda *a: False)
        full = solve_pose(P, uv, PINHOLE_CAMERA, prior=prior)
        monkeypatch.undo()
        assert answered, "a plane's few pairs go to the fast path first"
        if answered[0] is None:
            declined += 1
            continue
        fast_answers += 1
        assert solution.status is SolveStatus.OK and full.status is SolveStatus.OK, full.reason
        np.testing.assert_allclose(solution.obj2cam, full.obj2cam, atol=1e-6)
    assert fast_answers >= 0.75 * 150  # the mirror pose ties in some four-pair planes, hardly ever beyond
