"""``videocal grab``: N frames of any camera connector as PNG files and frames.csv; a camera that vanishes
for a while is waited for and said; a camera that stays away ends it with the frames kept."""

import csv
import os
import subprocess
import sys
import time

import cv2
import numpy as np


def _grab(*args, env=None, timeout=90):
    return subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", "grab", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, **(env or {})},
    )


def test_grab_survives_a_ros2_camera_vanishing_for_a_while(tmp_path, domain):
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic

    from calib_core.ros2 import messages as msg
    from calib_core.ros2.wire import sensor_qos

    out = tmp_path / "frames"
    grab = _grab(
        "ros2:///cam/image_raw", "--count", "6", "--out", str(out), "--wait", "20", env={"ROS_DOMAIN_ID": str(domain)}
    )
    stamps = []

    def publish(first, until):
        """A camera driver of its own (gone with its participant), one frame every 0.25 s until ``until()``:
        sensor data is best effort, so a frame sent before the reader has matched this writer may never arrive."""
        dp = DomainParticipant(domain)
        writer = DataWriter(dp, Topic(dp, "rt/cam/image_raw", msg.Image), qos=sensor_qos(1))
        deadline = time.monotonic() + 60
        while writer.get_publication_matched_status().current_count == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        k = 0
        while not until() and time.monotonic() < deadline:
            stamp = time.time_ns()
            stamps.append((stamp, first + k))
            writer.write(
                msg.Image(msg.Header(msg.Time.of_ns(stamp), "cam"), 8, 8, "mono8", 0, 8, bytes([first + k] * 64))
            )
            k += 1
            time.sleep(0.25)  # slower than the reader: a frame it reads is the one just sent
        del writer, dp

    publish(10, until=lambda: len(list(out.glob("frame_*.png"))) >= 3)
    time.sleep(3.0)  # the camera is away for 3 s (grab's 2 s wait per read has run out at least once)
    publish(50, until=lambda: grab.poll() is not None)
    out_text, err = grab.communicate(timeout=60)
    assert grab.returncode == 0, err
    assert "waiting: ROS 2 camera /cam/image_raw: no image for 2 s" in err and "the camera is back after" in err
    rows = list(csv.DictReader((out / "frames.csv").open()))
    assert [r["file"] for r in rows] == [f"frame_{k:06d}.png" for k in range(6)]
    sent = dict(stamps)
    values = [int(cv2.imread(str(out / r["file"]), cv2.IMREAD_GRAYSCALE)[0, 0]) for r in rows]
    # Each frame kept is one that was sent, with the sender's stamp, in order; some before the gap, some after.
    assert [sent[int(r["t_device_ns"])] for r in rows] == values
    assert values == sorted(values) and values[0] < 50 <= values[-1] and values[2] < 50


def test_grab_keeps_what_it_got_when_the_camera_stays_away(tmp_path, domain):
    out = tmp_path / "frames"
    grab = _grab(
        "ros2:///nobody/image_raw",
        "--count",
        "3",
        "--out",
        str(out),
        "--wait",
        "1",
        env={"ROS_DOMAIN_ID": str(domain)},
    )
    _, err = grab.communicate(timeout=60)
    assert (
        grab.returncode == 4
        and "no frame for" in err
        and "0 of 3 frames: nothing was left behind" in err
        and "Traceback" not in err
    )
    assert not out.exists()  # no empty folder, no empty frames.csv


def test_grab_from_a_folder_and_refusals(tmp_path):
    shots = tmp_path / "shots"
    shots.mkdir()
    for k in range(2):
        cv2.imwrite(str(shots / f"{k}.png"), np.full((6, 9, 3), 30 * k, np.uint8))
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "grab", str(shots), "--count", "3", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0, run.stderr
    rows = list(csv.DictReader((out / "frames.csv").open()))
    assert len(rows) == 3 and all(r["t_device_ns"] == "" for r in rows)  # a folder has no device clock
    again = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "grab", str(shots), "--count", "1", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert again.returncode == 2 and "frames.csv exists" in again.stderr
    bad = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "grab", "nosuch://cam", "--count", "1", "--out", str(tmp_path / "x")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (
        bad.returncode == 2 and "no camera connector for 'nosuch://cam'" in bad.stderr and "Traceback" not in bad.stderr
    )
