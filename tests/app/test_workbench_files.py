"""Files the workbench reads: a measured camera mounting replaces the modelled one."""

import numpy as np
import pytest
import yaml

from app.gui.workbench import Workbench
from videocal_sim.sim_site import simulated_cell
from calib_core.errors import FileFormatError
from calib_core.frames import pose_difference


def test_hand_eye_file_moves_the_modelled_camera(qapp, tmp_path):
    wb = Workbench(*simulated_cell())
    try:
        q = np.array([-20.0, 10.0, 5.0, 0.0, -15.0, 0.0])
        before = wb.robot.fk(q, "camera")
        path = tmp_path / "he.yaml"
        path.write_text(yaml.safe_dump({"cam2flange": {"xyz": [81.0, -1.0, 88.0], "rpy": [-100.0, 0.0, -90.0]}}))
        wb.apply_hand_eye_file(path)
        after = wb.robot.fk(q, "camera")
        cam_in_flange = np.linalg.inv(wb.robot.fk(q, "flange")) @ after
        assert np.allclose(cam_in_flange[:3, 3], [81.0, -1.0, 88.0], atol=1e-9)
        assert np.linalg.norm(pose_difference(after, before)[0]) > 1.0
        bad = tmp_path / "bad.yaml"
        bad.write_text("cam2flange: {xyz: [1, 2]}")
        with pytest.raises(FileFormatError, match=r"cam2flange.xyz.*must be a list of 3 numbers"):
            wb.apply_hand_eye_file(bad)
    finally:
        wb.close()
