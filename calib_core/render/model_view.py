"""The cell as the modelled camera sees it, lens distortion included: what Find points and the edge
refinement compare a camera frame with (which edges the model shows, where its faces differ)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from calib_core.camera.distortion_map import distortion_map
from calib_core.camera.intrinsics import Intrinsics
from calib_core.render.renderer import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem


class ModelView:
    """Renders ``items`` (the workcell and the modelled robot) through ``intrinsics``. Offscreen, one
    renderer kept for the object's life; :meth:`close` frees it."""

    def __init__(self, intrinsics: Intrinsics):
        self.intrinsics = intrinsics
        self._map = distortion_map(intrinsics)
        self._renderer: SceneRenderer | None = None
        self._items: list[SceneItem] | None = None

    def render(self, items: list[SceneItem], cam2world: np.ndarray, moved: dict[str, np.ndarray] | None = None) -> np.ndarray:
        """The image (h, w, 3) uint8 the modelled camera at ``cam2world`` (4, 4, mm) would take;
        ``moved``: items (by name) put at these poses (4, 4, mm) first (the renderer writes an item's
        pose into it: pass items of your own)."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self._map.ideal.width, self._map.ideal.height)
        if items is not self._items:
            self._renderer.set_items(items)
            self._items = items
        for name, pose in (moved or {}).items():
            self._renderer.set_pose(name, pose)
        return self._map.apply(self._renderer.render_view(self._map.ideal, cam2world, RenderOptions(show_edges=False)))

    def of(self, items: list[SceneItem], item2world: np.ndarray, riding: frozenset[str] = frozenset(), cam2world_model: np.ndarray | None = None
           ) -> Callable[[np.ndarray], np.ndarray]:
        """``expected(obj2cam) -> image`` for an object at ``item2world``: the view with the object at
        ``obj2cam`` from the camera (the camera placed accordingly). ``riding``: the names of the items
        that move with the camera (the gripper and its fingers on the camera's link), which the model
        places relative to the camera at ``cam2world_model``: they go with the camera, not stay in the
        cell (a robot's error moves the camera 10-20 mm from where the model puts it, and the fingers
        with it, 40-90 px at a task location)."""
        if cam2world_model is None or not riding:
            return lambda obj2cam: self.render(items, item2world @ np.linalg.inv(obj2cam))
        own = {i.name: np.array(i.item2world, dtype=float) for i in items if i.name in riding}
        scene = [replace(i, item2world=own[i.name].copy()) if i.name in own else i for i in items]  # the caller's items keep their poses
        world2cam_model = np.linalg.inv(cam2world_model)

        def expected(obj2cam: np.ndarray) -> np.ndarray:
            cam2world = item2world @ np.linalg.inv(obj2cam)
            carry = cam2world @ world2cam_model  # the modelled camera onto the one placed here
            return self.render(scene, cam2world, {name: carry @ pose for name, pose in own.items()})

        return expected

    def of_cell(self, components: list[SceneItem], visuals, q_deg, item2world: np.ndarray, camera_frame: str = "camera", extras: list[SceneItem] = ()
                ) -> Callable[[np.ndarray], np.ndarray]:
        """:meth:`of` for the cell's ``components`` and a robot's ``visuals``
        (:class:`~calib_core.robot.visuals.RobotVisuals`) at joints ``q_deg``, plus ``extras``: what
        rides on ``camera_frame``'s joint goes with the camera."""
        items = list(components) + visuals.scene_items(q_deg) + list(extras)
        return self.of(items, item2world, visuals.riding_with(camera_frame), visuals.robot.fk(q_deg, camera_frame))

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
