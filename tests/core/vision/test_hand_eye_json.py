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
