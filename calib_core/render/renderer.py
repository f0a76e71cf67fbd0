"""Offscreen rendering of scene items from the virtual (calibrated) camera or an overview camera,
with read-back of colour and depth, and picking.

One code path everywhere: an offscreen render window (OSMesa or EGL without a display, the
normal window class on a desktop); the panes show the returned images. Multisampling is off.
"""

from __future__ import annotations

import threading

from dataclasses import dataclass, field

import numpy as np
from calib_core.render import vtk_api as vtk
from calib_core.render.vtk_api import numpy_support

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.render.virtual_camera import depth_from_zbuffer, set_vtk_camera
from calib_core.render.studio import Studio, light_with
from calib_core.render.vtk_scene import ItemActor
from calib_core.scene import SceneItem

STYLES = ("surface", "wireframe", "edges")


@dataclass
class RenderOptions:
    """How to draw. ``highlight``: a component drawn in ``highlight_color``; ``show_features``:
    feature points of components as dots (``feature_size_px``), with names when
    ``feature_names``; ``style``: ``surface``, ``wireframe`` or ``edges`` (outlines only, for
    overlaying on video); ``background`` RGB in [0, 1]; ``transparent_background`` returns RGBA
    with alpha 0 where nothing was drawn; ``hidden`` item names not drawn; ``markers``: extra
    points (3,) mm in the world frame with RGB colours, e.g. picked points."""

    highlight: str | None = None
    highlight_color: tuple[float, float, float] = (1.0, 0.55, 0.1)
    show_features: bool = False
    feature_names: bool = False
    feature_size_px: float = 7.0
    style: str = "surface"
    background: tuple[float, float, float] = (0.13, 0.14, 0.16)
    transparent_background: bool = False
    hidden: frozenset[str] = frozenset()
    markers: list[tuple[np.ndarray, tuple[float, float, float]]] = field(default_factory=list)
    edge_color: tuple[float, float, float] = (0.2, 1.0, 0.4)
    show_edges: bool = True
    label_color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    lines: list[tuple[np.ndarray, tuple[float, float, float]]] = field(default_factory=list)


@dataclass(frozen=True)
class PickResult:
    """What a pixel of a virtual-camera render shows. ``component``: the item hit;
    ``point_component_mm`` (3,) in its frame, ``point_world_mm`` (3,); ``feature``: the named
    feature snapped to (then the points are the feature's) or ``None``; ``distance_px`` from
    the clicked pixel to the feature's pixel (0 without snapping)."""

    component: str
    point_component_mm: np.ndarray
    point_world_mm: np.ndarray
    feature: str | None
    distance_px: float


GL_TURNS = threading.RLock()
"""Every render, read-back and context of the process takes its turn here: OpenGL through OSMesa and VTK's GL state are
shared by the process, and two renders at once on two threads (the simulated camera's worker and the window's
overview) crashed the window (a segmentation fault inside both ``Render`` calls)."""


