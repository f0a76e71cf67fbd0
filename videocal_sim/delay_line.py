"""A long-distance link between the workstation and a simulated cell: a TCP relay that holds every
chunk for a one-way delay, varies it (jitter), and makes some chunks late as TCP does when a segment
is lost on the way (the receiver gets nothing until the sender has sent it again).

Why a relay in user space and not the kernel's ``netem``: the machines this runs on (CI containers)
have no ``sch_netem``, and every connector that crosses the delay line (videocal's own protocol over
``socket://``, Universal Robots' RTDE, script and dashboard ports) runs over TCP, whose answer to a
lost segment is a late one, never a missing one. The loss model is TCP's fast retransmit: a lost
chunk arrives one round trip plus 200 ms (Linux's least retransmission timeout) later than its
delay said, and everything behind it waits (TCP delivers in order).

Delays: each chunk read from one side is due ``one_way_s * (1 + jitter * u)`` later, ``u`` uniform
in [-1, 1]; never before the chunk ahead of it (in order). Seeded: a run can be repeated.
"""

from __future__ import annotations

import heapq
import random
import select
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

_CHUNK = 65536
_RETRANSMIT_MIN_S = 0.2


@dataclass(frozen=True)
class LinkWeather:
    """The path between the two sides: ``one_way_s`` (s) mean one-way delay, ``jitter`` its spread
    as a fraction of it (0.3: +-30 %), ``loss`` the fraction of chunks lost once on the way (0.01: 1 %)."""

    one_way_s: float = 0.0
    jitter: float = 0.0
    loss: float = 0.0

    def __post_init__(self):
        if not (0.0 <= self.one_way_s <= 10.0):
            raise ValueError(f"one-way delay must lie in [0, 10] s, got {self.one_way_s}")
        if not (0.0 <= self.jitter < 1.0):
            raise ValueError(f"jitter must lie in [0, 1), got {self.jitter}")
        if not (0.0 <= self.loss < 0.5):
            raise ValueError(f"loss must lie in [0, 0.5), got {self.loss}")

    def crossing(self, rng: random.Random) -> tuple[float, bool]:
        """How long one chunk takes to cross (s), its loss included, and whether it was lost once."""
        delay = self.one_way_s * (1.0 + self.jitter * rng.uniform(-1.0, 1.0))
        lost = bool(self.loss) and rng.random() < self.loss
        if lost:
            delay += 2.0 * self.one_way_s + _RETRANSMIT_MIN_S
        return delay, lost


@dataclass
class DelayStats:
    """What crossed: ``chunks`` and ``bytes`` per direction (``up``: workstation to cell), ``late``: chunks lost
    once."""

    chunks: dict = field(default_factory=lambda: {"up": 0, "down": 0})
    bytes: dict = field(default_factory=lambda: {"up": 0, "down": 0})
    late: int = 0
    connections: int = 0


