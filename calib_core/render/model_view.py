"""The cell as the modelled camera sees it, lens distortion included: what Find points and the edge
refinement compare a camera frame with (which edges the model shows, where its faces differ).

A box of the image can be rendered alone (the target and a margin): the software renderer's time
goes with the pixels it fills, and Find points renders four to six views a call (a 400 x 300 box
takes a quarter of the whole 1280 x 960 image's time)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import cv2
import numpy as np

from calib_core.camera.distortion_map import distortion_map
from calib_core.camera.intrinsics import Intrinsics
from calib_core.render.renderer import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem
from calib_core.frames import concat, invert


class ModelView:
    """Renders ``items`` (the workcell and the modelled robot) through ``intrinsics``. Offscreen, one
    renderer kept for the object's life; :meth:`close` frees it."""

    def __init__(self, intrinsics: Intrinsics):
        self.intrinsics = intrinsics
        self._map = distortion_map(intrinsics)
        self._renderer: SceneRenderer | None = None
        self._items: list[SceneItem] | None = None

    def render(
        self,
        items: list[SceneItem],
        cam2world: np.ndarray,
        moved: dict[str, np.ndarray] | None = None,
        box_px: tuple[int, int, int, int] | None = None,
        supersample: float = 1,
    ) -> np.ndarray:
        """The image (h, w, 3) uint8 the modelled camera at ``cam2world`` (4, 4, mm) would take;
        ``moved``: items (by name) put at these poses (4, 4, mm) first (the renderer writes an item's
        pose into it: pass items of your own). ``box_px`` (u0, v0, u1, v1), px of the image, ends
        excluded: only that box is rendered, the rest of the image is black (no edges).
        ``supersample``: a whole number above 1 renders the box that many times finer and box-filters it
        down, as a camera's pixels integrate the light over their area (without it an edge a few degrees
        off the rows is a staircase of whole-pixel steps, and a face under a pixel wide shows or not: a
        corner measured against such a view came out 0.9 px off); a fraction (0.5) renders it coarser and
        interpolates it up, for a view that only has to say where edges are."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self._map.ideal.width, self._map.ideal.height)
        if items is not self._items:
            self._renderer.set_items(items)
            self._items = items
        for name, pose in (moved or {}).items():
            self._renderer.set_pose(name, pose)
        options = RenderOptions(show_edges=False)
        if box_px is None:
            return self._map.apply(self._renderer.render_view(self._map.ideal, cam2world, options))
        w, h = self.intrinsics.width, self.intrinsics.height
        u0, v0 = max(int(box_px[0]), 0), max(int(box_px[1]), 0)
        u1, v1 = min(int(box_px[2]), w), min(int(box_px[3]), h)
        out = np.zeros((h, w, 3), dtype=np.uint8)
        if u1 <= u0 or v1 <= v0:
            return out
        # the ideal (undistorted) pixels the box samples, and a pinhole camera that sees just them
        map_x, map_y = self._map.map_x[v0:v1, u0:u1], self._map.map_y[v0:v1, u0:u1]
        ideal = self._map.ideal
        a0, b0 = max(int(np.floor(map_x.min())) - 2, 0), max(int(np.floor(map_y.min())) - 2, 0)
        a1, b1 = min(int(np.ceil(map_x.max())) + 3, ideal.width), min(int(np.ceil(map_y.max())) + 3, ideal.height)
        part = Intrinsics(ideal.fu, ideal.fv, ideal.cx - a0, ideal.cy - b0, a1 - a0, b1 - b0)
        image = self._renderer.render_view(part.scaled(supersample) if supersample != 1 else part, cam2world, options)
        if supersample > 1:  # an exact box filter for an integer factor
            image = cv2.resize(image, (part.width, part.height), interpolation=cv2.INTER_AREA)
        elif supersample < 1:
            image = cv2.resize(image, (part.width, part.height), interpolation=cv2.INTER_LINEAR)
        out[v0:v1, u0:u1] = cv2.remap(
            image, map_x - a0, map_y - b0, interpolation=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        return out

    def of(
        self,
        items: list[SceneItem],
        item2world: np.ndarray,
        riding: frozenset[str] = frozenset(),
        cam2world_model: np.ndarray | None = None,
    ) -> Callable[[np.ndarray], np.ndarray]:
        """``expected(obj2cam, box_px=None, supersample=1) -> image`` for an object at ``item2world``: the
        view with the object at ``obj2cam`` from the camera (the camera placed accordingly; ``box_px`` and
        ``supersample`` as :meth:`render`'s). ``riding``: the names of the items
        that move with the camera (the gripper and its fingers on the camera's link), which the model
        places relative to the camera at ``cam2world_model``: they go with the camera, not stay in the
        cell (a robot's error moves the camera 10-20 mm from where the model puts it, and the fingers
        with it, 40-90 px at a task location)."""
        if cam2world_model is None or not riding:
            return lambda obj2cam, box_px=None, supersample=1: self.render(
                items, concat(invert(obj2cam), item2world), box_px=box_px, supersample=supersample
            )
        own = {i.name: np.array(i.item2world, dtype=float) for i in items if i.name in riding}
        scene = [
            replace(i, item2world=own[i.name].copy()) if i.name in own else i for i in items
        ]  # the caller's items keep their poses
        world2cam_model = invert(cam2world_model)

        def expected(
            obj2cam: np.ndarray, box_px: tuple[int, int, int, int] | None = None, supersample: float = 1
        ) -> np.ndarray:
            cam2world = concat(invert(obj2cam), item2world)
            carry = concat(world2cam_model, cam2world)  # the modelled camera onto the one placed here
            return self.render(
                scene, cam2world, {name: concat(pose, carry) for name, pose in own.items()}, box_px, supersample
            )

        return expected

    def of_cell(
        self,
        components: list[SceneItem],
        visuals,
        q_deg,
        item2world: np.ndarray,
        camera_frame: str = "camera",
        extras: list[SceneItem] = (),
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
