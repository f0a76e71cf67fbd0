"""One error boundary at the edge of the UI: an action that fails becomes a message, never a crash."""

from __future__ import annotations

import functools
import sys
import traceback
from collections.abc import Callable

from calib_core.errors import VideocalError


def guarded(report: Callable[[str], None]):
    """Decorate an action handler: user mistakes (``VideocalError``, ``ValueError``, ``KeyError``)
    are reported in words; anything else as an internal error with its traceback on stderr.

    The wrapper returns nothing, so a slot never hands Qt a value its signal does not expect."""

    def wrap(fn):
        @functools.wraps(fn)
        def run(*args, **kwargs):
            try:
                fn(*args, **kwargs)
            except (VideocalError, ValueError, KeyError, RuntimeError) as exc:
                report(str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc))
            except Exception as exc:  # the boundary: nothing escapes into Qt's event loop
                traceback.print_exc(file=sys.stderr)
                report(f"internal error ({type(exc).__name__}): {exc}")

        return run

    return wrap