class SceneRenderer:
    """Renders a set of scene items offscreen. One object is used from one thread; objects on several threads take turns
    at the GL (:data:`GL_TURNS`)."""

    def __init__(self, width: int = 640, height: int = 480):
        self.window = vtk.vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetMultiSamples(0)
        self.window.SetAlphaBitPlanes(1)
        self.window.SetSize(width, height)
        self.renderer = vtk.vtkRenderer()
        self.window.AddRenderer(self.renderer)
        self.renderer.SetUseFXAA(False)
        # Edges drawn on top of their own surfaces must win the depth test.
        vtk.vtkMapper.SetResolveCoincidentTopologyToPolygonOffset()
        self._actors: dict[str, ItemActor] = {}
        self._overlay_actors: list[vtk.vtkProp] = []
        self._last: tuple[Intrinsics, np.ndarray] | None = None
        self._material = (0.25, 0.75, 0.15, 1.0)  # ambient, diffuse, specular, specular power
        self._lights()

    # --- scene -------------------------------------------------------------------------
    def set_items(self, items: list[SceneItem]) -> None:
        """Replace the scene. Items keep their actors when their mesh object is unchanged."""
        old = self._actors
        self._actors = {}
        self.renderer.RemoveAllViewProps()
        for item in items:
            actor = old.get(item.name)
            if actor is None or actor.item.mesh is not item.mesh:
                actor = ItemActor(item)
            else:
                actor.item = item
                actor.set_pose(item.item2world)
            self._actors[item.name] = actor

    def set_pose(self, name: str, item2world: np.ndarray) -> None:
        self._actors[name].set_pose(item2world)

    def items(self) -> list[SceneItem]:
        return [a.item for a in self._actors.values()]

    def _lights(self, intensity: float = 1.0, key_direction=(0.4, -0.6, 1.0)) -> None:
        self.renderer.RemoveAllLights()
        head = vtk.vtkLight()
        head.SetLightTypeToHeadlight()
        head.SetIntensity(0.55 * intensity)
        self.renderer.AddLight(head)
        key = vtk.vtkLight()
        key.SetLightTypeToSceneLight()
        key.SetPositional(False)
        key.SetPosition(*key_direction)
        key.SetFocalPoint(0, 0, 0)
        key.SetIntensity(0.6 * intensity)
        self.renderer.AddLight(key)

    def set_lighting(self, intensity: float = 1.0, key_direction=(0.4, -0.6, 1.0)) -> None:
        """Change the lights (the simulated camera uses other light than the CAD views)."""
        self._lights(intensity, key_direction)

    def set_studio(self, studio: Studio) -> None:
        """Light the scene by ``studio``'s lamps, with their shadows and glossy surfaces (a workshop, not a CAD
        view)."""
        light_with(self.renderer, studio)
        self._material = (studio.ambient, 1.0 - studio.ambient, studio.specular, studio.specular_power)

    # --- drawing -----------------------------------------------------------------------
    def _style(self, options: RenderOptions) -> None:
        if options.style not in STYLES:
            raise ValueError(f"style must be one of {', '.join(STYLES)}, got {options.style!r}")
        self.renderer.RemoveAllViewProps()
        for name, actor in self._actors.items():
            if name in options.hidden:
                continue
            highlighted = name == options.highlight
            # A highlight tints the component rather than repainting it, so its shading still shows its shape.
            color = (
                tuple(0.45 * c + 0.55 * h for c, h in zip(actor.item.color, options.highlight_color))
                if highlighted
                else actor.item.color
            )
            if options.style == "edges":
                a = actor.edges
                a.GetProperty().SetColor(
                    *(options.highlight_color if name == options.highlight else options.edge_color)
                )
                a.GetProperty().SetLineWidth(2.0 if name == options.highlight else 1.0)
                a.GetProperty().LightingOff()
                self.renderer.AddActor(a)
                continue
            a = actor.surface
            prop = a.GetProperty()
            prop.SetColor(*color)
            prop.SetOpacity(actor.item.opacity)
            ambient, diffuse, specular, power = self._material
            prop.SetAmbient(ambient)
            prop.SetDiffuse(diffuse)
            prop.SetSpecular(specular)
            prop.SetSpecularPower(power)
            if options.style == "wireframe":
                prop.SetRepresentationToWireframe()
            else:
                prop.SetRepresentationToSurface()
            self.renderer.AddActor(a)
            if (
                options.show_edges
                and options.style == "surface"
                and actor.item.kind not in ("fixture", "ghost")
                or highlighted
            ):
                e = actor.edges
                e.GetProperty().SetColor(
                    *((0.55, 0.25, 0.0) if highlighted else tuple(0.35 * c for c in actor.item.color))
                )
                e.GetProperty().SetLineWidth(1.5 if highlighted else 1.0)
                e.GetProperty().LightingOff()
                self.renderer.AddActor(e)
        self._add_points(options)
        self._add_lines(options)
        if options.transparent_background:
            self.renderer.SetBackground(0, 0, 0)
            self.renderer.SetBackgroundAlpha(0.0)
        else:
            self.renderer.SetBackground(*options.background)
            self.renderer.SetBackgroundAlpha(1.0)

    def _add_points(self, options: RenderOptions) -> None:
        groups: list[tuple[np.ndarray, tuple[float, float, float], list[str]]] = []
        if options.show_features:
            for name, actor in self._actors.items():
                item = actor.item
                if item.features and name not in options.hidden and item.kind == "component":
                    pts = apply(item.item2world, np.array(list(item.features.values())))
                    color = (1.0, 0.85, 0.1) if name == options.highlight else (0.35, 0.75, 1.0)
                    groups.append((pts, color, list(item.features) if options.feature_names else []))
        for point, color in options.markers:
            groups.append((np.asarray(point, dtype=float).reshape(1, 3), color, []))
        for pts, color, labels in groups:
            poly = vtk.vtkPolyData()
            vpts = vtk.vtkPoints()
            vpts.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(pts), deep=True))
            poly.SetPoints(vpts)
            verts = vtk.vtkCellArray()
            for i in range(len(pts)):
                verts.InsertNextCell(1)
                verts.InsertCellPoint(i)
            poly.SetVerts(verts)
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(poly)
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            prop = actor.GetProperty()
            prop.SetColor(*color)
            prop.SetPointSize(options.feature_size_px)
            prop.SetRenderPointsAsSpheres(True)
            prop.LightingOff()
            self.renderer.AddActor(actor)
            for p, text in zip(pts, labels):
                label = vtk.vtkBillboardTextActor3D()
                label.SetInput(text)
                label.SetPosition(*p)
                label.SetDisplayOffset(6, 6)
                label.GetTextProperty().SetFontSize(13)
                label.GetTextProperty().SetColor(*options.label_color)
                label.GetTextProperty().ShadowOn()
                self.renderer.AddActor(label)

    def _add_lines(self, options: RenderOptions) -> None:
        """Polylines ((k, 3) mm, world frame) such as camera frustums."""
        for points, color in options.lines:
            pts = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 3))
            poly = vtk.vtkPolyData()
            vpts = vtk.vtkPoints()
            vpts.SetData(numpy_support.numpy_to_vtk(pts, deep=True))
            poly.SetPoints(vpts)
            cells = vtk.vtkCellArray()
            cells.InsertNextCell(len(pts))
            for i in range(len(pts)):
                cells.InsertCellPoint(i)
            poly.SetLines(cells)
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(poly)
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            actor.GetProperty().SetColor(*color)
            actor.GetProperty().SetLineWidth(2.0)
            actor.GetProperty().LightingOff()
            self.renderer.AddActor(actor)

    def _read_back(self, transparent: bool) -> np.ndarray:
        w, h = self.window.GetSize()
        self.window.MakeCurrent()
        arr = vtk.vtkUnsignedCharArray()
        self.window.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, arr)
        img = numpy_support.vtk_to_numpy(arr).reshape(h, w, 4)[::-1]
        return np.ascontiguousarray(img if transparent else img[:, :, :3])

    def render_view(
        self, intrinsics: Intrinsics, cam2world: np.ndarray, options: RenderOptions | None = None
    ) -> np.ndarray:
        """The image (h, w, 3) uint8 RGB (RGBA with a transparent background) seen by the
        calibrated camera at ``cam2world`` (4, 4, mm, OpenCV axes), without lens distortion."""
        options = options or RenderOptions()
        with GL_TURNS:
            self.window.SetSize(intrinsics.width, intrinsics.height)
            self._style(options)
            set_vtk_camera(self.renderer.GetActiveCamera(), intrinsics, cam2world)
            self.window.Render()
            self._last = (intrinsics, np.asarray(cam2world, dtype=float))
            return self._read_back(options.transparent_background)

    def render_overview(
        self,
        eye_mm=(-1900.0, -2300.0, 2900.0),
        target_mm=(700.0, 0.0, 800.0),
        *,
        width: int = 800,
        height: int = 600,
        view_angle_deg: float = 40.0,
        up=(0.0, 0.0, 1.0),
        options: RenderOptions | None = None,
    ) -> np.ndarray:
        """The image (h, w, 3) uint8 from an ordinary perspective camera at ``eye_mm`` looking at ``target_mm``."""
        options = options or RenderOptions()
        with GL_TURNS:
            self.window.SetSize(width, height)
            self._style(options)
            cam = self.renderer.GetActiveCamera()
            cam.SetUseExplicitProjectionTransformMatrix(False)
            cam.SetPosition(*eye_mm)
            cam.SetFocalPoint(*target_mm)
            cam.SetViewUp(*up)
            cam.SetViewAngle(view_angle_deg)
            cam.SetWindowCenter(0.0, 0.0)
            self.renderer.ResetCameraClippingRange()
            self.window.Render()
            self._last = None
            return self._read_back(options.transparent_background)

    def depth_mm(self) -> np.ndarray:
        """Camera-frame depth Z (h, w) mm of the last virtual-camera render; inf on the background."""
        if self._last is None:
            raise RuntimeError("depth is available after render_view only")
        w, h = self.window.GetSize()
        z = vtk.vtkFloatArray()
        with GL_TURNS:
            self.window.MakeCurrent()  # several render windows share the thread: read this one's buffers
            self.window.GetZbufferData(0, 0, w - 1, h - 1, z)
        zbuf = numpy_support.vtk_to_numpy(z).reshape(h, w)[::-1]
        return depth_from_zbuffer(zbuf)

    # --- picking -----------------------------------------------------------------------
    def pick(
        self, u: float, v: float, *, snap_radius_px: float = 12.0, components: set[str] | None = None
    ) -> PickResult | None:
        """What pixel ``(u, v)`` of the last virtual-camera render shows.

        The nearest visible named feature within ``snap_radius_px`` wins (so a click just
        beside a corner still takes the corner); otherwise the surface point hit. Only items of
        kind ``component`` are picked, and only those in ``components`` when given (the
        calibration's target object). ``None`` when nothing pickable is there."""
        if self._last is None:
            raise RuntimeError("pick works on the last render_view")
        allowed = [
            a.item
            for a in self._actors.values()
            if a.item.kind == "component" and (components is None or a.item.name in components)
        ]
        snapped = self._snap(u, v, snap_radius_px, allowed)
        if snapped is not None:
            return snapped
        name, world = self._ray_hit(u, v)
        if name is None or all(item.name != name for item in allowed):
            return None
        hit = self._actors[name].item
        return PickResult(hit.name, apply(invert(hit.item2world), world), world, None, 0.0)

    def _ray_hit(self, u: float, v: float) -> tuple[str | None, np.ndarray | None]:
        _, h = self.window.GetSize()
        picker = vtk.vtkCellPicker()
        picker.SetTolerance(0.0)
        for actor in self._actors.values():
            picker.AddPickList(actor.surface)
        picker.PickFromListOn()
        with GL_TURNS:
            self.window.MakeCurrent()
            if not picker.Pick(u + 0.5, h - (v + 0.5), 0.0, self.renderer):
                return None, None
        hit = picker.GetActor()
        name = next((n for n, a in self._actors.items() if a.surface is hit), None)
        return name, np.array(picker.GetPickPosition())

    def _snap(self, u: float, v: float, radius_px: float, items: list[SceneItem]) -> PickResult | None:
        """The nearest feature of ``items`` within ``radius_px`` of the pixel that is not hidden
        behind something else (its depth matches the depth buffer)."""
        if radius_px <= 0 or not items:
            return None
        intrinsics, cam2world = self._last
        world2cam = invert(cam2world)
        depth = None
        best: tuple[float, SceneItem, str] | None = None
        for item in items:
            names = list(item.features)
            if not names:
                continue
            pts_cam = apply(world2cam, apply(item.item2world, np.array([item.features[k] for k in names])))
            px = project(pts_cam, intrinsics, distort=False)
            d = np.hypot(px[:, 0] - u, px[:, 1] - v)
            for k in np.flatnonzero(d <= radius_px):
                if best is not None and d[k] >= best[0]:
                    continue
                if depth is None:
                    depth = self.depth_mm()
                col, row = int(round(px[k, 0])), int(round(px[k, 1]))
                if not (0 <= row < depth.shape[0] and 0 <= col < depth.shape[1]):
                    continue
                # Visible if nothing nearer than the feature covers its pixel (slack for edges and markers).
                window = depth[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2]
                if pts_cam[k, 2] <= window.max() + max(3.0, 0.02 * pts_cam[k, 2]):
                    best = (float(d[k]), item, names[k])
        if best is None:
            return None
        d, item, feature = best
        point = np.asarray(item.features[feature], dtype=float)
        return PickResult(item.name, point, apply(item.item2world, point), feature, d)

    def close(self) -> None:
        with GL_TURNS:
            self.window.Finalize()
