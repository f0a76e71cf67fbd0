"""The simulated gripper camera: what a real camera on the *true* robot would see.

Renders the workcell and robot from the true camera pose with lighting unlike the CAD
views, applies the lens distortion, vignetting, sensor noise and optional blur;
deterministic for a seed. It is a :class:`FrameSource` like any camera, and it reports its
ground truth for tests.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.render.studio import Studio
from calib_core.scene import SceneItem
from calib_core.camera.distortion_map import distortion_map
from calib_core.connectors.frame import Frame, FrameSource


AT_REST_DEG = 0.01
"""Joints that moved no more than this during a render (deg) count as at rest for the live video's integrated
frame: a controller's last samples on the way in differ by a thousandth of a degree (0.0013 deg seen under load),
and a frame point-sampled there could be measured on (the robot counts as settled) while aliasing a board's squares."""


@dataclass(frozen=True)
class CameraLook:
    """Image formation beyond geometry: ``noise_sigma`` (grey levels), ``blur_sigma_px`` (0: none),
    ``vignetting`` (relative darkening at the corners), ``gain`` and ``light_direction`` (of
    the key light, world frame) so the image does not look like the CAD render."""

    noise_sigma: float = 2.5
    blur_sigma_px: float = 0.0
    vignetting: float = 0.25
    gain: float = 0.92
    light_direction: tuple[float, float, float] = (-0.5, 0.4, 0.8)
    light_intensity: float = 0.8
    background: tuple[float, float, float] = (0.30, 0.31, 0.33)
    studio: Studio | None = None
    """Lamps that cast shadows and glossy surfaces (:func:`videocal_sim.real_look.real_camera_look`) instead of the
    key light; ``None``: the key light (``light_direction``, ``light_intensity``)."""
    supersample: int | None = None
    """Samples per pixel side (``None``: enough for a render at least :data:`FINE_WIDTH_PX` wide, at
    most 8). A sensor integrates the light over each pixel, a renderer samples the pixel's centre:
    point samples give stair-stepped edges whose offset is shared along an edge, and they tilted edge
    fits by 0.4-1.2 mrad at 1280 px and up to 3 mrad at 640 px, the same way in every view. Measured
    at 1280 px: 2 samples leave 0.1-0.17 mrad, 4 leave 0.05; at 640 px 2 leave 3.2 mrad, 4 leave 0.5."""


@dataclass(frozen=True)
class CameraTruth:
    """Ground truth of one simulated frame: the true ``cam2world`` (4, 4) mm, the commanded
    joints (deg) and the true intrinsics."""

    cam2world: np.ndarray
    q_commanded_deg: np.ndarray
    intrinsics: Intrinsics


FINE_WIDTH_PX = 2560
"""The width the automatic supersampling renders at, whatever the camera's resolution: the edges'
residual steps are then the same size in the scene (0.1 mrad on the cold cell's fixtures)."""


