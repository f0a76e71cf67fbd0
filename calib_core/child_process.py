"""Child processes that end with their parent: a ``preexec_fn`` asking Linux to send the child SIGKILL when the
process that started it dies (``PR_SET_PDEATHSIG``), so a user's Ctrl+C or a killed command leaves nothing running
(a xacro expansion of ``${9**9**9}`` went on computing after its parent was killed)."""

from __future__ import annotations

import ctypes
import signal

_PR_SET_PDEATHSIG = 1


def die_with_parent() -> None:
    """For ``subprocess``'s ``preexec_fn``: this child is killed when its parent dies (Linux; elsewhere nothing)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass
