"""The topics of a videocal recording and their schemas.

JSON channels (message encoding ``json``) carry a complete JSON Schema (draft 2020-12) each, so
every field shows in Foxglove's field pickers and a validator can check every message. What
Foxglove's own panels show goes on protobuf channels with Foxglove's schemas (see
:mod:`calib_core.recording.foxglove_messages`). Times: the MCAP log time is Unix nanoseconds;
``t_host_s`` fields are the recording host's monotonic clock in seconds; ``t_ms`` the controller's.
Lengths are mm and angles degrees in videocal's JSON; Foxglove's messages use metres (its convention).
"""

from __future__ import annotations

import json

FRAME_TOPIC = "/camera/image/compressed"
VIDEO_TOPIC = "/camera/video"
"""Frames as H.264 (``foxglove.CompressedVideo``, protobuf): the default. ``FRAME_TOPIC`` carries
JPEG frames (``foxglove.CompressedImage``, JSON) when a recording is made with ``frames="jpeg"``;
a recording has only the one of the two it uses."""
CALIBRATION_TOPIC = "/camera/calibration"
ANNOTATIONS_TOPIC = "/camera/annotations"
FOUND_TOPIC = "/camera/found_points"
"""Find points' proposals and the edge samples its fit used (``foxglove.ImageAnnotations``), on the frame found on."""
TRANSFORMS_TOPIC = "/tf"
SCENE_TOPIC = "/videocal/scene"
JOINTS_TOPIC = "/robot/joints"
EVENT_TOPIC = "/videocal/events"
SOLVE_TOPIC = "/videocal/solves"
CORRECTION_TOPIC = "/videocal/corrections"
SETUP_TOPIC = "/videocal/setup"

_NUMBER = {"type": "number"}
_NULLABLE_NUMBER = {"type": ["number", "null"]}


def _vector(n: int | None = None, description: str = "", items: dict = _NUMBER) -> dict:
    v: dict = {"type": "array", "items": items}
    if n is not None:
        v.update(minItems=n, maxItems=n)
    if description:
        v["description"] = description
    return v


def _matrix(rows: int, cols: int, description: str) -> dict:
    return {"type": "array", "items": _vector(cols), "minItems": rows, "maxItems": rows, "description": description}


_TIME = {
    "type": "object",
    "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999},
    },
    "required": ["sec", "nsec"],
}
_POSE_MM = _matrix(4, 4, "homogeneous transform, mm")

INTRINSICS = {
    "type": "object",
    "description": "pinhole camera with OpenCV distortion, pixels",
    "properties": {
        "fu": _NUMBER,
        "fv": _NUMBER,
        "cx": _NUMBER,
        "cy": _NUMBER,
        "width": {"type": "integer"},
        "height": {"type": "integer"},
        "distortion": _vector(None, "OpenCV order k1 k2 p1 p2 [k3 [k4 k5 k6]]"),
    },
    "required": ["fu", "fv", "cx", "cy", "width", "height"],
}

COMPRESSED_IMAGE = {
    "title": "foxglove.CompressedImage",
    "type": "object",
    "description": "a JPEG camera frame; data is base64 in JSON encoding",
    "properties": {
        "timestamp": {**_TIME, "description": "when the frame was captured (exposure), Unix time"},
        "frame_id": {"type": "string", "description": "the camera's frame in /tf"},
        "data": {"type": "string", "contentEncoding": "base64"},
        "format": {"type": "string", "enum": ["jpeg", "png"]},
        "t_host_s": {"type": "number", "description": "capture time, host monotonic clock, s"},
    },
    "required": ["timestamp", "frame_id", "data", "format"],
}

JOINT_SAMPLE = {
    "title": "videocal.JointSample",
    "type": "object",
    "description": "one joint sample from the controller, in the model's joint order",
    "properties": {
        "seq": {"type": "integer", "description": "the controller's sample counter"},
        "t_ms": {"type": "integer", "description": "controller clock, ms"},
        "t_host_s": {"type": "number", "description": "host monotonic clock when received, s"},
        "joints_deg": _vector(None, "joint values, deg (mm for a prismatic joint)"),
    },
    "required": ["seq", "t_ms", "t_host_s", "joints_deg"],
}

