"""A workstation that is not videocal's: raw sentences written to a controller's port, its first error read back."""

from __future__ import annotations

import time

import serial

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.protocol import ErrorReply, encode, parse_body


def first_error_reply(url: str, body: str, timeout_s: float = 5.0) -> ErrorReply:
    """Send ``body`` as a sentence to ``url`` and return the first ``ERR`` the controller answers with."""
    port = serial.serial_for_url(url, timeout=0.05)
    assembler, replies = SentenceAssembler(), []
    try:
        port.write(encode(body))
        deadline = time.monotonic() + timeout_s
        while not any(isinstance(r, ErrorReply) for r in replies) and time.monotonic() < deadline:
            replies += [parse_body(b) for b in assembler.feed(port.read(256))]
    finally:
        port.close()
    errors = [r for r in replies if isinstance(r, ErrorReply)]
    assert errors, f"no ERR from {url} within {timeout_s} s (got {replies})"
    return errors[0]