def samples_per_pixel(look: CameraLook, width_px: int) -> int:
    """The supersampling ``look`` asks for at an image ``width_px`` wide."""
    if look.supersample is not None:
        return max(1, int(look.supersample))
    return int(min(8, max(1, -(-FINE_WIDTH_PX // max(int(width_px), 1)))))


def supersampled(intrinsics: Intrinsics, samples: int) -> Intrinsics:
    """``intrinsics`` (no distortion) of a canvas with ``samples`` x ``samples`` pixels for each of
    ``intrinsics``' (pixel centres at integers: the coarse pixel ``u`` covers the fine ones
    ``samples * u + 0 .. samples - 1``, whose mean centre is ``samples * u + (samples - 1) / 2``)."""
    if samples == 1:
        return intrinsics
    shift = (samples - 1) / 2.0
    return Intrinsics(
        intrinsics.fu * samples,
        intrinsics.fv * samples,
        intrinsics.cx * samples + shift,
        intrinsics.cy * samples + shift,
        intrinsics.width * samples,
        intrinsics.height * samples,
    )


class SimulatedCamera(FrameSource):
    """Frames of the test bed's camera. ``scene_at(q)`` gives the scene items at commanded
    joints (workcell plus true robot), ``cam2world_at(q)`` the true camera pose, ``joints()``
    the current commanded joints (deg)."""

    description = "simulated camera"

    def __init__(
        self,
        intrinsics: Intrinsics,
        scene_at: Callable[[np.ndarray], list[SceneItem]],
        cam2world_at: Callable[[np.ndarray], np.ndarray],
        joints: Callable[[], np.ndarray],
        *,
        fps: float = 15.0,
        look: CameraLook | None = None,
        seed: int = 0,
        coarse_while_moving: bool = False,
    ):
        self.intrinsics = intrinsics
        self._scene_at = scene_at
        self._cam2world_at = cam2world_at
        self._joints = joints
        self._fps = float(fps)
        self.look = look or CameraLook()
        self._rng = np.random.default_rng(seed)
        self._map = distortion_map(intrinsics)
        self._renderers: dict[int, SceneRenderer] = {}
        self._index = 0
        self._vignette = self._vignette_mask()
        self._last_ideal: tuple | None = None
        self.coarse_while_moving = coarse_while_moving
        """Live video: a frame of a scene that changed since the last one (the robot moving) is point
        sampled, unless the joints did not change during that render; the next one of the same scene
        integrated. Frames of a moving robot are never measured
        on (a pick or a view needs it settled), and 16 samples a pixel at 15 fps take a core."""
        self.last_truth: CameraTruth | None = None

    @property
    def fps(self) -> float:
        return self._fps

    def _vignette_mask(self) -> np.ndarray:
        h, w = self.intrinsics.height, self.intrinsics.width
        y, x = np.mgrid[0:h, 0:w]
        r2 = ((x - self.intrinsics.cx) / (w / 2)) ** 2 + ((y - self.intrinsics.cy) / (h / 2)) ** 2
        return (self.look.gain * (1.0 - self.look.vignetting * np.clip(r2 / 2.0, 0, 1)))[..., None].astype(np.float32)

    def render(self, q_commanded_deg: np.ndarray) -> tuple[np.ndarray, CameraTruth]:
        """One image (h, w, 3) uint8 RGB at the given commanded joints, with its truth."""
        q = np.asarray(q_commanded_deg, dtype=float)
        items = self._scene_at(q)
        cam2world = self._cam2world_at(q)
        ideal = self._ideal_render(items, cam2world)
        moved_during_render = float(np.max(np.abs(np.asarray(self._joints(), dtype=float) - q), initial=0.0))
        if (
            self._last_ideal[2] < samples_per_pixel(self.look, self._map.ideal.width)
            and moved_during_render <= AT_REST_DEG
        ):
            # Point-sampled because the scene changed, yet the robot did not move during that render:
            # it may have come to rest, and the first frame at rest must be integrated too (a slow
            # machine can deliver it after the robot has been still long enough to be measured on).
            # (Its last samples on the way in may still differ by a thousandth of a degree: at rest too.)
            ideal = self._ideal_render(items, cam2world, integrate=True)
        image = self._map.apply(ideal).astype(np.float32) * self._vignette
        if self.look.blur_sigma_px > 0:
            image = cv2.GaussianBlur(image, (0, 0), self.look.blur_sigma_px)
        if self.look.noise_sigma > 0:
            image += self._rng.normal(0.0, self.look.noise_sigma, image.shape).astype(np.float32)
        image = np.clip(image, 0, 255).astype(np.uint8)
        return image, CameraTruth(cam2world, q, self.intrinsics)

    def _ideal_render(self, items: list[SceneItem], cam2world: np.ndarray, *, integrate: bool = False) -> np.ndarray:
        """The scene through the ideal (undistorted) lens, each pixel the mean of its samples; the
        last one again while neither the scene nor the camera moved (a robot at rest costs no render:
        only the noise is new)."""
        key = (
            cam2world.tobytes(),
            tuple(
                (
                    i.name,
                    id(i.mesh),
                    np.asarray(i.item2world).tobytes(),
                    tuple(map(float, i.color)),
                    float(i.opacity),
                    id(i.texture),
                )
                for i in items
            ),
        )
        same_scene = self._last_ideal is not None and self._last_ideal[0] == key
        ideal_intrinsics = self._map.ideal
        samples = samples_per_pixel(self.look, ideal_intrinsics.width)
        if self.coarse_while_moving and not same_scene and not integrate:
            samples = 1
        if same_scene and self._last_ideal[2] >= samples:
            return self._last_ideal[1]
        fine = supersampled(ideal_intrinsics, samples)
        renderer = self._renderers.get(samples)
        if renderer is None:  # one per sample count: a coarse and a fine one while live
            renderer = self._renderers[samples] = SceneRenderer(fine.width, fine.height)
            if self.look.studio is not None:
                renderer.set_studio(self.look.studio)
            else:
                renderer.set_lighting(self.look.light_intensity, self.look.light_direction)
        renderer.set_items(items)
        ideal = renderer.render_view(fine, cam2world, RenderOptions(background=self.look.background, show_edges=False))
        if samples > 1:  # an exact box filter for an integer factor
            ideal = cv2.resize(ideal, (ideal_intrinsics.width, ideal_intrinsics.height), interpolation=cv2.INTER_AREA)
        self._last_ideal = (key, ideal, samples)
        return ideal

    def read(self) -> Frame | None:
        # The exposure is the moment the robot's pose is taken; the render after it is the camera's
        # latency. The frame carries the exposure time, as a camera's capture timestamp does.
        t_capture = time.monotonic()
        image, truth = self.render(self._joints())
        self.last_truth = truth
        frame = Frame(image, self._index, t_capture, self._index / self._fps if self._fps else None)
        self._index += 1
        return frame

    def close(self) -> None:
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers = {}
        self._last_ideal = None
