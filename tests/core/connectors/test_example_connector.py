"""The example connector package in ``examples/`` works as a user's package would: found by its entry point,
its samples into the operator core, its refusal to move said."""

import time
from pathlib import Path

import numpy as np
import pytest

from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore
from calib_core.operator.site import RealSite

EXAMPLE = Path(__file__).parents[3] / "examples" / "videocal-csv-joints"


@pytest.fixture
def installed(tmp_path, monkeypatch):
    """The example's package on the path with its entry points, as ``pip install`` leaves them."""
    info = tmp_path / "videocal_csv_joints-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: videocal-csv-joints\nVersion: 0.1.0\n")
    text = (EXAMPLE / "pyproject.toml").read_text()
    entry = text.split('[project.entry-points."videocal.controllers"]\n', 1)[1].split("\n", 1)[0]
    (info / "entry_points.txt").write_text(f"[videocal.controllers]\n{entry.replace(chr(34), '')}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.syspath_prepend(str(EXAMPLE / "src"))


def test_the_example_connector_drives_the_core_and_moves_nothing(installed, tmp_path):
    cell = Cell.open()
    n = cell.robot.n_joints
    log = tmp_path / "joints.csv"
    rows = [f"{t},{','.join(str(v + 0.01 * t) for v in range(n))}" for t in range(0, 200, 20)]
    log.write_text("t_ms," + ",".join(cell.robot.joint_names) + "\n" + "\n".join(rows) + "\n")
    core = OperatorCore(cell, RealSite(f"csvjoints://{log}"))
    try:
        core.start_controller()
        deadline = time.monotonic() + 10
        last = np.arange(n) + 0.01 * 180
        while not np.allclose(core.joints_deg, last) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert np.allclose(core.joints_deg, last)
        with pytest.raises(Exception, match="plays back a file"):
            core.moves.move_joints(core.joints_deg + 1.0, "a test", confirmed=True)
    finally:
        core.close()
