"""The recording file as other tools read it: chunked and indexed, in log-time order, one
sequence per channel; and a recorder that fails (codec, full disk) without taking its caller down."""

import subprocess
import sys
import textwrap
import time

import numpy as np
from mcap.reader import make_reader

from calib_core.recording.reader import read_recording, recover
from calib_core.recording.recorder import SessionRecorder
from calib_core.recording.schemas import EVENT_TOPIC, JOINTS_TOPIC, VIDEO_TOPIC
from tests.core.recording.recordings import SimulatedClock, noisy_image, record


def _indexed(path):
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        messages = [
            (channel.topic, message.log_time, message.sequence)
            for _, channel, message in reader.iter_messages(log_time_order=False)
        ]
    return summary, messages


def test_an_indexed_reader_gets_every_message_back_in_order(tmp_path):
    path = record(tmp_path / "s.mcap", n_frames=12, n_solves=2, frames="h264")
    summary, indexed = _indexed(path)
    streamed = read_recording(path).messages
    assert len(summary.chunk_indexes) >= 4 and summary.statistics.message_count == len(streamed) == len(indexed)
    assert all(c.compression == "lz4" for c in summary.chunk_indexes)
    with open(path, "rb") as f:  # every chunk carries the CRC of its contents, and the CRCs hold
        from mcap.records import Chunk
        from mcap.stream_reader import StreamReader

        chunks = [r for r in StreamReader(f, emit_chunks=True, validate_crcs=True).records if isinstance(r, Chunk)]
    assert len(chunks) == len(summary.chunk_indexes) and all(c.uncompressed_crc != 0 for c in chunks)
    log_times = [t for _, t, _ in indexed]
    assert log_times == sorted(log_times)  # in file order, never backwards
    for topic in {t for t, _, _ in indexed}:
        assert [s for t, _, s in indexed if t == topic] == list(range(1, 1 + sum(t == topic for t, _, _ in indexed)))


def test_a_frame_is_logged_at_its_capture_and_samples_that_came_while_it_was_encoded_follow_it(tmp_path):
    clock = SimulatedClock(2.0)
    rec = SessionRecorder(tmp_path / "o.mcap", clock=clock, hold_s=0.0, drop_when_busy=False)
    rec.record_frame(noisy_image(0, None, noise=0.0), 1.0)  # captured at 1.0 s, reached the recorder at 2.0 s
    rec.record_joints(0, 0, 1.5, [0.0] * 6)  # arrived at 1.5 s: written only once the frame is
    rec.close(timeout_s=None)
    messages = read_recording(tmp_path / "o.mcap").messages
    assert [m.topic for m in messages if m.topic in (VIDEO_TOPIC, JOINTS_TOPIC)] == [VIDEO_TOPIC, JOINTS_TOPIC]
    frame = next(m for m in messages if m.topic == VIDEO_TOPIC)
    assert frame.log_time_ns == rec.unix_ns(1.0) and frame.payload["timestamp"]["sec"] * 10**9 + frame.payload[
        "timestamp"
    ]["nsec"] == rec.unix_ns(1.0)
    assert rec.late_messages == 0


def test_a_monochrome_camera_is_recorded_as_grey_video(tmp_path):
    from calib_core.recording.frame_track import FrameTrack

    grey = noisy_image(0, None, noise=0.0)[..., 1]
    with SessionRecorder(tmp_path / "mono.mcap", drop_when_busy=False) as rec:
        rec.record_frame(grey, time.monotonic())
    image = FrameTrack(read_recording(tmp_path / "mono.mcap")).image(0)
    assert image.shape == grey.shape + (3,) and np.abs(image.astype(int) - grey[..., None]).mean() < 4


def test_a_frame_later_than_what_was_written_keeps_its_capture_time_and_the_file_its_order(tmp_path):
    clock = SimulatedClock(5.0)
    rec = SessionRecorder(tmp_path / "late.mcap", clock=clock, hold_s=0.0, drop_when_busy=False)
    rec.record_joints(0, 0, 4.0, [0.0] * 6)
    assert rec.flush()
    rec.record_frame(noisy_image(0, None, noise=0.0), 3.0)  # captured before the sample already written
    rec.close(timeout_s=None)
    messages = read_recording(tmp_path / "late.mcap").messages
    frame = next(m for m in messages if m.topic == VIDEO_TOPIC)
    assert rec.late_messages == 1 and frame.log_time_ns == rec.unix_ns(4.0)
    assert frame.payload["timestamp"]["sec"] * 10**9 + frame.payload["timestamp"]["nsec"] == rec.unix_ns(3.0)


