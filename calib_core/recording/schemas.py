"""The topics of a videocal recording and their JSON schemas (message encoding ``json``).

Timestamps in messages are host monotonic seconds unless named otherwise; the MCAP log time
is Unix nanoseconds of recording.
"""

from __future__ import annotations

import json

FRAME_TOPIC = "/camera/image/compressed"
VIDEO_TOPIC = "/camera/video"
"""Frames as H.264 (``foxglove.CompressedVideo``, protobuf): the default. ``FRAME_TOPIC`` carries
JPEG frames (``foxglove.CompressedImage``, JSON) when a recording is made with ``frames="jpeg"``."""
JOINTS_TOPIC = "/robot/joints"
EVENT_TOPIC = "/videocal/events"
SOLVE_TOPIC = "/videocal/solves"
CORRECTION_TOPIC = "/videocal/corrections"
SETUP_TOPIC = "/videocal/setup"

# Foxglove's schema, so the video shows in Foxglove Studio. ``data`` is base64 in JSON encoding.
COMPRESSED_IMAGE = {
    "title": "foxglove.CompressedImage",
    "type": "object",
    "properties": {
        "timestamp": {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}},
        "frame_id": {"type": "string"},
        "data": {"type": "string", "contentEncoding": "base64"},
        "format": {"type": "string"},
    },
}

JOINT_SAMPLE = {
    "title": "videocal.JointSample",
    "type": "object",
    "properties": {
        "seq": {"type": "integer"},
        "t_ms": {"type": "integer", "description": "controller clock, ms"},
        "t_host_s": {"type": "number", "description": "host monotonic clock when received, s"},
        "joints_deg": {"type": "array", "items": {"type": "number"}},
    },
}

EVENT = {
    "title": "videocal.Event",
    "type": "object",
    "properties": {"kind": {"type": "string"}, "detail": {"type": "object"}},
}

SOLVE = {
    "title": "videocal.Solve",
    "type": "object",
    "description": "a solve's complete inputs and its result, enough to re-solve it",
    "properties": {"id": {"type": "integer"}, "inputs": {"type": "object"}, "result": {"type": "object"}},
}

CORRECTION = {"title": "videocal.Correction", "type": "object"}
SETUP = {"title": "videocal.Setup", "type": "object", "description": "intrinsics, workcell and versions in use"}

TOPICS = {
    FRAME_TOPIC: COMPRESSED_IMAGE,
    JOINTS_TOPIC: JOINT_SAMPLE,
    EVENT_TOPIC: EVENT,
    SOLVE_TOPIC: SOLVE,
    CORRECTION_TOPIC: CORRECTION,
    SETUP_TOPIC: SETUP,
}


def schema_bytes(topic: str) -> bytes:
    return json.dumps(TOPICS[topic]).encode()


def video_schema() -> tuple[str, bytes]:
    """Name and ``FileDescriptorSet`` bytes of Foxglove's own protobuf ``CompressedVideo`` (the
    schema Foxglove Studio plays), from the ``foxglove-schemas-protobuf`` package."""
    from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo
    from mcap_protobuf.schema import build_file_descriptor_set

    return CompressedVideo.DESCRIPTOR.full_name, build_file_descriptor_set(CompressedVideo).SerializeToString()
