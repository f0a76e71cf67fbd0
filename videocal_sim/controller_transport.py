"""Carrying the simulated controller over a pseudo-terminal or a loopback TCP port.

The pty is put in raw mode (no echo, no CR/LF translation) and its slave path printed, so any
serial program can open it; ``link_path`` keeps a stable symlink to the current pty across
simulated reboots. Simulated faults: garbage/corrupt/dropped sentences, a device that
disappears (``disconnect_after_s``) or reboots (``reboot_after_s``: gone for ``reboot_downtime_s``,
then back with a fresh joint-sample sequence).
"""

from __future__ import annotations

import os
import select
import time
import tty
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from calib_core.link.assembler import SentenceAssembler
from videocal_sim.controller_sim import ControllerLogic
from videocal_sim.tcp_port import TcpPort
from videocal_sim.wire_faults import FaultInjector
from calib_core.link.protocol import encode


@dataclass
class SimOptions:
    """How to serve: ``pty`` or ``tcp_port`` (loopback only)."""

    pty: bool = False
    tcp_port: int | None = None
    link_path: Path | None = None
    disconnect_after_s: float | None = None
    reboot_after_s: float | None = None
    reboot_downtime_s: float = 1.0


class _PtyEndpoint:
    def __init__(self, link_path: Path | None):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        tty.setraw(self.master)
        # Like a serial line, a pty nobody reads must not stall the controller: drop what does not fit.
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)
        self.link_path = link_path
        if link_path is not None:
            if link_path.exists() and not link_path.is_symlink():
                raise FileExistsError(
                    f"--link {link_path}: a file is there and it is not a link; give another path (nothing was "
                    "replaced)"
                )
            tmp = Path(str(link_path) + ".tmp")
            if tmp.is_symlink() or tmp.exists():
                tmp.unlink()
            tmp.symlink_to(self.path)
            os.replace(tmp, link_path)

        self.assembler = SentenceAssembler()  # one line, shared by whoever writes on it

    def fds(self) -> list[int]:
        return [self.master]

    def read(self, fd: int) -> tuple[None, list[str]]:
        try:
            data = os.read(self.master, 4096)
        except OSError:
            data = b""
        return None, self.assembler.feed(data)

    def accepts(self, client, body: str) -> bool:
        return True  # one line: whoever writes on it is heard, as on a serial cable

    def heard(self, client, replies: list) -> None:
        pass

    def write(self, data: bytes, to=None) -> None:
        try:
            os.write(self.master, data)
        except (BlockingIOError, OSError):
            pass

    def close(self) -> None:
        for fd in (self.master, self.slave):
            try:
                os.close(fd)
            except OSError:
                pass


def serve(
    logic: ControllerLogic,
    options: SimOptions,
    faults: FaultInjector | None = None,
    announce: Callable[[str], None] = print,
    should_stop: Callable[[], bool] = lambda: False,
) -> None:
    """Serve ``logic`` until ``should_stop()`` or a simulated disconnect; ``announce`` receives
    the device path (again after each reboot)."""
    if options.pty == (options.tcp_port is not None):
        raise ValueError("choose exactly one of a pty or a TCP port")
    faults = faults or FaultInjector()

    def open_endpoint():
        return _PtyEndpoint(options.link_path) if options.pty else TcpPort(options.tcp_port, logic.key is not None)

    endpoint = open_endpoint()
    announce(endpoint.path)
    started = time.monotonic()
    rebooted = False

    def send(messages, to=None) -> None:
        for msg in messages:
            endpoint.write(faults.apply(encode(msg.body())), to)

    try:
        while not should_stop():
            now = time.monotonic()
            if options.disconnect_after_s is not None and now - started >= options.disconnect_after_s:
                return
            if options.reboot_after_s is not None and not rebooted and now - started >= options.reboot_after_s:
                endpoint.close()
                time.sleep(options.reboot_downtime_s)
                # a rebooted controller forgets streams, moves and its session
                logic.__init__(logic.model, logic.joints_deg, logic.clock, key=logic.key, on_refusal=logic.on_refusal)
                endpoint = open_endpoint()
                announce(endpoint.path)
                rebooted = True
                continue
            timeout = max(0.0, min(logic.next_deadline() - now, 0.05))
            ready, _, _ = select.select(endpoint.fds(), [], [], timeout)
            for fd in ready:
                generation = getattr(endpoint, "generation", 0)
                client, bodies = endpoint.read(fd)
                if getattr(endpoint, "generation", 0) != generation:
                    logic.end_session()  # its holder went away
                for body in bodies:
                    if not endpoint.accepts(client, body):
                        continue  # another's AUT: it would spend the one try of the hello in force
                    replies = logic.handle(body)
                    endpoint.heard(client, replies)
                    send(replies, client)
            send(logic.tick())
    finally:
        endpoint.close()
