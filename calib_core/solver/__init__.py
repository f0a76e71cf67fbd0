"""The pose solver: the camera pose relative to an object from picked point pairs.

``solve_pose`` needs no starting pose; ``refine_pose`` iterates from one, as the paper
did; ``solve_pose_batch`` solves many independent problems at once.
"""

from calib_core.lazy_exports import lazy_exports

# Submodule of each public name. They load on first use (PEP 562): the numba kernels behind
# ``solve_pose`` cost a few tenths of a second to import, which the window's start need not pay.
_WHERE = {
    "BatchPoseSolution": "batch",
    "solve_pose_batch": "batch",
    "DegenerateGeometryError": "errors",
    "DuplicatePointsError": "errors",
    "InvalidIntrinsicsError": "errors",
    "MismatchedPointsError": "errors",
    "NonFiniteInputError": "errors",
    "OutOfRangeInputError": "errors",
    "PointsBehindCameraError": "errors",
    "SolverInputError": "errors",
    "TooFewPointsError": "errors",
    "PoseCandidate": "solution",
    "PoseSolution": "solution",
    "SolveStatus": "solution",
    "refine_pose": "solve",
    "solve_pose": "solve",
}


__getattr__ = lazy_exports(__name__, _WHERE)

__all__ = [
    "solve_pose",
    "refine_pose",
    "solve_pose_batch",
    "PoseSolution",
    "PoseCandidate",
    "SolveStatus",
    "BatchPoseSolution",
    "SolverInputError",
    "TooFewPointsError",
    "MismatchedPointsError",
    "NonFiniteInputError",
    "OutOfRangeInputError",
    "DuplicatePointsError",
    "DegenerateGeometryError",
    "PointsBehindCameraError",
    "InvalidIntrinsicsError",
]
