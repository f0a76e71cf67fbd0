"""The workcell: components with meshes, surveyed placements, feature points and task locations.

The public names load their submodules on first use (PEP 562): a look that only needs a feature's kind
(``calib_core.workcell.feature_kinds``) does not load the cell's loader and with it the robot model (Pinocchio).
"""

from calib_core.lazy_exports import lazy_exports

_WHERE = {
    "DEFAULT_WORKCELL": "loader",
    "load_workcell": "loader",
    "TaskLocation": "model",
    "Workcell": "model",
}
__all__ = ["load_workcell", "Workcell", "TaskLocation", "DEFAULT_WORKCELL"]
__getattr__ = lazy_exports(__name__, _WHERE)
