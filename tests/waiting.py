"""Waiting in tests on the predicate the code itself uses (polled), never on a fixed sleep."""

import time


def wait_until(predicate, timeout_s: float = 10.0) -> bool:
    """True as soon as ``predicate()`` holds, False after ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True
