"""ROS 2 domains for tests, reserved across every process on the machine: two test suites running at once (a
developer's and a CI job's, or `make test` twice) each had a domain chosen by process id, and sometimes the same
one, so one suite's simulated arm answered the other's action client. A domain is taken by an exclusive lock on a
file of its own; the lock goes with the holder (released on exit, or by the kernel when the process dies).

ROS 2's safe domain ids are 0-101 on Linux: above, a domain's DDS ports fall in the ephemeral range (32768 and up),
where any other socket (a GigE stream, a UDP client) may hold one. Tests take 1-70; the demo's private domains are
71-100."""

from __future__ import annotations

import fcntl
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

TEST_DOMAINS = range(1, 71)
LOCKS = Path(tempfile.gettempdir()) / "videocal-test-ros-domains"
_next = [os.getpid() % len(TEST_DOMAINS)]  # where this process looks first: past the last domain it took


@contextmanager
def reserved_domain():
    """A ROS 2 domain id no other process on this machine holds while the block runs (:data:`TEST_DOMAINS`)."""
    LOCKS.mkdir(exist_ok=True)
    # Where to start looking: by process at first, so suites rarely contend, then past the last domain this process
    # took, so it comes back to one only after all the others: what an earlier test left on a domain (a participant
    # not yet collected, a child process still leaving) is not heard by a later one (a leftover action server once
    # made a test's client find a server where its arm had none).
    start = _next[0]
    for k in range(len(TEST_DOMAINS)):
        index = (start + k) % len(TEST_DOMAINS)
        domain = TEST_DOMAINS[index]
        handle = open(LOCKS / f"{domain}.lock", "w")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            continue
        _next[0] = index + 1
        try:
            yield domain
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
            handle.close()
        return
    raise RuntimeError(
        f"every ROS 2 test domain ({TEST_DOMAINS.start}-{TEST_DOMAINS.stop - 1}) is held by another process"
    )
