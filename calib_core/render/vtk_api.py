"""The part of VTK videocal draws with, imported module by module: ``import vtk`` loads every VTK
module (about 0.7 s on this machine, on the way to the first window), this a third of it.
Used as ``from calib_core.render import vtk_api as vtk``."""

# ruff: noqa: F401  (a namespace of re-exports)
import vtkmodules.vtkRenderingFreeType  # text actors (feature names)
import vtkmodules.vtkRenderingOpenGL2  # the OpenGL backend: registers the (OSMesa/EGL/X) render windows
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonCore import VTK_UNSIGNED_CHAR, vtkFloatArray, vtkPoints, vtkUnsignedCharArray
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkImageData, vtkPolyData
from vtkmodules.vtkCommonMath import vtkMatrix4x4
from vtkmodules.vtkFiltersCore import vtkFeatureEdges
from vtkmodules.vtkRenderingCore import (
    vtkActor,
    vtkBillboardTextActor3D,
    vtkCamera,
    vtkCellPicker,
    vtkLight,
    vtkMapper,
    vtkPolyDataMapper,
    vtkProp,
    vtkRenderer,
    vtkRenderWindow,
    vtkTexture,
)