def test_a_failing_encoder_stops_the_recorder_without_raising_into_the_caller(tmp_path):
    path = tmp_path / "codec.mcap"
    rec = SessionRecorder(path)
    rec.record_event("before", n=1)
    assert rec.flush()
    rec.record_frame(np.zeros((48, 64, 3), np.uint16), time.monotonic())  # 16 bits a channel: PyAV refuses it as rgb24
    deadline = time.monotonic() + 30
    while rec.failure is None and time.monotonic() < deadline:
        rec.flush(timeout_s=0.2)
    assert rec.failure is not None and "ValueError" in rec.failure
    rec.record_event("after")  # neither raises nor reaches the file
    rec.record_frame(noisy_image(0, None, noise=0.0), time.monotonic())
    assert rec.messages_lost == 2
    started = time.monotonic()
    rec.close()
    assert time.monotonic() - started < 5.0  # returns (the bound measured is in docs/benchmarks/reliability.md)
    contents = read_recording(path)
    assert not contents.complete and [m.payload["kind"] for m in contents.topic(EVENT_TOPIC)] == ["before"]
    fixed = recover(path, tmp_path / "fixed.mcap")
    assert read_recording(tmp_path / "fixed.mcap").complete and len(fixed.messages) == len(contents.messages)


FULL_DISK = textwrap.dedent(
    """
    import resource, signal, sys, time, numpy as np
    from calib_core.recording.recorder import SessionRecorder
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG, as on a full disk
    resource.setrlimit(resource.RLIMIT_FSIZE, (3_000_000, 3_000_000))  # a few chunks of noise video
    rec = SessionRecorder(sys.argv[1])
    rng = np.random.default_rng(0)
    k = 0
    while rec.failure is None and k < 2000:
        rec.record_frame(rng.integers(0, 255, (240, 320, 3), dtype=np.uint8), time.monotonic())
        rec.record_joints(k, 20 * k, time.monotonic(), [0.1 * k] * 6)
        k += 1
        time.sleep(1 / 60)
    started = time.monotonic()
    rec.close()
    print(repr(rec.failure), time.monotonic() - started, rec.messages, flush=True)
    """
)


def test_a_full_disk_is_reported_and_leaves_a_recoverable_file(tmp_path):
    path = tmp_path / "full.mcap"
    run = subprocess.run([sys.executable, "-c", FULL_DISK, str(path)], capture_output=True, text=True, timeout=180)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    failure, close_s, messages = run.stdout.rsplit(" ", 2)
    assert "File too large" in failure and float(close_s) < 5.0
    contents = read_recording(path)
    assert not contents.complete and len(contents.messages) >= int(messages) > 0
    fixed = tmp_path / "fixed.mcap"
    recover(path, fixed)
    assert read_recording(fixed).complete


def test_close_drops_what_the_encoder_cannot_finish_in_time_and_still_finishes_the_file(tmp_path):
    path = tmp_path / "busy.mcap"
    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 255, (1080, 1920, 3), dtype=np.uint8) for _ in range(4)]
    rec = SessionRecorder(path, queue_frames=40)
    for k in range(40):
        rec.record_frame(frames[k % 4], time.monotonic())
    started = time.monotonic()
    rec.close(timeout_s=0.2)
    assert time.monotonic() - started < 5.0  # returned, the writer still busy with its frame
    assert rec.wait_finished(60) and rec.failure is None
    assert rec.frames_dropped > 0 and rec.frames_written + rec.frames_dropped == 40
    contents = read_recording(path)
    assert contents.complete and len(contents.topic(VIDEO_TOPIC)) == rec.frames_written


def test_a_damaged_chunk_is_skipped_and_the_rest_recovered(tmp_path):
    path = record(tmp_path / "s.mcap", n_frames=12, n_solves=1, frames="jpeg")
    summary, _ = _indexed(path)
    full = read_recording(path).messages
    second = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[1]
    data = bytearray(path.read_bytes())
    data[second.chunk_start_offset + second.chunk_length - 40] ^= 0xFF  # a flipped byte in its compressed data
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    contents = read_recording(damaged)
    assert "damaged" in contents.problem and "chunk 2" in contents.problem
    kept = {m.raw for m in contents.messages}
    assert 0 < len(contents.messages) < len(full) and kept < {m.raw for m in full}
    assert full[-1].raw in kept  # the chunks after the damaged one are read too
    recover(damaged, tmp_path / "fixed.mcap")
    fixed_summary, fixed = _indexed(tmp_path / "fixed.mcap")
    assert len(fixed) == len(contents.messages) and fixed_summary.chunk_indexes
