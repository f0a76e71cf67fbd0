"""Connectors are found by their URL's scheme through entry points: videocal's own and a user's alike."""

from __future__ import annotations

import numpy as np
import pytest

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import ConnectorNotFoundError, open_camera, open_controller
from calib_core.connectors.urls import camera_scheme, controller_scheme
from calib_core.link.driver import ControllerLink
from calib_core.connectors.joint_map import JointMap


def _context(n=6):
    return ControllerContext(
        tuple(f"j{i}" for i in range(n)), ("deg",) * n, JointMap(np.arange(n)[::-1].copy(), np.full(n, 10.0))
    )


@pytest.mark.parametrize(
    "url, scheme",
    [
        ("/dev/ttyUSB0", "serial"),
        ("COM3", "serial"),
        ("socket://10.0.0.2:7000", "socket"),
        ("ROS2:///joint_states", "ros2"),
        ("ur-rtde://192.168.1.10", "ur-rtde"),
    ],
)
def test_controller_schemes(url, scheme):
    assert controller_scheme(url) == scheme


def test_camera_schemes(tmp_path):
    assert camera_scheme("0") == "opencv"
    assert camera_scheme(str(tmp_path)) == "folder"
    assert camera_scheme(str(tmp_path / "clip.mp4")) == "file"
    assert camera_scheme("rtsp://cam/stream") == "rtsp"
    assert camera_scheme("aravis://Fake_1") == "aravis"


def test_an_unknown_scheme_names_the_installed_ones():
    with pytest.raises(ConnectorNotFoundError) as info:
        open_controller("nosuch://robot", _context())
    text = str(info.value)
    assert "'nosuch://robot'" in text and "socket://" in text and "serial://" in text


def test_the_own_protocol_is_a_connector_with_the_cells_axes():
    context = _context()
    link = open_controller("socket://127.0.0.1:9", context)
    assert isinstance(link, ControllerLink)
    assert link.joint_map is context.cell_joint_map
    assert link.n_joints == 6


def test_a_folder_camera_plays_its_images(tmp_path):
    import cv2

    for i in range(2):
        cv2.imwrite(str(tmp_path / f"f{i}.png"), np.full((8, 10, 3), 40 * i, np.uint8))
    with open_camera(str(tmp_path)) as camera:
        frame = camera.read()
    assert frame.size == (10, 8)


def test_a_users_package_adds_a_scheme(tmp_path, monkeypatch):
    """A package of the user's registers ``mycell://`` in ``videocal.controllers``: found, no fork."""
    (tmp_path / "my_connector.py").write_text("def open(url, context):\n    return ('opened', url, context.n_joints)\n")
    info = tmp_path / "my_connector-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: my-connector\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[videocal.controllers]\nmycell = my_connector:open\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert open_controller("mycell://arm-3", _context(4)) == ("opened", "mycell://arm-3", 4)
