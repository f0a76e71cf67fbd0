"""One DDS participant per domain per process (as one ROS 2 context), shared by every reader and writer.

A domain's Cyclone DDS configuration is ``CYCLONEDDS_URI``'s (as for any ROS 2 program), unless
:func:`configure` gave one before its first participant (a far link's own interface and peers)."""

from __future__ import annotations

import threading

from calib_core.errors import VideocalError

_lock = threading.Lock()
_participants: dict[int, object] = {}
_domains: dict[int, object] = {}


class DomainConfiguredError(VideocalError, RuntimeError):
    """A domain's configuration given after a participant joined it (DDS reads it once)."""


def configure(domain: int, config_xml: str) -> None:
    """Give ``domain`` its Cyclone DDS configuration (XML) for this process, before any participant joins it."""
    from cyclonedds.domain import Domain

    with _lock:
        if domain in _participants or domain in _domains:
            raise DomainConfiguredError(
                f"ROS domain {domain} is already in use in this process: its DDS configuration is fixed"
            )
        _domains[domain] = Domain(domain, config_xml)


def participant(domain: int):
    """The process's :class:`cyclonedds.domain.DomainParticipant` on ``domain``."""
    from cyclonedds.domain import DomainParticipant

    with _lock:
        if domain not in _participants:
            _participants[domain] = DomainParticipant(domain)
        return _participants[domain]


def delete(*entities) -> None:
    """Delete DDS entities now (readers, writers, wait sets; DDS deletes an entity's conditions with it), not when
    Python collects them: until then other programs on the domain still discover a closed reader or writer (a client
    would find the action server of an arm that was closed). ``None`` is skipped; a second deletion does nothing.
    Only once no thread uses them."""
    for entity in entities:
        if entity is not None:
            entity.__del__()


def release(domain: int) -> None:
    """Leave ``domain`` in this process: its participant and everything under it are deleted, and a configuration
    given by :func:`configure` is forgotten (a far link's interface that is gone must not be written to). Readers and
    writers made on it must not be used afterwards."""
    with _lock:
        entities = [_participants.pop(domain, None), _domains.pop(domain, None)]
    for entity in entities:
        if entity is not None:
            entity.__del__()  # DDS deletes the children with their parent
