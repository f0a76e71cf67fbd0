"""The one writer: old file intact on failure, permissions kept, symlinks followed, a library's
hidden write error caught by reading back."""

import os
import stat
import subprocess
import sys

import pytest

from calib_core.atomic_file import atomic_path, atomic_write_text
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics, save_intrinsics
from calib_core.errors import FileWriteError


def test_permissions_are_kept_and_a_symlink_stays_a_link(tmp_path):
    target = tmp_path / "real.json"
    target.write_text("old")
    os.chmod(target, 0o640)
    link = tmp_path / "link.json"
    link.symlink_to(target)
    atomic_write_text(link, "new")
    assert link.is_symlink() and target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640


def test_a_write_that_does_not_read_back_leaves_the_old_file(tmp_path):
    target = tmp_path / "camera.yaml"
    intrinsics = Intrinsics(800.0, 800.0, 320.0, 240.0, 640, 480)
    save_intrinsics(target, intrinsics)
    before = target.read_bytes()
    # What cv2.FileStorage does on a full disk: the call returns, the file is empty.
    with pytest.raises(FileWriteError, match="nothing reached the disk"):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"")
    with pytest.raises(FileWriteError, match="does not read back"):
        with atomic_path(target, lambda p: load_intrinsics(p)) as tmp:
            tmp.write_text("camera_matrix: [1, 2")
    assert target.read_bytes() == before and not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert load_intrinsics(target).fu == 800.0


def test_a_full_disk_while_opencv_writes_is_an_error_and_the_old_file_stays(tmp_path):
    """The disk fills while cv2.FileStorage writes (a file-size limit on the process: writes past 64
    bytes fail as on a full disk, and FileStorage says nothing): the save raises, the old file is whole."""
    target = tmp_path / "camera.yaml"
    save_intrinsics(target, Intrinsics(800.0, 800.0, 320.0, 240.0, 640, 480))
    before = target.read_bytes()
    code = f"""
import resource, signal
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import save_intrinsics
from calib_core.errors import FileWriteError
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (64, 64))
try:
    save_intrinsics({str(target)!r}, Intrinsics(900.0, 900.0, 320.0, 240.0, 640, 480))
except FileWriteError as exc:
    print("refused:", exc)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert "refused:" in out.stdout and "camera.yaml" in out.stdout, out.stderr
    assert target.read_bytes() == before and load_intrinsics(target).fu == 800.0
