"""The ROS 2 camera: images by encoding, compressed images, CameraInfo, stamps, a camera that goes quiet and
comes back; on the wire as a peer declared with plain ``sequence<uint8>`` writes and reads it."""

import time
from dataclasses import dataclass
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import int32, sequence, uint8, uint32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

from calib_core.connectors.registry import open_camera
from calib_core.ros2 import messages as msg
from calib_core.ros2.image_decoding import image_to_rgb
from calib_core.ros2.image_source import Ros2ImageSource
from calib_core.ros2.participant import participant
from calib_core.ros2.wire import default_qos, sensor_qos
from calib_core.connectors.frame import FrameTimeout, VideoSourceError


@dataclass
class PeerTime(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class PeerHeader(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: PeerTime
    frame_id: str


@dataclass
class PeerImage(IdlStruct, typename="sensor_msgs::msg::dds_::Image_"):
    header: PeerHeader
    height: uint32
    width: uint32
    encoding: str
    is_bigendian: uint8
    step: uint32
    data: sequence[uint8]


def _image(rgb, stamp_ns=None):
    h, w = rgb.shape[:2]
    return msg.Image(
        msg.Header(msg.Time.of_ns(stamp_ns or time.time_ns()), "camera"), h, w, "rgb8", 0, w * 3, rgb.tobytes()
    )


def _matched(writer):
    deadline = time.monotonic() + 10
    while writer.get_publication_matched_status().current_count == 0:
        assert time.monotonic() < deadline, "no reader matched"
        time.sleep(0.01)


def test_images_cross_the_wire_both_ways_with_a_plain_sequence_peer(domain):
    peer = DomainParticipant(domain)
    dp = participant(domain)
    ours = DataWriter(dp, Topic(dp, "rt/camera/image_raw", msg.Image), qos=sensor_qos(1))
    theirs = DataReader(peer, Topic(peer, "rt/camera/image_raw", PeerImage), qos=sensor_qos(1))
    camera = open_camera("ros2:///camera/image_raw")
    try:
        _matched(ours)
        rgb = np.random.default_rng(1).integers(0, 255, (48, 64, 3), dtype=np.uint8)
        ours.write(_image(rgb))
        frame = camera.read()
        assert np.array_equal(frame.image, rgb)
        deadline = time.monotonic() + 5
        got = []
        while not got and time.monotonic() < deadline:
            got = theirs.take()
            time.sleep(0.01)
        assert bytes(got[0].data) == rgb.tobytes()
        writer = DataWriter(peer, Topic(peer, "rt/camera/image_raw", PeerImage), qos=sensor_qos(1))
        _matched(writer)
        small = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
        writer.write(PeerImage(PeerHeader(PeerTime(1, 0), "c"), 2, 3, "rgb8", 0, 9, list(small.tobytes())))
        assert np.array_equal(camera.read().image, small)
    finally:
        camera.close()


def test_a_frame_is_dated_by_its_stamp_and_camera_info_is_kept(domain):
    dp = participant(domain)
    images = DataWriter(dp, Topic(dp, "rt/arm_cam/image_raw", msg.Image), qos=default_qos(1))
    infos = DataWriter(dp, Topic(dp, "rt/arm_cam/camera_info", msg.CameraInfo), qos=default_qos(1))
    camera = Ros2ImageSource("ros2:///arm_cam/image_raw", {"timeout_s": 0.3})
    try:
        _matched(images)
        _matched(infos)
        k = [800.0, 0, 320, 0, 800.0, 240, 0, 0, 1]
        infos.write(msg.CameraInfo(msg.Header(), 480, 640, "plumb_bob", [0.1, -0.2, 0, 0, 0], k))
        stamp_ns = time.time_ns() - 500_000_000  # taken half a second before it is sent
        images.write(_image(np.zeros((4, 4, 3), np.uint8), stamp_ns))
        sent_host = time.monotonic()
        frame = camera.read()
        assert frame.t_source_s == pytest.approx(stamp_ns / 1e9)
        assert sent_host - 0.6 < frame.t_host_s < sent_host - 0.4
        deadline = time.monotonic() + 5
        while camera.camera_info is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert list(camera.camera_info.k) == k and camera.camera_info.distortion_model == "plumb_bob"
        # A frame that arrives 30 s late is 30 s old: it must never pass for a new one (a GigE run showed an
        # image of an earlier pose taken as settled when late frames were dated by their arrival).
        images.write(_image(np.zeros((4, 4, 3), np.uint8), time.time_ns() - 30_000_000_000))
        sent_host = time.monotonic()
        assert sent_host - 30.2 < camera.read().t_host_s < sent_host - 29.8
        # Quiet: the reader says it is waiting (and keeps the source open) ...
        with pytest.raises(FrameTimeout, match="no image for 0.3 s"):
            camera.read()
        # ... and the camera coming back brings frames again.
        images.write(_image(np.full((4, 4, 3), 7, np.uint8)))
        assert camera.read().image[0, 0, 0] == 7
    finally:
        camera.close()


def test_compressed_images_by_image_transport_name(domain):
    dp = participant(domain)
    writer = DataWriter(dp, Topic(dp, "rt/camera/image_raw/compressed", msg.CompressedImage), qos=sensor_qos(1))
    camera = open_camera("ros2:///camera/image_raw/compressed")
    try:
        _matched(writer)
        rgb = np.zeros((40, 60, 3), np.uint8)
        rgb[:, :30] = (200, 30, 30)
        ok, png = cv2.imencode(".png", cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        writer.write(msg.CompressedImage(msg.Header(msg.Time.of_ns(time.time_ns())), "png", png.tobytes()))
        assert np.array_equal(camera.read().image, rgb)
        writer.write(msg.CompressedImage(msg.Header(msg.Time.of_ns(time.time_ns())), "jpeg", b"\xff\xd8 not a jpeg"))
        with pytest.raises(VideoSourceError, match="does not decode"):
            camera.read()
    finally:
        camera.close()


def _raw(encoding, h, w, step, data, big=0):
    return SimpleNamespace(encoding=encoding, height=h, width=w, step=step, data=data, is_bigendian=big)


def test_encodings_cameras_send():
    rgb = np.random.default_rng(2).integers(0, 255, (5, 7, 3), dtype=np.uint8)
    bgr = rgb[:, :, ::-1].copy()
    padded = np.zeros((5, 7 * 3 + 3), np.uint8)  # rows padded to a step of 24 bytes
    padded[:, :21] = bgr.reshape(5, 21)
    assert np.array_equal(image_to_rgb(_raw("bgr8", 5, 7, 24, padded.tobytes()), "cam"), rgb)
    grey = rgb[:, :, 0].copy()
    assert np.array_equal(image_to_rgb(_raw("mono8", 5, 7, 7, grey.tobytes()), "cam")[:, :, 2], grey)
    wide = (grey.astype(np.uint16) << 8).astype(">u2")
    assert np.array_equal(image_to_rgb(_raw("mono16", 5, 7, 14, wide.tobytes(), big=1), "cam")[:, :, 1], grey)
    mosaic = np.zeros((8, 8), np.uint8)
    mosaic[0::2, 0::2] = 250  # red sites of an RGGB sensor lit: a red scene
    assert tuple(image_to_rgb(_raw("bayer_rggb8", 8, 8, 8, mosaic.tobytes()), "cam")[4, 4]) == (250, 0, 0)
    with pytest.raises(VideoSourceError, match="'yuv422' is not supported"):
        image_to_rgb(_raw("yuv422", 5, 7, 14, bytes(70)), "cam")
    with pytest.raises(VideoSourceError, match="needs 105 bytes, got 100"):
        image_to_rgb(_raw("rgb8", 5, 7, 21, bytes(100)), "cam")
