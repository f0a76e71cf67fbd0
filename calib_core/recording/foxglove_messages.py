"""Foxglove's own message schemas (protobuf, the ``foxglove-schemas-protobuf`` package) for what
its panels show from a recording: the camera's calibration, the robot's frames, the picks on the
image, the cell in 3D.

Foxglove works in metres and quaternions (x, y, z, w); videocal's poses are (4, 4) mm: every
conversion is here. The camera frame is OpenCV's (x right, y down, z forward), which is also
the optical frame Foxglove projects images with.
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.recording.schemas import (
    ANNOTATIONS_TOPIC,
    CALIBRATION_TOPIC,
    FOUND_TOPIC,
    SCENE_TOPIC,
    TRANSFORMS_TOPIC,
    VIDEO_TOPIC,
)

WORLD_FRAME = "world"
"""The root of the recorded frame tree: the cell's world (the robot's base frame)."""


def _classes() -> dict:
    from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
    from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo
    from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
    from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

    return {
        VIDEO_TOPIC: CompressedVideo,
        CALIBRATION_TOPIC: CameraCalibration,
        TRANSFORMS_TOPIC: FrameTransforms,
        ANNOTATIONS_TOPIC: ImageAnnotations,
        FOUND_TOPIC: ImageAnnotations,
        SCENE_TOPIC: SceneUpdate,
    }


def protobuf_schema(topic: str) -> tuple[str, bytes]:
    """Schema name and ``FileDescriptorSet`` bytes of the Foxglove message carried on ``topic``."""
    from mcap_protobuf.schema import build_file_descriptor_set

    classes = _classes()
    if topic not in classes:
        raise KeyError(f"no schema for topic {topic}")
    cls = classes[topic]
    return cls.DESCRIPTOR.full_name, build_file_descriptor_set(cls).SerializeToString()


def _stamp(message, t_ns: int) -> None:
    message.timestamp.FromNanoseconds(int(t_ns))


def _pose(target, T_mm: np.ndarray) -> None:
    """Fill a foxglove ``Pose`` (or the translation/rotation of a ``FrameTransform``) from (4, 4) mm."""
    x, y, z, w = Rotation.from_matrix(np.asarray(T_mm)[:3, :3]).as_quat()
    t = np.asarray(T_mm)[:3, 3] / 1000.0
    if hasattr(target, "position"):
        target.position.x, target.position.y, target.position.z = map(float, t)
        target.orientation.x, target.orientation.y, target.orientation.z, target.orientation.w = map(
            float, (x, y, z, w)
        )
    else:
        target.translation.x, target.translation.y, target.translation.z = map(float, t)
        target.rotation.x, target.rotation.y, target.rotation.z, target.rotation.w = map(float, (x, y, z, w))


def camera_calibration(intrinsics: Intrinsics, frame_id: str, t_ns: int):
    """``foxglove.CameraCalibration``: K, D (OpenCV order), R = I, P = [K | 0], size; the model is ``plumb_bob``,
    ``rational_polynomial`` or, for a fisheye (``equidistant``) lens, Foxglove's name for the same model,
    ``kannala_brandt`` (k1..k4)."""
    from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration

    d = [float(v) for v in intrinsics.distortion]
    model = {"equidistant": "kannala_brandt"}.get(intrinsics.model, intrinsics.model)
    fu, fv, cx, cy = map(float, (intrinsics.fu, intrinsics.fv, intrinsics.cx, intrinsics.cy))
    message = CameraCalibration(
        frame_id=frame_id,
        width=int(intrinsics.width),
        height=int(intrinsics.height),
        distortion_model=model,
        D=d,
        K=[fu, 0.0, cx, 0.0, fv, cy, 0.0, 0.0, 1.0],
        R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        P=[fu, 0.0, cx, 0.0, 0.0, fv, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
    )
    _stamp(message, t_ns)
    return message


def frame_transforms(tree, t_ns: int):
    """``foxglove.FrameTransforms`` from ``(parent, child, child2parent (4, 4) mm)``; a ``None``
    parent is the world."""
    from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms

    message = FrameTransforms()
    for parent, child, T in tree:
        ft = message.transforms.add(parent_frame_id=parent or WORLD_FRAME, child_frame_id=child)
        _stamp(ft, t_ns)
        _pose(ft, T)
    return message


_PICK = (0.23, 0.85, 0.33, 1.0)
_MODEL = (1.0, 0.55, 0.1, 1.0)
_STALE = (0.6, 0.6, 0.6, 1.0)


def _color(target, rgba) -> None:
    target.r, target.g, target.b, target.a = map(float, rgba)


def _corner_origin(uv) -> tuple[float, float]:
    """videocal's pixels (OpenCV: (0, 0) is the centre of the top-left pixel) in Foxglove's image
    coordinates, whose origin is the top-left pixel's top-left corner."""
    return float(uv[0]) + 0.5, float(uv[1]) + 0.5


