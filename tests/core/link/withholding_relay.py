"""A keyless TCP relay between the workstation and the controller that holds sentences back: what an attacker on
the network (or a misbehaving link box) can do without the key. It passes the controller's bytes on at once; of the
workstation's it delays heartbeats, withholds the first sealed move together with the heartbeat queued before it,
and drops everything after that (Stop included). The withheld sentences are sent on when the test says."""

from __future__ import annotations

import socket
import threading
import time

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.protocol import encode


class WithholdingRelay:
    """Listens on ``port`` (0: any); connects each client to ``controller_port``. ``heartbeat_delay_s``: how late
    heartbeats are passed on."""

    def __init__(self, controller_port: int, heartbeat_delay_s: float = 0.2):
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.controller = socket.create_connection(("127.0.0.1", controller_port), timeout=5)
        self.delay_s = heartbeat_delay_s
        self.withheld: list[str] = []
        self.from_controller: list[str] = []
        self._queue: list[tuple[float, str]] = []  # (due, body) heartbeats on their way
        self._lock = threading.Lock()
        self._dropping = False
        self._stop = threading.Event()
        threading.Thread(target=self._accept, daemon=True).start()
        threading.Thread(target=self._controller_reader, daemon=True).start()
        threading.Thread(target=self._pacer, daemon=True).start()

    def _accept(self) -> None:
        client, _ = self.listener.accept()
        self.client = client
        threading.Thread(target=self._workstation_reader, args=(client,), daemon=True).start()

    def _workstation_reader(self, client: socket.socket) -> None:
        assembler = SentenceAssembler()
        while not self._stop.is_set():
            try:
                data = client.recv(4096)
            except OSError:
                return
            if not data:
                return
            for body in assembler.feed(data):
                self._from_workstation(body)

    def _from_workstation(self, body: str) -> None:
        with self._lock:
            if self._dropping:
                return
            if body.startswith("MVJ,") and ",#" in body:
                pending = [b for _, b in self._queue]
                self.withheld = ([pending[-1]] if pending else []) + [body]
                self._queue.clear()
                self._dropping = True
            elif body.startswith("HBT,"):
                self._queue.append((time.monotonic() + self.delay_s, body))
            else:
                self.controller.sendall(encode(body))

    def _pacer(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            with self._lock:
                due = [b for t, b in self._queue if t <= now]
                self._queue = [(t, b) for t, b in self._queue if t > now]
            for body in due:
                self.controller.sendall(encode(body))
            time.sleep(0.005)

    def _controller_reader(self) -> None:
        assembler = SentenceAssembler()
        while not self._stop.is_set():
            try:
                data = self.controller.recv(4096)
            except OSError:
                return
            if not data:
                return
            self.from_controller += assembler.feed(data)
            try:
                self.client.sendall(data)
            except (OSError, AttributeError):
                pass  # the workstation is gone: the relay keeps the controller's side open

    def release(self) -> None:
        """Send the withheld sentences on to the controller, in order."""
        for body in self.withheld:
            self.controller.sendall(encode(body))

    def ask(self, body: str) -> None:
        self.controller.sendall(encode(body))

    def close(self) -> None:
        self._stop.set()
        for s in (self.controller, self.listener):
            s.close()