class DelayLine:
    """Listens on ``listen`` (host, port; port 0: any free one, see :attr:`address`) and relays each
    connection to ``target`` through ``weather``. ``tap(direction, data)`` sees every chunk as it is
    delivered (``"up"`` towards the target). Start with :meth:`start`, end with :meth:`close`."""

    def __init__(
        self,
        listen: tuple[str, int],
        target: tuple[str, int],
        weather: LinkWeather,
        *,
        seed: int = 0,
        tap: Callable[[str, bytes], None] | None = None,
    ):
        self.target = target
        self.weather = weather
        self.stats = DelayStats()
        self._rng = random.Random(seed)
        self._rng_lock = threading.Lock()
        self._tap = tap
        self._server = socket.create_server(listen, reuse_port=False)
        self._server.settimeout(0.1)
        self.address = self._server.getsockname()[:2]
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._sockets: list[socket.socket] = []

    def start(self) -> DelayLine:
        self._spawn(self._accept_loop, "delay-line accept")
        return self

    def close(self) -> None:
        self._stop.set()
        self._server.close()
        for s in list(self._sockets):
            try:
                s.close()
            except OSError:
                pass
        for t in self._threads:
            t.join(timeout=2.0)

    def __enter__(self) -> DelayLine:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()

    def _spawn(self, target, name: str, *args) -> None:
        thread = threading.Thread(target=target, args=args, name=name, daemon=True)
        self._threads.append(thread)
        thread.start()

    def _accept_loop(self) -> None:
        while not self._stop.is_set():
            try:
                near, _ = self._server.accept()
            except (TimeoutError, socket.timeout):
                continue
            except OSError:
                return
            try:
                far = socket.create_connection(self.target, timeout=5.0)
            except OSError:
                near.close()  # the cell is not there: the workstation sees its connection end
                continue
            self.stats.connections += 1
            self._sockets += [near, far]
            for sock in (near, far):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._spawn(self._pump, "delay-line up", near, far, "up")
            self._spawn(self._pump, "delay-line down", far, near, "down")

    def _due(self) -> float:
        with self._rng_lock:
            delay, lost = self.weather.crossing(self._rng)
        self.stats.late += lost
        return delay

    def _pump(self, source: socket.socket, sink: socket.socket, direction: str) -> None:
        """Read from ``source``, deliver to ``sink`` when each chunk is due, in order."""
        queue: list[tuple[float, int, bytes]] = []
        order = 0
        last_due = 0.0
        source_open = True
        try:
            while not self._stop.is_set() and (source_open or queue):
                now = time.monotonic()
                while queue and queue[0][0] <= now:
                    _, _, data = heapq.heappop(queue)
                    sink.sendall(data)
                    if self._tap is not None:
                        self._tap(direction, data)
                wait = min(0.05, max(0.0, queue[0][0] - now)) if queue else 0.05
                if not source_open:
                    time.sleep(wait)
                    continue
                ready, _, _ = select.select([source], [], [], wait)
                if not ready:
                    continue
                data = source.recv(_CHUNK)
                if not data:
                    source_open = False  # deliver what is on the way, then pass the end on
                    continue
                last_due = max(last_due, time.monotonic() + self._due())
                heapq.heappush(queue, (last_due, order, data))
                order += 1
                self.stats.chunks[direction] += 1
                self.stats.bytes[direction] += len(data)
        except OSError:
            pass
        finally:
            for s in (source, sink):
                try:
                    s.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass


def _address(text: str) -> tuple[str, int]:
    host, _, port = text.rpartition(":")
    return host or "127.0.0.1", int(port)


def main(argv: list[str] | None = None) -> int:
    """``python -m videocal_sim.delay_line --listen H:P --to H:P [--to ...]``: relays until stopped. A
    client library that holds Python's interpreter lock while it waits (``ur_rtde``) must not share a
    process with the relay. Several ``--listen``/``--to`` pairs (same order) share one weather."""
    import argparse
    import signal

    parser = argparse.ArgumentParser(prog="python -m videocal_sim.delay_line", description=main.__doc__)
    parser.add_argument("--listen", action="append", required=True, help="HOST:PORT to listen on")
    parser.add_argument("--to", action="append", required=True, help="HOST:PORT to relay to")
    parser.add_argument("--one-way-ms", type=float, default=0.0)
    parser.add_argument("--jitter", type=float, default=0.0, help="fraction of the delay (0.3: +-30 %%)")
    parser.add_argument("--loss", type=float, default=0.0, help="fraction of chunks lost once (0.01)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if len(args.listen) != len(args.to):
        parser.error("give one --to for each --listen")
    weather = LinkWeather(args.one_way_ms / 1000.0, args.jitter, args.loss)
    lines = [
        DelayLine(_address(a), _address(b), weather, seed=args.seed + i).start()
        for i, (a, b) in enumerate(zip(args.listen, args.to))
    ]
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    print("ready " + " ".join(f"{h}:{p}" for h, p in (line.address for line in lines)), flush=True)
    try:
        stop.wait()
    except KeyboardInterrupt:
        pass
    for line in lines:
        line.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
