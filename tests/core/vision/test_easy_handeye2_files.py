"""easy_handeye2's own calibration files (its test data, unchanged) as camera mountings: the eye-in-hand result read
as cam2flange (metres and a quaternion to mm and a rotation, checked against the file's numbers with the quaternion
worked by hand), the eye-on-base one refused by name."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from calib_core.errors import FileFormatError
from calib_core.vision.hand_eye_io import load_cam2flange

DATA = Path(__file__).resolve().parents[2] / "data" / "third_party" / "easy_handeye2"


def test_an_eye_in_hand_calibration_is_the_camera_on_the_flange():
    T = load_cam2flange(DATA / "easy_handeye2_demo_eih.calib")
    doc = yaml.safe_load((DATA / "easy_handeye2_demo_eih.calib").read_text())["transform"]
    np.testing.assert_allclose(T[:3, 3], [1000.0 * doc["translation"][k] for k in "xyz"], atol=1e-9)
    # the quaternion by hand (Hamilton, w last in the file): R = I + 2w[v]x + 2[v]x^2 for a unit q = (v, w)
    x, y, z, w = (doc["rotation"][k] for k in "xyzw")
    v = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    np.testing.assert_allclose(T[:3, :3], np.eye(3) + 2 * w * v + 2 * v @ v, atol=1e-9)


def test_the_eye_on_base_one_and_a_broken_one_are_refused_by_field(tmp_path):
    with pytest.raises(FileFormatError, match="eye_on_base.*only eye_in_hand") as info:
        load_cam2flange(DATA / "easy_handeye2_demo_eob.calib")
    assert info.value.field == "parameters.calibration_type"
    text = (DATA / "easy_handeye2_demo_eih.calib").read_text()
    for old, new, field in (
        ("w: 0.9999999952309185", "w: 0.5", "transform.rotation"),
        ("x: 0.12009306887856315", "x: .nan", "transform.translation.x"),
    ):
        broken = tmp_path / "broken.calib"
        broken.write_text(text.replace(old, new))
        with pytest.raises(FileFormatError) as info:
            load_cam2flange(broken)
        assert info.value.field == field
