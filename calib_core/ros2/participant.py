"""One DDS participant per domain per process (as one ROS 2 context), shared by every reader and writer."""

from __future__ import annotations

import threading

_lock = threading.Lock()
_participants: dict[int, object] = {}


def participant(domain: int):
    """The process's :class:`cyclonedds.domain.DomainParticipant` on ``domain``."""
    from cyclonedds.domain import DomainParticipant

    with _lock:
        if domain not in _participants:
            _participants[domain] = DomainParticipant(domain)
        return _participants[domain]
