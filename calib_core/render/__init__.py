"""Offscreen VTK rendering of the workcell: the virtual camera (exactly the calibrated camera),
the overview, picking. The only package that imports VTK or pyvista."""

from calib_core.render.renderer import PickResult, RenderOptions, SceneRenderer
from calib_core.render.virtual_camera import projection_matrix, set_vtk_camera

__all__ = ["SceneRenderer", "RenderOptions", "PickResult", "projection_matrix", "set_vtk_camera"]
