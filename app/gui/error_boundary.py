"""One error boundary at the edge of the UI: an action that fails becomes a message, never a crash.

A user's mistake raises a :class:`~calib_core.errors.VideocalError`: its message is shown as it is; so is the
machine's refusal (an :class:`OSError`: a read-only folder, a full disk), with the file it names.
Anything else is a bug: its traceback goes to a log file under the user's state folder, and the
operator is told an internal error happened and where its details are.
"""

from __future__ import annotations

import functools
import time
import traceback
from collections.abc import Callable
from pathlib import Path

import platformdirs

from calib_core.errors import VideocalError


def internal_error_log() -> Path:
    """Where internal errors are written: ``<user state folder>/videocal/internal-errors.log``."""
    return Path(platformdirs.user_state_dir("videocal")) / "internal-errors.log"


def record_internal_error(exc: BaseException) -> Path:
    """Append ``exc`` with its traceback to :func:`internal_error_log`; returns the file."""
    path = internal_error_log()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("a", encoding="utf-8") as log:
            log.write(f"--- {time.strftime('%Y-%m-%d %H:%M:%S')}\n")
            log.write("".join(traceback.format_exception(exc)))
    except OSError:
        pass  # nowhere to write: the message still names the error
    return path


def refused_by_the_system(exc: OSError) -> str:
    """One line for an :class:`OSError` that no part of videocal turned into its own message: the file it names
    and the system's reason (``Read-only file system``, ``No space left on device``)."""
    where = f"{exc.filename}: " if exc.filename else ""
    return f"{where}{exc.strerror or exc} (the system refused it)"


def attempt(report: Callable[[str], None], fn, *args, **kwargs) -> bool:
    """Run ``fn``; True if it succeeded. A failure is reported (see the module) and gives False."""
    try:
        fn(*args, **kwargs)
    except VideocalError as exc:
        report(str(exc))
        return False
    except OSError as exc:  # the machine refused (a read-only folder, a full disk): the operator's to mend, no bug
        report(refused_by_the_system(exc))
        return False
    except Exception as exc:  # the boundary: nothing escapes into Qt's event loop
        log = record_internal_error(exc)
        report(f"internal error ({type(exc).__name__}: {exc}); the details are in {log}")
        return False
    return True


def guarded(report: Callable[[str], None]):
    """Decorate an action handler with :func:`attempt`. The wrapper returns nothing, so a slot
    never hands Qt a value its signal does not expect."""

    def wrap(fn):
        @functools.wraps(fn)
        def run(*args, **kwargs):
            attempt(report, fn, *args, **kwargs)

        return run

    return wrap
