"""The pose solver: the camera pose relative to an object from picked point pairs.

``solve_pose`` needs no starting pose; ``refine_pose`` iterates from one, as the paper
did; ``solve_pose_batch`` solves many independent problems at once.
"""

from calib_core.solver.batch import BatchPoseSolution, solve_pose_batch
from calib_core.solver.errors import (
    DegenerateGeometryError,
    DuplicatePointsError,
    InvalidIntrinsicsError,
    MismatchedPointsError,
    NonFiniteInputError,
    PointsBehindCameraError,
    SolverInputError,
    TooFewPointsError,
)
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus
from calib_core.solver.solve import refine_pose, solve_pose

__all__ = [
    "solve_pose", "refine_pose", "solve_pose_batch", "PoseSolution", "PoseCandidate", "SolveStatus", "BatchPoseSolution",
    "SolverInputError", "TooFewPointsError", "MismatchedPointsError", "NonFiniteInputError", "DuplicatePointsError",
    "DegenerateGeometryError", "PointsBehindCameraError", "InvalidIntrinsicsError",
]
