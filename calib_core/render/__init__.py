"""Offscreen VTK rendering of the workcell: the virtual camera (exactly the calibrated camera),
the overview, picking. The only package that imports VTK or pyvista."""

import os as _os

# Without a display VTK must render through OSMesa/EGL; set before VTK is imported.
if not _os.environ.get("DISPLAY") and not _os.environ.get("WAYLAND_DISPLAY"):
    _os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkOSOpenGLRenderWindow")

from calib_core.render.renderer import PickResult, RenderOptions, SceneRenderer
from calib_core.render.virtual_camera import projection_matrix, set_vtk_camera

__all__ = ["SceneRenderer", "RenderOptions", "PickResult", "projection_matrix", "set_vtk_camera"]
