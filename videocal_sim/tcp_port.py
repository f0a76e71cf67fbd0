"""The simulated controller's TCP port: who may talk to the robot, and who waits.

A controller with a link key serves one authenticated workstation at a time, and until one holds a session it
hears every client that connects, as a shared serial line would: each client's sentences are answered to it, the
joint samples go to all of them, and the first whose handshake completes keeps the port (the others are let go;
newcomers then get ``ERR,BUSY``). So a client without the key can neither take the port nor push the key's holder
off it: a flood of keyless connections once displaced a workstation 1 s away before its hello had crossed the link,
every time, and it never opened a session. Bounds: a few waiting clients per address (a flood from one host
replaces its own oldest), a few dozen in all; a client whose hello proved the key is never replaced. Only the client
whose hello was answered may send the ``AUT`` that answers it (another's wrong ``AUT`` would spend its one try).

A controller without a key keeps its first client, as before authentication existed.
"""

from __future__ import annotations

import contextlib
import socket
import time
from dataclasses import dataclass, field

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.protocol import Ack, ErrorReply, HelloReply, encode

WAITING_PER_ADDRESS = 2
"""Clients without a session kept from one address: a workstation reconnecting may briefly have two."""
WAITING_IN_ALL = 32
"""Clients without a session kept in all (each holds a socket and a sentence buffer of at most 320 bytes)."""
_BUSY = encode(ErrorReply("BUSY", "another workstation is connected; this connection is closed").body())


@dataclass(eq=False)
class _Client:
    sock: socket.socket
    address: str
    since: float
    assembler: SentenceAssembler = field(default_factory=SentenceAssembler)
    proven: bool = False
    """Its hello proved the link key (answered with the controller's proof)."""


class TcpPort:
    """The port on loopback ``port`` (0: any free one); ``keyed``: the controller authenticates its workstation.

    ``fds()`` to select on; ``read(fd)`` gives ``(client, bodies)`` (the sentences it completed, or none);
    ``heard(client, replies)`` tells the port what the controller answered it; ``write(data, to)`` sends to one client
    or (``to=None``) to the line: the session's holder, else every waiting client. ``generation`` counts the ends of
    sessions by a lost holder (the controller then forgets its session)."""

    def __init__(self, port: int, keyed: bool):
        self.keyed = keyed
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind(("127.0.0.1", port))
        self.server.listen(8)
        self.clients: list[_Client] = []
        self.holder: _Client | None = None
        self.refused = 0
        self.replaced = 0
        self.generation = 0
        self.path = f"socket://127.0.0.1:{self.server.getsockname()[1]}"

    def fds(self) -> list:
        return [self.server] + [c.sock for c in self.clients]

    def read(self, fd) -> tuple[_Client | None, list[str]]:
        if fd is self.server:
            self._accept()
            return None, []
        client = next((c for c in self.clients if c.sock is fd), None)
        if client is None:
            return None, []
        try:
            data = client.sock.recv(4096)
        except OSError:
            data = b""
        if not data:
            self._drop(client)
            return None, []
        return client, client.assembler.feed(data)

    def accepts(self, client: _Client, body: str) -> bool:
        """Whether ``client``'s sentence ``body`` goes to the controller: an ``AUT`` only from the client whose hello
        was answered (on a keyed port)."""
        if not self.keyed or not body.startswith("AUT,"):
            return True
        return client.proven

    def heard(self, client: _Client, replies: list) -> None:
        """The controller answered ``client`` with ``replies``: a hello proven, or a session opened."""
        if not self.keyed or client not in self.clients:
            return
        for reply in replies:
            if isinstance(reply, HelloReply):
                for other in self.clients:
                    other.proven = other is client  # the controller answers one hello at a time
            elif isinstance(reply, Ack) and reply.cmd == "AUT":
                self.holder = client
                for other in [c for c in self.clients if c is not client]:
                    self._close(other)  # let go: the workstation holds the port now

    def write(self, data: bytes, to: _Client | None = None) -> None:
        targets = [to] if to is not None else ([self.holder] if self.holder is not None else list(self.clients))
        for client in targets:
            if client is None or client not in self.clients:
                continue
            try:
                client.sock.sendall(data)
            except OSError:
                self._drop(client)

    def close(self) -> None:
        for client in list(self.clients):
            self._close(client)
        self.server.close()

    def _accept(self) -> None:
        conn, (address, _) = self.server.accept()
        conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        for client in [c for c in self.clients if not _alive(c.sock)]:
            self._drop(client)  # gone, its end of stream not read yet: it holds nothing
        if self.holder is not None or (not self.keyed and self.clients):
            # One workstation at a time: a newcomer does not take the robot over.
            with contextlib.suppress(OSError):
                conn.sendall(_BUSY)
            conn.close()
            self.refused += 1
            return
        if self.keyed and not self._room_for(address):
            with contextlib.suppress(OSError):
                conn.sendall(_BUSY)
            conn.close()
            self.refused += 1
            return
        self.clients.append(_Client(conn, address, time.monotonic()))

    def _room_for(self, address: str) -> bool:
        """Make room for a newcomer from ``address`` by letting go a waiting client that proved nothing: that
        address's oldest when it has its share, else the oldest of the address with most; ``False`` when every one
        proved the key."""
        same = [c for c in self.clients if c.address == address and not c.proven]
        if len([c for c in self.clients if c.address == address]) >= WAITING_PER_ADDRESS:
            if not same:
                return False
            self._close(same[0])
            self.replaced += 1
        if len(self.clients) >= WAITING_IN_ALL:
            counts: dict[str, int] = {}
            for c in self.clients:
                counts[c.address] = counts.get(c.address, 0) + 1
            unproven = [c for c in self.clients if not c.proven]
            if not unproven:
                return False
            self._close(max(unproven, key=lambda c: (counts[c.address], -c.since)))
            self.replaced += 1
        return True

    def _drop(self, client: _Client) -> None:
        """``client`` went away (or its writes fail): a holder's loss ends the session."""
        if client is self.holder:
            self.holder = None
            self.generation += 1
        self._close(client)

    def _close(self, client: _Client) -> None:
        with contextlib.suppress(OSError):
            client.sock.close()
        if client in self.clients:
            self.clients.remove(client)
        if client is self.holder:
            self.holder = None
            self.generation += 1


def _alive(sock: socket.socket) -> bool:
    """The client is still there (a peer that closed reads as end of stream)."""
    try:
        return sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) != b""
    except BlockingIOError:
        return True
    except OSError:
        return False
