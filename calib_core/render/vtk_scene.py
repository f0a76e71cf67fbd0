"""Scene items as VTK actors: built once per mesh, moved by their poses, restyled per render."""

from __future__ import annotations

import numpy as np
from calib_core.render import vtk_api as vtk

from calib_core.scene import SceneItem


def vtk_matrix(T: np.ndarray) -> vtk.vtkMatrix4x4:
    m = vtk.vtkMatrix4x4()
    for i in range(4):
        for j in range(4):
            m.SetElement(i, j, float(T[i, j]))
    return m


def polydata_of(mesh) -> vtk.vtkPolyData:
    """A trimesh mesh as VTK triangles (the points and connectivity copied once)."""
    points = vtk.vtkPoints()
    points.SetData(vtk.numpy_support.numpy_to_vtk(np.ascontiguousarray(mesh.vertices, dtype=float), deep=True))
    faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    offsets = np.arange(0, 3 * len(faces) + 1, 3, dtype=np.int64)
    cells = vtk.vtkCellArray()
    cells.SetData(
        vtk.numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=True),
        vtk.numpy_support.numpy_to_vtkIdTypeArray(faces.ravel(), deep=True),
    )
    data = vtk.vtkPolyData()
    data.SetPoints(points)
    data.SetPolys(cells)
    return data


class ItemActor:
    """One scene item: a surface actor, and lazily its feature-edge actor for overlays."""

    def __init__(self, item: SceneItem):
        self.item = item
        self.polydata = polydata_of(item.mesh)
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(self.polydata)
        mapper.ScalarVisibilityOff()
        self.surface = vtk.vtkActor()
        self.surface.SetMapper(mapper)
        if item.texture is not None:
            self._apply_texture(item)
        self._edges: vtk.vtkActor | None = None
        self.set_pose(item.item2world)

    def _apply_texture(self, item: SceneItem) -> None:
        tcoords = vtk.numpy_support.numpy_to_vtk(np.ascontiguousarray(item.texture_coords, dtype=np.float32), deep=True)
        tcoords.SetName("TCoords")
        self.polydata.GetPointData().SetTCoords(tcoords)
        image = item.texture if item.texture.ndim == 3 else np.repeat(item.texture[:, :, None], 3, axis=2)
        h, w = image.shape[:2]
        data = vtk.vtkImageData()
        data.SetDimensions(w, h, 1)
        # VTK images start at the bottom row.
        pixels = vtk.numpy_support.numpy_to_vtk(
            np.ascontiguousarray(image[::-1].reshape(-1, 3)), deep=True, array_type=vtk.VTK_UNSIGNED_CHAR
        )
        pixels.SetNumberOfComponents(3)
        data.GetPointData().SetScalars(pixels)
        texture = vtk.vtkTexture()
        texture.SetInputData(data)
        texture.InterpolateOn()
        texture.MipmapOn()
        self.surface.SetTexture(texture)

    def set_pose(self, item2world: np.ndarray) -> None:
        self.item.item2world = np.asarray(item2world, dtype=float)
        m = vtk_matrix(self.item.item2world)
        self.surface.SetUserMatrix(m)
        if self._edges is not None:
            self._edges.SetUserMatrix(m)

    @property
    def edges(self) -> vtk.vtkActor:
        """Outline and crease edges (dihedral angle over 30 deg), the lines a CAD overlay shows."""
        if self._edges is None:
            fe = vtk.vtkFeatureEdges()
            fe.SetInputData(self.polydata)
            fe.BoundaryEdgesOn()
            fe.FeatureEdgesOn()
            fe.SetFeatureAngle(30.0)
            fe.ManifoldEdgesOff()
            fe.NonManifoldEdgesOff()
            fe.ColoringOff()
            fe.Update()
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(fe.GetOutput())
            mapper.ScalarVisibilityOff()
            self._edges = vtk.vtkActor()
            self._edges.SetMapper(mapper)
            self._edges.SetUserMatrix(vtk_matrix(self.item.item2world))
        return self._edges
