"""A recorder in a child process that a test can kill: its script, starting it and reading its output."""

import subprocess
import sys
import textwrap
import time

RECORDER = textwrap.dedent(
    """
    import sys, time, numpy as np
    from calib_core.recording.recorder import SessionRecorder
    rec = SessionRecorder(sys.argv[1], drop_when_busy=False)
    rec.record_setup(note="killed on purpose")
    k = 0
    while True:
        image = np.zeros((240, 320, 3), np.uint8) + np.linspace(0, 200, 320).astype(np.uint8)[None, :, None]
        image[100:140, (k * 3) % 280 : (k * 3) % 280 + 40] = (240, 40, 40)
        now = time.monotonic()
        rec.record_frame(image, now)
        for j in range(3):
            rec.record_joints(3 * k + j, 20 * (3 * k + j), now, [0.1 * k] * 6)
        k += 1
        print(rec.messages, rec.frames_written, flush=True)
        time.sleep(1 / 30)
    """
)


def start(script: str, *args) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", script, *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def read_until(proc: subprocess.Popen, enough) -> str:
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            raise AssertionError(f"the child stopped: {proc.stderr.read()[-2000:]}")
        if enough(line):
            return line
    raise AssertionError("the child did not get far enough")