EVENT = {
    "title": "videocal.Event",
    "type": "object",
    "description": "an operator or link event: pair edits (pair_added, pair_changed, pair_removed, pair_reset), "
    "link_state, move_*, frame_held, verified, ...",
    "properties": {
        "kind": {"type": "string"},
        "detail": {
            "type": "object",
            "description": "fields of the event; pair events carry the pair (number, target, feature, point_world_mm, "
            "pixel, view)",
        },
    },
    "required": ["kind", "detail"],
}

_STD = {
    "type": ["object", "null"],
    "description": "1-sigma of the solve, null when it could not be computed",
    "properties": {
        "t_obj2cam_mm": _vector(3, items=_NULLABLE_NUMBER),
        "rotation_deg": _vector(3, items=_NULLABLE_NUMBER),
        "camera_position_mm": _vector(3, items=_NULLABLE_NUMBER),
        "fu": _NULLABLE_NUMBER,
        "fv": _NULLABLE_NUMBER,
        "sigma_px": _NULLABLE_NUMBER,
        "sigma_source": {"type": ["string", "null"]},
    },
}

SOLVE_RESULT = {
    "type": "object",
    "description": "what the solve found (the fields of `videocal solve`)",
    "properties": {
        "status": {"type": "string"},
        "reason": {"type": ["string", "null"]},
        "model": {"type": "string"},
        "R_obj2cam": _matrix(3, 3, "rotation object to camera"),
        "t_obj2cam_mm": _vector(3, "object origin in the camera frame, mm", _NULLABLE_NUMBER),
        "camera_position_mm": _vector(3, "camera centre in the object frame, mm", _NULLABLE_NUMBER),
        "fu": _NULLABLE_NUMBER,
        "fv": _NULLABLE_NUMBER,
        "iterations": {"type": "integer"},
        "rms_px": _NULLABLE_NUMBER,
        "residuals_px": {
            "type": "array",
            "items": _vector(2, items=_NULLABLE_NUMBER),
            "description": "observed - reprojected, px, one row per pair",
        },
        "leave_one_out_px": _vector(None, items=_NULLABLE_NUMBER),
        "outliers": _vector(None, items={"type": "boolean"}),
        "misfits": {
            "type": ["array", "null"],
            "items": {"type": "boolean"},
            "description": "pairs that do not fit the others (likely mis-picks)",
        },
        "std": _STD,
        "condition_number": _NULLABLE_NUMBER,
        "candidates": {
            "type": "array",
            "items": {"type": "object"},
            "description": "poses that fit about as well, best first",
        },
        "warnings": _vector(None, items={"type": "string"}),
        "method": {
            "type": "string",
            "enum": ["points", "edges"],
            "description": "points: from the pairs; edges: from the target's edges on the image (residuals: one per "
            "edge sample)",
        },
    },
    "required": ["status", "R_obj2cam", "t_obj2cam_mm", "rms_px"],
}

SOLVE_INPUTS = {
    "type": "object",
    "description": "everything needed to solve again (the fields of `videocal solve`)",
    "properties": {
        "intrinsics": INTRINSICS,
        "points_3d": {"type": "array", "items": _vector(3), "description": "model points in the object frame, mm"},
        "points_2d": {"type": "array", "items": _vector(2), "description": "picked pixels"},
        "estimate_focal": {"type": "boolean"},
        "model": {"type": "string"},
        "sigma_px": _NULLABLE_NUMBER,
        "robust": {"type": "boolean"},
        "prior": {
            "type": "object",
            "properties": {"R_obj2cam": _matrix(3, 3, "prior rotation"), "t_obj2cam_mm": _vector(3)},
        },
        "method": {
            "type": "string",
            "enum": ["points", "edges"],
            "description": "edges: solved on the frame's image (no pairs: points_3d and points_2d are empty)",
        },
        "component": {"type": "string", "description": "with method edges: the target whose edges were used"},
        "frame_index": {"type": "integer", "description": "with method edges: the camera frame solved on"},
    },
    "required": ["intrinsics", "points_3d", "points_2d"],
}

