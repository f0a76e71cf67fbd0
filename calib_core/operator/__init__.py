"""The operator core: the cell, the site that gives it devices, and the workflow state, without Qt."""

from calib_core.operator.cell import Cell, CellIdentity, CellMismatchError
from calib_core.operator.core import OperatorCore
from calib_core.operator.site import RealSite, Site

__all__ = ["Cell", "CellIdentity", "CellMismatchError", "OperatorCore", "RealSite", "Site"]
