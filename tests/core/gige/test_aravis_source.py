"""GenICam cameras through Aravis: Aravis's own fake camera (settings read back), and a GigE Vision camera on the
loopback interface (Aravis's fake GigE Vision camera sending our images over GVCP/GVSP): exact pixels, device
timestamps, the camera vanishing and coming back."""

import re
import subprocess
import time

import cv2
import numpy as np
import pytest

from calib_core.connectors.registry import open_camera
from calib_core.gige.pixel_formats import BGR8, MONO8, MONO16, RGB8, to_rgb
from calib_core.connectors.frame import FrameTimeout, VideoSourceError
from videocal_sim.gige_camera import SimulatedGigECamera


def test_aravis_fake_camera_takes_and_reports_its_settings():
    camera = open_camera("aravis://Fake_1?exposure_us=4000&gain_db=3&pixel_format=Mono8&width=320&height=240")
    try:
        assert camera.model == "Aravis Fake" and camera.pixel_format == "Mono8"
        assert camera.exposure_us == pytest.approx(4000.0) and camera.gain_db == pytest.approx(3.0)
        frames = [camera.read() for _ in range(3)]
        assert all(f.size == (320, 240) for f in frames)
        stamps = [f.t_device_ns for f in frames]
        assert stamps == sorted(stamps) and len(set(stamps)) == 3
    finally:
        camera.close()


def test_settings_a_camera_refuses_are_named():
    with pytest.raises(VideoSourceError, match="refuses pixel_format='YUV422'; it offers .*Mono8"):
        open_camera("aravis://Fake_1?pixel_format=YUV422")
    with pytest.raises(VideoSourceError, match="unknown option.*exposure"):
        open_camera("aravis://Fake_1?exposure=3")
    with pytest.raises(VideoSourceError, match="name the camera"):
        open_camera("aravis://")


@pytest.mark.parametrize(
    "option, message",
    [
        ("exposure_us=-5", "refuses exposure_us='-5': it offers 10-10000000 us"),
        ("gain_db=1000", "refuses gain_db='1000': it offers 0-10 dB"),
        ("width=99999", "refuses width='99999': it offers 1-2048 px"),
        ("height=0", "refuses height='0': it offers 1-2048 px"),
        ("exposure_us=fast", "exposure_us='fast' is not a number"),
        ("gain_db=nan", "gain_db='nan' is not a finite number"),
    ],
)
def test_a_setting_outside_what_the_camera_offers_is_refused_with_its_range(option, message):
    with pytest.raises(VideoSourceError, match=re.escape(message)):
        open_camera(f"aravis://Fake_1?{option}")


def test_a_gige_camera_is_found_by_its_device_id_as_by_its_address_and_an_unknown_id_lists_what_is_there():
    scene = _scene()
    server = SimulatedGigECamera(lambda: scene, serial="BYID01")
    try:
        # as the docs say: `arv-tool-0.8` (installed by the set-up) lists the cameras by id, and that id opens it
        listing = subprocess.run(["arv-tool-0.8"], capture_output=True, text=True, timeout=60).stdout
        assert "Aravis-Fake-BYID01 (127.0.0.1)" in listing, listing
        camera = open_camera("aravis://Aravis-Fake-BYID01?pixel_format=RGB8&width=160&height=120&timeout_s=5")
        try:
            assert np.array_equal(camera.read().image, scene)
        finally:
            camera.close()
        with pytest.raises(
            VideoSourceError, match=r"no camera with that id; cameras found: .*Aravis-Fake-BYID01 \(127\.0\.0\.1\)"
        ):
            open_camera("aravis://Basler-acA1300-000000")
    finally:
        server.close()


