"""The session's recording: at most one recorder at a time, tapping the operator core's events while it runs.

Who starts and stops recording (the window's File menu, a test, a script) holds this, not the whole core: the
recorder is made, connected to what it records, polled and closed here.
"""

from __future__ import annotations

from collections.abc import Callable

from calib_core.operator.operator_log import OperatorLog


class SessionRecording:
    """Records the session to one MCAP file at a time through ``tap(recorder)``, which connects a recorder to what is
    recorded and returns something with ``detach()`` (the core's :class:`~calib_core.operator.recording_tap.
    RecordingTap` on its events); says what it did in ``log``."""

    def __init__(self, tap: Callable[[object], object], log: OperatorLog):
        self._connect = tap
        self._log = log
        self.recorder = None
        """The :class:`~calib_core.recording.recorder.SessionRecorder` writing now, or ``None``."""
        self._tap = None

    def start(self, path, **options) -> None:
        """Record the session to ``path`` (MCAP), ending any recording before; ``options`` go to the
        :class:`~calib_core.recording.recorder.SessionRecorder` (``frames="jpeg"``, ``clock``...)."""
        from calib_core.recording.recorder import SessionRecorder

        self.stop()
        recorder = SessionRecorder(path, **options)
        self._tap = self._connect(recorder)
        self.recorder = recorder
        self._log.say(f"recording to {path}")

    def failure(self) -> str | None:
        """Poll the recorder (the window does on its status tick): when its disk or encoder failed, the
        recording is stopped and the reason returned, once. ``None`` while all is well."""
        rec = self.recorder
        if rec is None or rec.failure is None:
            return None
        failure = rec.failure
        self.stop()
        return failure

    def stop(self) -> None:
        """End the recording (its file finished in the background), saying how it ended."""
        rec = self.recorder
        if rec is None:
            return
        self._tap.detach()
        rec.close()
        if rec.failure is not None:
            self._log.say(
                f"recording {rec.path} stopped: {rec.failure}. The file keeps what was written before; `videocal "
                "recover` completes it"
            )
        elif not rec.finished:
            self._log.say(f"recording {rec.path}: the file is being finished in the background")
        else:
            dropped = f", {rec.frames_dropped} frames dropped" if rec.frames_dropped else ""
            self._log.say(
                f"recording {rec.path} closed ({rec.messages} messages, {rec.frames_written} frames{dropped})"
            )
        self.recorder, self._tap = None, None

    def close(self, wait_s: float = 5.0) -> None:
        """Stop, and wait up to ``wait_s`` for the file to be finished (an exit does not cut it off)."""
        rec = self.recorder
        self.stop()
        if rec is not None:
            rec.wait_finished(wait_s)
