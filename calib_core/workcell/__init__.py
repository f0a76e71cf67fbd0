"""The workcell: components with meshes, surveyed placements, feature points and task locations."""

from calib_core.workcell.loader import DEFAULT_WORKCELL, load_workcell
from calib_core.workcell.model import TaskLocation, Workcell

__all__ = ["load_workcell", "Workcell", "TaskLocation", "DEFAULT_WORKCELL"]
