"""Recordings read by the Foxglove ecosystem's own MCAP reader, as Foxglove and Lichtblick open a
file: ``@mcap/core``'s indexed reader (tests/node/read_indexed.mjs), every message decoded with the
schema in the file (protobuf through protobufjs, JSON validated against its JSON Schema by Ajv).
A fresh recording made through the core, one recovered from a killed recorder, and the sample.

Needs node and the packages of tests/node (``make test`` installs them where npm is found);
skipped, with the reason, where they are not."""

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from calib_core.recording.reader import read_recording, recover
from tests.core.recording.recorder_process import RECORDER, read_until, start

NODE_DIR = Path(__file__).resolve().parents[2] / "node"
SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "recordings" / "sample_session.mcap"


def _node_missing() -> str | None:
    if shutil.which("node") is None:
        return "node is not installed: the Foxglove readers (@mcap/core) cannot run"
    if not (NODE_DIR / "node_modules" / "@mcap" / "core").is_dir():
        return f"the reader packages are not installed: npm ci --prefix {NODE_DIR}"
    return None


pytestmark = pytest.mark.skipif(_node_missing() is not None, reason=_node_missing() or "")


def _read_indexed(*paths) -> list[dict]:
    run = subprocess.run(
        ["node", str(NODE_DIR / "read_indexed.mjs"), *map(str, paths)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return [json.loads(line) for line in run.stdout.splitlines()]


def _agrees_with_ours(result: dict, path) -> None:
    """Every message back by the index, decoded by its schema, as many per topic as videocal reads."""
    ours = read_recording(path)
    assert result["errors"] == [] and result["chunks"] > 0 and result["logTimesOrdered"] and result["crcChecked"]
    counts = {}
    for m in ours.messages:
        counts[m.topic] = counts.get(m.topic, 0) + 1
    assert result["messages"] == len(ours.messages) > 0 and result["topics"] == counts


def test_a_fresh_recording_through_the_core_opens_indexed_and_decodes(tmp_path):
    import numpy as np

    from calib_core.operator.core import OperatorCore
    from tests.core.operator.perfect_operator import pick_all, task_joints
    from tests.core.operator.still_robot import frame_now, still_for
    from videocal_sim.sim_site import simulated_cell

    cell, site = simulated_cell(image_scale=0.5)
    core = OperatorCore(cell, site)
    path = tmp_path / "fresh.mcap"
    core.recording.start(path)
    q = task_joints(core)
    still_for(core, 1.0, joints_deg=q)
    for k in range(3):
        frame_now(core, k, image=np.full((cell.intrinsics.height, cell.intrinsics.width, 3), 60 + 40 * k, np.uint8))
    pick_all(core, site.bed, q)
    assert not core.finder.find_points().result.found  # a flat grey frame: recorded all the same
    core.picking.calibrate()
    core.desk.store_correction(convert="a test: the approach's look stands for the task", confirmation="test")
    core.recording.stop()
    (result,) = _read_indexed(path)
    _agrees_with_ours(result, path)
    assert (
        result["schemas"]["/camera/video"] == "foxglove.CompressedVideo"
        and result["schemas"]["/tf"] == "foxglove.FrameTransforms"
    )
    assert (
        result["schemas"]["/camera/calibration"] == "foxglove.CameraCalibration"
        and result["schemas"]["/camera/annotations"] == "foxglove.ImageAnnotations"
    )
    assert (
        result["schemas"]["/videocal/scene"] == "foxglove.SceneUpdate"
        and "/camera/image/compressed" not in result["schemas"]
    )
    assert result["schemas"]["/camera/found_points"] == "foxglove.ImageAnnotations"
    assert [a["name"] for a in result["attachments"]] == ["robot.urdf"]


@pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL")
def test_a_recording_recovered_after_a_kill_opens_indexed_and_decodes(tmp_path):
    killed = tmp_path / "killed.mcap"
    proc = start(RECORDER, killed)
    read_until(proc, lambda line: int(line.split()[1]) >= 20)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(10)
    proc.stdout.close()
    proc.stderr.close()
    (cut,) = _read_indexed(killed)
    assert cut["errors"]  # no summary, no index: what the issue found of every file before
    fixed = tmp_path / "fixed.mcap"
    recover(killed, fixed)
    (result,) = _read_indexed(fixed)
    _agrees_with_ours(result, fixed)


def test_the_sample_recording_opens_indexed_at_the_rates_it_states():
    (result,) = _read_indexed(SAMPLE)
    _agrees_with_ours(result, SAMPLE)
    ours = read_recording(SAMPLE)
    for topic, hz in (("/camera/video", 15.0), ("/robot/joints", 50.0)):
        times = [m.log_time_ns for m in ours.topic(topic)]
        rate = (len(times) - 1) / ((times[-1] - times[0]) / 1e9)
        assert rate == pytest.approx(hz, rel=0.01)
