"""The robot model: URDF loaded with Pinocchio; forward kinematics, Jacobians and inverse
kinematics of any frame, in mm and degrees at the boundary (Pinocchio's metres inside)."""

from calib_core.lazy_exports import lazy_exports

# Submodule of each public name. They load on first use (PEP 562): the model pulls in Pinocchio, trimesh and SciPy
# (0.6 s), which a submodule needing none of them (the bounded xacro child, started once a document) need not pay.
_WHERE = {
    "RobotModelError": "errors",
    "UnknownFrameError": "errors",
    "UnreachableTargetError": "errors",
    "IKSolution": "ik",
    "solve_ik": "ik",
    "RobotModel": "model",
    "load_robot": "model",
}


__getattr__ = lazy_exports(__name__, _WHERE)

__all__ = [
    "RobotModel",
    "load_robot",
    "solve_ik",
    "IKSolution",
    "RobotModelError",
    "UnknownFrameError",
    "UnreachableTargetError",
]
