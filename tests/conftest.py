"""Test-wide set-up: headless Qt and offscreen VTK before anything imports them."""

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkOSOpenGLRenderWindow")

import tempfile  # noqa: E402

from calib_core.solver.kernel_cache import kernel_cache_folder  # noqa: E402

# The solver's compiled kernels are the one per-user file the tests share with the user: they are machine code named
# by the kernels' sources, which `make` compiles at install. In a throw-away cache every test process (each worker and
# every command a test starts) compiled them again, about a minute of CPU each.
_kernels = kernel_cache_folder()
if _kernels is not None:
    os.environ.setdefault("NUMBA_CACHE_DIR", _kernels)

# Autosaves, window settings and other per-user files (platformdirs and QSettings follow the XDG folders) go to
# throw-away folders, never into the home of whoever runs the tests.
os.environ["XDG_DATA_HOME"] = tempfile.mkdtemp(prefix="videocal-test-data-")
os.environ["XDG_CONFIG_HOME"] = tempfile.mkdtemp(prefix="videocal-test-config-")
os.environ["XDG_STATE_HOME"] = tempfile.mkdtemp(prefix="videocal-test-state-")
os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="videocal-test-cache-")


import sys

import pytest

_exit_status = {"code": 0}


@pytest.hookimpl(trylast=True)
def pytest_sessionfinish(session, exitstatus):
    _exit_status["code"] = int(exitstatus)


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config):
    # After the last report is written, leave without the interpreter's final garbage collection:
    # tearing down Qt, VTK (OSMesa) and numba objects in arbitrary order at exit is slow and has
    # crashed before (PySide6 6.12.0's Signal.emit refcount bug, now excluded in pyproject.toml).
    # The exit status is kept.
    if os.environ.get("VIDEOCAL_TEST_CLEAN_EXIT") != "1":
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status["code"])


@pytest.fixture
def domain(monkeypatch):
    """A ROS 2 domain of this test's own, held by no other process on the machine (another test suite running at once
    included), so nothing else on the machine's DDS is heard; ``ROS_DOMAIN_ID`` is set to it."""
    from tests.ros_domains import reserved_domain

    with reserved_domain() as value:
        monkeypatch.setenv("ROS_DOMAIN_ID", str(value))
        yield value
