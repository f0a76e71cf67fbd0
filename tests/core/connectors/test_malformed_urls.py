"""A connector URL with an unmatched bracket (a typo in the site: section, ``--robot`` or ``--camera``) is refused by
the connector with its own error naming the URL: it once escaped as Python's bare "Invalid IPv6 URL" (found by the
reliability bench's fuzzing of connector URLs)."""

import pytest

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.frame import VideoSourceError
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkError
from calib_core.connectors.registry import open_camera, open_controller

CONTEXT = ControllerContext(("a", "b"), ("deg", "deg"), JointMap.identity(2), 50.0, {})


@pytest.mark.parametrize("url", ["ros2://]x", "ros2://[::1/joint_states", "ur-rtde://[10.0.0.5", "ur-rtde://]"])
def test_a_controller_url_with_an_unmatched_bracket_is_refused_by_name(url):
    with pytest.raises(LinkError, match="not a URL the connector can read") as refused:
        open_controller(url, CONTEXT)
    assert repr(url) in str(refused.value)


@pytest.mark.parametrize("spec", ["ros2://]cam", "aravis://[Fake_1", "aravis://]"])
def test_a_camera_spec_with_an_unmatched_bracket_is_refused_by_name(spec):
    with pytest.raises(VideoSourceError, match="not a URL the connector can read") as refused:
        open_camera(spec)
    assert repr(spec) in str(refused.value)