SOLVE = {
    "title": "videocal.Solve",
    "type": "object",
    "description": "a solve's complete inputs, its result, and the context that turns it into an end-effector estimate",
    "properties": {
        "id": {"type": "integer", "description": "1, 2, ... in the recording"},
        "inputs": SOLVE_INPUTS,
        "result": SOLVE_RESULT,
        "context": {
            "type": "object",
            "properties": {
                "obj2world": _POSE_MM,
                "cam2world_model": _POSE_MM,
                "tcp2base_model": _POSE_MM,
                "joints_deg": _vector(None, "the joints the pairs were picked at"),
                "target": {"type": "string"},
            },
        },
    },
    "required": ["id", "inputs", "result"],
}

CORRECTION = {
    "title": "videocal.Correction",
    "type": "object",
    "description": "a stored correction of a task location: measured minus modelled end effector",
    "properties": {
        "task": {"type": "string"},
        "displacement_mm": _vector(3, "measured TCP position - model, base frame, mm"),
        "rotation_deg": _vector(3, "rotation vector measured vs model, deg"),
        "std_displacement_mm": _vector(3, items=_NULLABLE_NUMBER),
        "std_rotation_deg": _vector(3, items=_NULLABLE_NUMBER),
        "joints_deg": _vector(None),
        "rms_px": _NULLABLE_NUMBER,
        "pairs": {"type": "integer"},
        "verdict": {"type": "string", "description": "ok, or what the operator confirmed"},
        "confirmation": {"type": "string", "description": "who confirmed a result that was not ok, when and why"},
        "time_s": {"type": "number", "description": "Unix time"},
    },
    "required": ["task", "displacement_mm", "rotation_deg"],
}

SETUP = {
    "title": "videocal.Setup",
    "type": "object",
    "description": "what the session ran with: the cell, the camera and the versions",
    "properties": {
        "videocal_version": {"type": "string"},
        "workcell": {"type": "string", "description": "path of the workcell file"},
        "cell": {
            "type": "object",
            "properties": {
                "name": {"type": "string"},
                "content_hash": {"type": "string", "description": "sha256 of robot, frames, placements and features"},
            },
        },
        "intrinsics": INTRINSICS,
        "target": {"type": ["string", "null"]},
        "task": {"type": ["string", "null"]},
        "joint_names": _vector(None, items={"type": "string"}),
        "frames": {"type": "string", "enum": ["h264", "jpeg"], "description": "how camera frames are recorded"},
        "camera_frame": {"type": "string", "description": "frame_id of the camera in /tf and on the images"},
    },
    "required": ["videocal_version"],
}

TOPICS = {
    FRAME_TOPIC: COMPRESSED_IMAGE,
    JOINTS_TOPIC: JOINT_SAMPLE,
    EVENT_TOPIC: EVENT,
    SOLVE_TOPIC: SOLVE,
    CORRECTION_TOPIC: CORRECTION,
    SETUP_TOPIC: SETUP,
}
"""JSON topics and their schemas."""


def schema_bytes(topic: str) -> bytes:
    return json.dumps({"$schema": "https://json-schema.org/draft/2020-12/schema", **TOPICS[topic]}).encode()


PROTOBUF_TOPICS = (VIDEO_TOPIC, CALIBRATION_TOPIC, ANNOTATIONS_TOPIC, FOUND_TOPIC, TRANSFORMS_TOPIC, SCENE_TOPIC)
"""Topics in Foxglove's protobuf schemas (see ``foxglove_messages``)."""
KNOWN_TOPICS = frozenset(TOPICS) | frozenset(PROTOBUF_TOPICS)