def _scene(w=160, h=120):
    image = np.zeros((h, w, 3), np.uint8)
    image[:, : w // 2] = (210, 40, 10)
    cv2.circle(image, (w // 2, h // 2), h // 4, (20, 220, 90), -1)
    return image


def test_a_gige_camera_on_loopback_sends_our_pixels_and_comes_back_after_vanishing():
    scene = _scene()
    server = SimulatedGigECamera(lambda: scene)
    camera = open_camera("aravis://127.0.0.1?pixel_format=RGB8&width=160&height=120&timeout_s=1&reopen_after_s=1.5")
    try:
        frame = camera.read()
        assert np.array_equal(frame.image, scene)
        assert frame.t_device_ns is not None and abs(frame.t_device_ns / 1e9 - time.time()) < 5
        assert time.monotonic() - 2 < frame.t_host_s <= time.monotonic()
        server.close()  # unplugged
        with pytest.raises(FrameTimeout, match="no frame for"):
            for _ in range(5):  # the frames already on their way may still arrive first
                camera.read()
        server = SimulatedGigECamera(lambda: scene[::-1].copy())  # back, showing something else
        deadline = time.monotonic() + 60
        while True:
            try:
                frame = camera.read()
                if np.array_equal(frame.image, scene[::-1]):
                    break
            except FrameTimeout:
                pass
            assert time.monotonic() < deadline, "the camera did not come back"
        assert camera.reopened >= 1
    finally:
        camera.close()
        server.close()


def test_pixel_formats():
    scene = _scene(8, 6)
    assert np.array_equal(to_rgb(scene.tobytes(), 8, 6, RGB8, "cam"), scene)
    assert np.array_equal(to_rgb(scene[:, :, ::-1].tobytes(), 8, 6, BGR8, "cam"), scene)
    grey = scene[:, :, 1].copy()
    assert np.array_equal(to_rgb(grey.tobytes(), 8, 6, MONO8, "cam")[:, :, 0], grey)
    assert np.array_equal(to_rgb((grey.astype("<u2") << 8).tobytes(), 8, 6, MONO16, "cam")[:, :, 2], grey)
    mosaic = np.zeros((8, 8), np.uint8)
    mosaic[0::2, 0::2] = 240  # BayerRG8: red on the even rows' even columns
    assert tuple(to_rgb(mosaic.tobytes(), 8, 8, 0x01080009, "cam")[4, 4]) == (240, 0, 0)
    with pytest.raises(VideoSourceError, match="needs 144 bytes, got 10"):
        to_rgb(bytes(10), 8, 6, RGB8, "cam")
    with pytest.raises(VideoSourceError, match="0x02100032 is not supported"):
        to_rgb(bytes(100), 8, 6, 0x02100032, "cam")


def test_one_simulated_camera_serves_on_an_interface_at_a_time():
    """Two fake GigE Vision cameras on the loopback both answered discovery and a client's register writes reached the
    one another client controlled: a second waits until the first has closed, across processes (a lock file of the
    interface), and only it is then on the network."""
    import fcntl
    import os
    import tempfile
    import threading

    scene = _scene()
    first = SimulatedGigECamera(lambda: scene, serial="FIRST1")
    second = {}
    lock = os.open(os.path.join(tempfile.gettempdir(), "videocal-gige-lo.lock"), os.O_RDWR)
    maker = threading.Thread(
        target=lambda: second.setdefault("camera", SimulatedGigECamera(lambda: scene, serial="NEXT1"))
    )
    try:
        with pytest.raises(BlockingIOError):  # held while the first serves: another process's camera would wait
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        maker.start()
        first.close()
        maker.join(timeout=60)
        assert "camera" in second  # made once the first had gone
        listing = subprocess.run(["arv-tool-0.8"], capture_output=True, text=True, timeout=60).stdout
        assert "Aravis-Fake-NEXT1" in listing and "FIRST1" not in listing, listing
    finally:
        os.close(lock)
        first.close()
        maker.join(timeout=60)
        if "camera" in second:
            second["camera"].close()


def test_a_camera_that_does_not_answer_is_told_apart_from_one_that_refuses():
    """Aravis's timeout (a GLib error of its device domain) is the camera or the network not answering, which the
    message says as such; any other error is the camera's refusal."""
    from gi.repository import GLib

    from calib_core.gige.aravis_lib import aravis
    from calib_core.gige.aravis_source import _timed_out

    Aravis = aravis()
    timeout = GLib.Error.new_literal(Aravis.device_error_quark(), "GigEVision write_register timeout", 5)
    refused = GLib.Error.new_literal(
        Aravis.device_error_quark(), "out of range", int(Aravis.DeviceError.PROTOCOL_ERROR)
    )
    assert _timed_out(timeout, Aravis) and not _timed_out(refused, Aravis)
    assert not _timed_out(ValueError("not a GLib error"), Aravis)
