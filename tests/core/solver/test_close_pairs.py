"""The duplicate checks' close pairs, compiled (all pairs compared for a few points, a sweep along one direction for
many), against SciPy's k-d tree on the same points: planted near-duplicates, points on a grid plane (which a sweep
along a coordinate axis would compare all with all), tolerances from a micro-pixel to a few mm."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from calib_core.solver.kernels.geometry_checks import close_pairs, close_pairs_swept


@pytest.mark.parametrize("dim", [2, 3])
def test_the_compiled_close_pairs_are_the_k_d_trees(dim):
    rng = np.random.default_rng(dim)
    for trial in range(150):
        n = int(rng.integers(5, 400))
        points = rng.uniform(-50.0, 50.0, (n, dim))
        planted = rng.integers(0, n, (int(rng.integers(0, 20)), 2))
        points[planted[:, 1]] = points[planted[:, 0]] + rng.normal(0.0, 1e-4, (len(planted), dim))
        if trial % 3 == 0:
            points[:, 0] = np.round(points[:, 0] / 10.0) * 10.0  # a CAD grid: many share one coordinate
        tol = float(rng.choice([1e-6, 1e-3, 0.5, 3.0]))
        expected = sorted(cKDTree(points).query_pairs(tol))
        assert sorted(map(tuple, close_pairs_swept(points, tol).tolist())) == expected
        if n <= 64:
            assert list(map(tuple, close_pairs(points, tol).tolist())) == expected
