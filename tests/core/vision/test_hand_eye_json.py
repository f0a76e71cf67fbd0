"""A JSON pose file of {image, flange2base}: the form the shared real hand-eye sets (and many capture scripts) write."""

from __future__ import annotations

import json

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy
from calib_core.vision.hand_eye_data import load_posed_images


def test_metres_by_default_and_millimetres_when_said(tmp_path):
    T = transform_from_xyz_rpy([500.0, -120.0, 830.0], [10.0, -20.0, 30.0])
    in_metres = T.copy()
    in_metres[:3, 3] /= 1000.0
    path = tmp_path / "poses.json"
    path.write_text(json.dumps([{"image": "images/a.png", "flange2base": in_metres.tolist()}]))
    (view,) = load_posed_images(path).views
    np.testing.assert_allclose(view.flange2base, T, atol=1e-9)
    assert view.image_path == tmp_path / "images" / "a.png" and view.name == "a"
    path.write_text(json.dumps({"length_unit": "mm", "poses": [{"image": "a.png", "flange2base": T.tolist()}]}))
    np.testing.assert_allclose(load_posed_images(path).views[0].flange2base, T, atol=1e-9)


@pytest.mark.parametrize(
    "doc, field, says",
    [
        (
            [{"image": "a.png", "flange2base": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]]}],
            "[0].flange2base",
            "not a rigid transform",
        ),
        ([{"image": "a.png", "flange2base": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}], "[0].flange2base", "4 x 4"),
        ([{"flange2base": np.eye(4).tolist()}], "[0]", "an image"),
        ({"length_unit": "inch", "poses": []}, "length_unit", "'m' or 'mm'"),
        (
            [{"image": "a.png", "flange2base": [[1, 0, 0, 1e9], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}],
            "[0].flange2base",
            "is the unit right",
        ),
    ],
)
def test_a_bad_entry_names_its_file_and_field(tmp_path, doc, field, says):
    path = tmp_path / "poses.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(FileFormatError) as refused:
        load_posed_images(path)
    assert "poses.json" in str(refused.value) and field in str(refused.value) and says in str(refused.value)


def test_an_image_of_another_size_is_named(tmp_path):
    """One calibration is for one camera mode: the image whose size differs from the first's is named."""
    import cv2

    T = np.eye(4)
    cv2.imwrite(str(tmp_path / "a.png"), np.zeros((480, 640), np.uint8))
    cv2.imwrite(str(tmp_path / "b.png"), np.zeros((600, 800), np.uint8))
    path = tmp_path / "poses.json"
    path.write_text(json.dumps([{"image": n, "flange2base": T.tolist()} for n in ("a.png", "b.png")]))
    data = load_posed_images(path)
    image, size = data.read_image_sized(data.views[0], None)
    assert size == (640, 480) and image.shape == (480, 640)
    with pytest.raises(FileFormatError, match=r"b.png: 800 x 600 px, the first image is 640 x 480 px"):
        data.read_image_sized(data.views[1], size)
