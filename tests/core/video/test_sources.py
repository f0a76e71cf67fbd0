"""Real OpenCV video sources: a video file and an image folder."""

import cv2
import numpy as np
import pytest

from calib_core.video.folder_source import ImageFolderSource
from calib_core.connectors.frame import VideoSourceError
from calib_core.video.opencv_source import OpenCVSource


def test_video_file_frames_in_order_as_rgb(tmp_path):
    path = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 20.0, (64, 48))
    for k in range(10):
        img = np.zeros((48, 64, 3), np.uint8)
        img[:, :, 2] = 200  # red in BGR
        img[0:8, 0:8] = k * 20
        writer.write(img)
    writer.release()
    src = OpenCVSource(str(path))
    assert src.fps == pytest.approx(20.0)
    frames = []
    while (f := src.read()) is not None:
        frames.append(f)
    src.close()
    assert len(frames) == 10 and [f.index for f in frames] == list(range(10))
    assert frames[5].image[30, 40, 0] > 150 and frames[5].image[30, 40, 2] < 60  # RGB, not BGR
    assert frames[9].t_source_s > frames[1].t_source_s


def test_image_folder(tmp_path):
    for k in range(3):
        cv2.imwrite(str(tmp_path / f"{k:02d}.png"), np.full((10, 12, 3), k * 50, np.uint8))
    (tmp_path / "readme.txt").write_text("ignored")
    src = ImageFolderSource(tmp_path, fps=10)
    values = [int(f.image[0, 0, 0]) for f in iter(src.read, None)]
    assert values == [0, 50, 100]
    with pytest.raises(VideoSourceError, match="no images"):
        ImageFolderSource(_empty(tmp_path))
    with pytest.raises(VideoSourceError, match="cannot open"):
        OpenCVSource(str(tmp_path / "missing.mp4"))


def _empty(tmp_path):
    d = tmp_path / "empty"
    d.mkdir()
    return d
