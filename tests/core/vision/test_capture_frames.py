"""A board capture refuses a frame it has captured already (four captures of one frame were
four views)."""

import numpy as np
import pytest

from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.capture import BoardCapture
from calib_core.vision.intrinsics_calibration import CalibrationInputError


def test_the_same_frame_twice_is_refused_a_new_one_is_taken():
    capture = BoardCapture(parse_board(DEFAULT_SPEC))
    image = np.full((480, 640, 3), 128, np.uint8)
    first = capture.add(image, None, frame_key=("live", 7, 12.5))
    with pytest.raises(CalibrationInputError, match=rf"captured already \({first.name}\)"):
        capture.add(image, None, frame_key=("live", 7, 12.5))
    second = capture.add(image, None, frame_key=("live", 8, 12.6))
    assert second.name != first.name and len(capture.rejected) == 2
