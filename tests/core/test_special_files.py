"""A workcell that is a FIFO blocked the load forever. A pipe or a device is refused by name."""

import os
import subprocess
import sys

import pytest

from calib_core.documents import read_text
from calib_core.errors import FileFormatError


def test_a_fifo_is_refused_not_read(tmp_path):
    fifo = tmp_path / "workcell.yaml"
    os.mkfifo(fifo)
    with pytest.raises(FileFormatError, match="workcell.yaml.*not a regular file"):
        read_text(fifo, "workcell file")
    with pytest.raises(FileFormatError, match="not a regular file"):
        read_text("/dev/zero", "workcell file")
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "render", "--workcell", str(fifo), "--out", str(tmp_path / "x.png")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "not a regular file" in run.stderr and "Traceback" not in run.stderr