def image_annotations(picks, t_ns: int, reprojected=None, stale_numbers=()):
    """``foxglove.ImageAnnotations`` on the camera image: ``picks`` ``[(number, (u, v) px)]`` (OpenCV
    pixels, shifted half a pixel to Foxglove's corner origin) as
    circles labelled with the pair numbers the window shows (grey when in ``stale_numbers``:
    picked at another robot state), and, after a solve, ``reprojected`` ``[(number, (u, v))]``
    model points as crosses with a line from each pick (the residual)."""
    from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations
    from foxglove_schemas_protobuf.PointsAnnotation_pb2 import PointsAnnotation

    message = ImageAnnotations()
    stale = set(stale_numbers)
    picked = {}
    for number, uv in picks:
        u, v = _corner_origin(uv)
        picked[number] = (u, v)
        circle = message.circles.add(diameter=14.0, thickness=2.0)
        _stamp(circle, t_ns)
        circle.position.x, circle.position.y = u, v
        _color(circle.outline_color, _STALE if number in stale else _PICK)
        text = message.texts.add(text=f"#{number}", font_size=14.0)
        _stamp(text, t_ns)
        text.position.x, text.position.y = u + 9.0, v - 9.0
        _color(text.text_color, _STALE if number in stale else _PICK)
        _color(text.background_color, (0, 0, 0, 0.6))
    if reprojected:
        crosses = message.points.add(type=PointsAnnotation.Type.LINE_LIST, thickness=2.0)
        residuals = message.points.add(type=PointsAnnotation.Type.LINE_LIST, thickness=1.0)
        for m in (crosses, residuals):
            _stamp(m, t_ns)
        _color(crosses.outline_color, _MODEL)
        _color(residuals.outline_color, (1.0, 0.2, 0.2, 1.0))
        for number, uv in reprojected:
            u, v = _corner_origin(uv)
            for du, dv in ((-6, -6), (6, 6), (-6, 6), (6, -6)):
                p = crosses.points.add()
                p.x, p.y = u + du, v + dv
            if number in picked:
                for x, y in (picked[number], (u, v)):
                    p = residuals.points.add()
                    p.x, p.y = x, y
    return message


_FOUND = (0.31, 0.78, 1.0, 1.0)
_EDGE = (1.0, 0.85, 0.2, 0.8)


def found_points_annotations(proposals, t_ns: int, edges_px=None):
    """``foxglove.ImageAnnotations`` of a Find points: ``proposals`` ``[(feature, (u, v) px)]`` as blue
    circles named after their features, and ``edges_px`` (m, 2) the image edge points its edge fit
    settled on, as small dots (OpenCV pixels, shifted to Foxglove's corner origin)."""
    from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations
    from foxglove_schemas_protobuf.PointsAnnotation_pb2 import PointsAnnotation

    message = ImageAnnotations()
    for feature, uv in proposals:
        u, v = _corner_origin(uv)
        circle = message.circles.add(diameter=12.0, thickness=2.0)
        _stamp(circle, t_ns)
        circle.position.x, circle.position.y = u, v
        _color(circle.outline_color, _FOUND)
        text = message.texts.add(text=str(feature), font_size=12.0)
        _stamp(text, t_ns)
        text.position.x, text.position.y = u + 8.0, v - 8.0
        _color(text.text_color, _FOUND)
        _color(text.background_color, (0, 0, 0, 0.6))
    if edges_px is not None and len(edges_px):
        dots = message.points.add(type=PointsAnnotation.Type.POINTS, thickness=2.0)
        _stamp(dots, t_ns)
        _color(dots.outline_color, _EDGE)
        for uv in np.asarray(edges_px, dtype=float):
            p = dots.points.add()
            p.x, p.y = _corner_origin(uv)
    return message


_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])
"""glTF is y-up and Foxglove turns a glTF model +90 deg about x to z-up: store z-up meshes turned back."""


def glb(mesh: trimesh.Trimesh) -> bytes:
    """A mesh (mm) as binary glTF in metres, oriented so Foxglove shows it as it is in the cell."""
    m = mesh.copy()
    m.apply_scale(1e-3)
    m.apply_transform(_Y_UP)
    return trimesh.Scene(m).export(file_type="glb")


def mesh_entity(entity_id: str, frame_id: str, mesh: trimesh.Trimesh, mesh2frame_mm: np.ndarray, color, t_ns: int):
    """A ``foxglove.SceneEntity`` drawing ``mesh`` at ``mesh2frame_mm`` in ``frame_id``, locked to
    that frame (it moves with the frame's transforms)."""
    from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity

    entity = SceneEntity(id=entity_id, frame_id=frame_id, frame_locked=True)
    _stamp(entity, t_ns)
    model = entity.models.add(media_type="model/gltf-binary", data=glb(mesh), override_color=True)
    _pose(model.pose, mesh2frame_mm)
    model.scale.x = model.scale.y = model.scale.z = 1.0
    rgba = tuple(color) + (1.0,) * (4 - len(tuple(color)))
    _color(model.color, rgba)
    return entity


def feature_entity(entity_id: str, points_mm: dict, t_ns: int):
    """The named features of a component (points in the world, mm) as spheres with labels."""
    from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity

    entity = SceneEntity(id=entity_id, frame_id=WORLD_FRAME, frame_locked=True)
    _stamp(entity, t_ns)
    for name, p in points_mm.items():
        sphere = entity.spheres.add()
        _pose(
            sphere.pose,
            np.block([[np.eye(3), np.asarray(p, float).reshape(3, 1)], [np.zeros((1, 3)), np.ones((1, 1))]]),
        )
        sphere.size.x = sphere.size.y = sphere.size.z = 0.006
        _color(sphere.color, _MODEL)
        text = entity.texts.add(text=name, billboard=True, font_size=12.0, scale_invariant=True)
        text.pose.position.x, text.pose.position.y, text.pose.position.z = (
            np.asarray(p, float) / 1000.0 + [0, 0, 0.008]
        ).tolist()
        text.pose.orientation.w = 1.0
        _color(text.color, (1, 1, 1, 1))
    return entity


def scene_update(entities):
    from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

    message = SceneUpdate()
    message.entities.extend(entities)
    return message
