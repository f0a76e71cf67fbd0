"""Recordings: write and read back, survive a cut, recover, replay solves exactly; the sample
recording in resources replays; a tampered result is found."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.recording.frame_track import FrameTrack
from calib_core.recording.reader import decode_frame, read_recording, recover
from calib_core.recording.recorder import SessionRecorder
from calib_core.recording.replay import replay
from calib_core.recording.schemas import EVENT_TOPIC, FRAME_TOPIC, JOINTS_TOPIC, SOLVE_TOPIC, VIDEO_TOPIC
from tests.core.recording.recordings import noisy_image, record

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "recordings" / "sample_session.mcap"


def test_round_trip(tmp_path):
    path = record(tmp_path / "s.mcap")
    contents = read_recording(path)
    assert contents.complete and contents.problem is None
    assert (
        len(contents.topic(FRAME_TOPIC)) == 3
        and len(contents.topic(JOINTS_TOPIC)) == 3
        and len(contents.topic(EVENT_TOPIC)) == 3
    )
    frame = contents.topic(FRAME_TOPIC)[0].payload
    assert frame["format"] == "jpeg" and decode_frame(frame).shape == (48, 64, 3)
    assert contents.topic(JOINTS_TOPIC)[2].payload["joints_deg"][-1] == 2.0


def test_video_frames_decode_in_order_and_by_seeking(tmp_path):
    path = record(tmp_path / "v.mcap", n_frames=70, n_solves=0, frames="h264")
    contents = read_recording(path)
    assert not contents.topic(FRAME_TOPIC)
    track = FrameTrack(contents)
    assert track.is_video and len(track) == 70 and track.keyframes == [0, 30, 60]
    truth = [noisy_image(i, None, noise=0.0) for i in range(70)]
    sequential = [track.image(k) for k in range(70)]
    for k in (69, 31, 5, 45, 44, 0):  # jumps forwards, back across keyframes, to the start
        assert np.array_equal(track.image(k), sequential[k])
    errors = [np.abs(img.astype(int) - ref).mean() for img, ref in zip(sequential, truth)]
    assert max(errors) < 5.0  # gray levels against the noise-free picture (4:2:0 blurs the red square)
    # the moving square is where it was in each frame, not in its neighbour's place
    assert sequential[40][15, 45:55, 0].mean() > 200 and sequential[40][15, 35:40, 0].mean() < 150
    assert np.all(np.diff(track.times_s) >= 0) and track.index_at(track.times_s[12] + 1e-6) == 12


def test_video_frames_use_foxglove_compressed_video(tmp_path):
    from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo
    from google.protobuf.descriptor_pb2 import FileDescriptorSet
    from mcap.reader import make_reader

    from calib_core.recording.video_codec import nal_unit_types

    path = record(tmp_path / "v.mcap", n_frames=3, n_solves=0, frames="h264")
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    channel = next(c for c in summary.channels.values() if c.topic == VIDEO_TOPIC)
    schema = summary.schemas[channel.schema_id]
    assert (schema.name, schema.encoding, channel.message_encoding) == (
        "foxglove.CompressedVideo",
        "protobuf",
        "protobuf",
    )
    files = FileDescriptorSet.FromString(schema.data)
    assert any(m.name == "CompressedVideo" for fd in files.file for m in fd.message_type)
    first = read_recording(path).topic(VIDEO_TOPIC)[0]
    message = CompressedVideo.FromString(first.raw)
    assert message.format == "h264" and message.timestamp.ToNanoseconds() == first.log_time_ns
    # Annex B with SPS and PPS before the IDR slice, as Foxglove requires of a keyframe
    types = nal_unit_types(message.data)
    assert message.data.startswith(b"\x00\x00\x00\x01") and types.index(7) < types.index(5) and 8 in types
    assert not any(c.topic == FRAME_TOPIC for c in summary.channels.values())  # only the frame topic in use
    jpeg = record(tmp_path / "j.mcap", n_frames=2, n_solves=0, frames="jpeg")
    with open(jpeg, "rb") as f:
        summary = make_reader(f).get_summary()
    image = next(c for c in summary.channels.values() if c.topic == FRAME_TOPIC)
    assert summary.schemas[image.schema_id].name == "foxglove.CompressedImage" and image.message_encoding == "json"
    assert not any(c.topic == VIDEO_TOPIC for c in summary.channels.values())


def test_a_busy_encoder_drops_frames_and_counts_them(tmp_path):
    frame = np.zeros((480, 640, 3), np.uint8)
    with SessionRecorder(tmp_path / "busy.mcap", queue_frames=2) as rec:
        for _ in range(40):
            rec.record_frame(frame, 0.0)
    assert rec.frames_dropped > 0 and rec.frames_written + rec.frames_dropped == 40
    assert len(read_recording(tmp_path / "busy.mcap").topic(VIDEO_TOPIC)) == rec.frames_written


@pytest.mark.parametrize("frames", ["jpeg", "h264"])
def test_every_message_before_a_cut_survives_and_recovers(tmp_path, frames):
    path = record(tmp_path / "s.mcap", n_frames=8, n_solves=1, frames=frames)
    full = read_recording(path).messages
    data = path.read_bytes()
    for cut in (len(data) // 3, len(data) // 2, len(data) - 200):
        cut_path = tmp_path / f"cut{cut}.mcap"
        cut_path.write_bytes(data[:cut])
        contents = read_recording(cut_path)
        assert not contents.complete and "ends" in contents.problem
        n = len(contents.messages)
        assert 0 < n <= len(full)  # whole chunks before the cut survive; a cut inside the summary loses no message
        assert [m.payload for m in contents.messages] == [m.payload for m in full[:n]]
        fixed = recover(cut_path, tmp_path / f"fixed{cut}.mcap")
        again = read_recording(tmp_path / f"fixed{cut}.mcap")
        assert again.complete and [m.payload for m in again.messages] == [m.payload for m in fixed.messages]
        if frames == "h264" and again.topic(VIDEO_TOPIC):
            track = FrameTrack(again)
            assert track.image(len(track) - 1).shape == (48, 64, 3)


def test_replay_agrees_exactly_and_finds_a_tampered_result(tmp_path):
    path = record(tmp_path / "s.mcap")
    assert all(r.agree for r in replay(path))
    # Tamper: the same messages with one recorded translation nudged by 1 um.
    contents = read_recording(path)
    tampered = tmp_path / "t.mcap"
    with SessionRecorder(tampered) as rec:
        for m in contents.messages:
            payload = m.payload
            if m.topic == SOLVE_TOPIC and payload["id"] == 2:
                payload["result"]["t_obj2cam_mm"][0] += 0.001
            rec._write(m.topic, payload, m.log_time_ns)
    results = replay(tampered)
    assert [r.agree for r in results] == [True, False]
    assert results[1].translation_diff_mm == pytest.approx(0.001, rel=1e-6)
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "replay", str(tampered), "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 5
    assert [s["agree"] for s in json.loads(run.stdout)["solves"]] == [True, False]


def test_the_bundled_sample_recording_replays():
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "replay", str(SAMPLE)], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "2 solves" in run.stdout and "agrees" in run.stdout
    contents = read_recording(SAMPLE)
    assert contents.complete and len(FrameTrack(contents)) >= 5


def test_foreign_and_missing_files(tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"this is not mcap at all")
    with pytest.raises(FileFormatError, match="not an MCAP recording"):
        read_recording(junk)
    with pytest.raises(FileFormatError, match="no such recording"):
        read_recording(tmp_path / "none.mcap")
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "replay", str(junk)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2 and run.stderr.startswith("error: ")
