"""Carrying the simulated controller over a pseudo-terminal or a loopback TCP port.

The pty is put in raw mode (no echo, no CR/LF translation) and its slave path printed, so any
serial program can open it; ``link_path`` keeps a stable symlink to the current pty across
simulated reboots. Simulated faults: garbage/corrupt/dropped sentences, a device that
disappears (``disconnect_after_s``) or reboots (``reboot_after_s``: gone for ``reboot_downtime_s``,
then back with a fresh joint-sample sequence).
"""

from __future__ import annotations

import contextlib
import os
import select
import socket
import time
import tty
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from calib_core.link.assembler import SentenceAssembler
from videocal_sim.controller_sim import ControllerLogic
from videocal_sim.wire_faults import FaultInjector
from calib_core.link.protocol import ErrorReply, encode


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

    def fds(self) -> list[int]:
        return [self.master]

    def read(self, fd: int) -> bytes:
        try:
            return os.read(self.master, 4096)
        except OSError:
            return b""

    def write(self, data: bytes) -> None:
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


class _TcpEndpoint:
    """One workstation at a time on a TCP port. ``holds_session()``: the connected client has an
    authenticated session (``None``: a controller without a key, where the first client keeps the
    port). A client without a session does not lock the port: the next connection takes its place."""

    def __init__(self, port: int, holds_session: Callable[[], bool] | None = None):
        self.holds_session = holds_session
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind(("127.0.0.1", port))
        self.server.listen(1)
        self.client: socket.socket | None = None
        self.refused = 0
        self.generation = 0  # counts client changes: a new or lost client ends the authenticated session
        self.path = f"socket://127.0.0.1:{self.server.getsockname()[1]}"

    @staticmethod
    def _alive(client: socket.socket) -> bool:
        """The connected client is still there (a peer that closed reads as end of stream)."""
        try:
            return client.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) != b""
        except BlockingIOError:
            return True
        except OSError:
            return False

    def fds(self) -> list:
        return [self.server] + ([self.client] if self.client else [])

    def read(self, fd) -> bytes:
        if fd is self.server:
            conn, _ = self.server.accept()
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            keeps_port = self.holds_session is None or self.holds_session()
            if self.client is not None and self._alive(self.client) and keeps_port:
                # One workstation at a time: a second client does not take the robot over.
                with contextlib.suppress(OSError):
                    conn.sendall(
                        encode(ErrorReply("BUSY", "another workstation is connected; this connection is closed").body())
                    )
                conn.close()
                self.refused += 1
                return b""
            if self.client is not None:
                self.client.close()
            self.client = conn
            self.generation += 1
            return b""
        try:
            data = self.client.recv(4096)
        except OSError:
            data = b""
        if not data:
            self.client.close()
            self.client = None
            self.generation += 1
        return data

    def write(self, data: bytes) -> None:
        if self.client is None:
            return
        try:
            self.client.sendall(data)
        except OSError:
            self.client.close()
            self.client = None
            self.generation += 1

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        self.server.close()


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
        return (
            _PtyEndpoint(options.link_path)
            if options.pty
            else _TcpEndpoint(options.tcp_port, None if logic.key is None else lambda: logic.session_open)
        )

    endpoint = open_endpoint()
    announce(endpoint.path)
    assembler = SentenceAssembler()
    started = time.monotonic()
    rebooted = False

    def send(messages) -> None:
        for msg in messages:
            endpoint.write(faults.apply(encode(msg.body())))

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
                assembler.reset()
                endpoint = open_endpoint()
                announce(endpoint.path)
                rebooted = True
                continue
            timeout = max(0.0, min(logic.next_deadline() - now, 0.05))
            ready, _, _ = select.select(endpoint.fds(), [], [], timeout)
            for fd in ready:
                generation = getattr(endpoint, "generation", 0)
                data = endpoint.read(fd)
                if getattr(endpoint, "generation", 0) != generation:
                    logic.end_session()
                    assembler.reset()
                for body in assembler.feed(data):
                    send(logic.handle(body))
            send(logic.tick())
    finally:
        endpoint.close()
