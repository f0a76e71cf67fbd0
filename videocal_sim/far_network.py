"""A far network for connectors that speak UDP (ROS 2 on DDS): a second network namespace, the simulated
robot's side, joined to this one by two TAP devices whose Ethernet frames cross a user-space relay that holds each
for a one-way delay, varies it (jitter) and drops some (loss), as a satellite link between the operator's
workstation and the cell would.

Why not the kernel's ``netem``: these machines (CI containers) have no ``sch_netem``. Why not a UDP relay on
loopback as the TCP delay line is: DDS tells its peers where to send (the locators in its discovery messages),
so a relay on another port is never used; Cyclone's ``ExternalNetworkAddress`` refuses a loopback-only
machine. With two namespaces each side has its own address and its own route, and every packet between them
passes through here, whatever the protocol says.

One process (``python -m videocal_sim.far_network``, root: namespaces and TAP devices need CAP_NET_ADMIN)
makes the near TAP device in its own namespace, then moves into a new namespace of its own and makes the far
one there (a TAP device stays in the namespace it was made in). Each side has a /24 address with a broadcast (a
GigE Vision camera is found by broadcast) and the other's MAC set outright (ARP would give up across seconds). Programs
of the far side join it with
``nsenter --net=/proc/PID/ns/net`` (:meth:`FarNetwork.far_command`). Nothing is left behind: the namespace
lives while the relay or a far program runs in it, the TAP devices while the relay holds them open.

Loss here is a missing frame (UDP's packet), not a late one (TCP's, :mod:`videocal_sim.delay_line`); the order of
the frames is kept (a packet is never due before the one ahead of it), as a single path keeps it.
"""

from __future__ import annotations

import ctypes
import fcntl
import functools
import heapq
import os
import random
import select
import shutil
import signal
import struct
import subprocess
import sys
import threading
import time
from dataclasses import dataclass

from calib_core.errors import VideocalError
from videocal_sim.delay_line import LinkWeather

_TUNSETIFF = 0x400454CA
_IFF_TAP, _IFF_NO_PI = 0x0002, 0x1000
_CLONE_NEWNET = 0x40000000
_MTU = 1500


class FarNetworkError(VideocalError, RuntimeError):
    """The far network cannot be made here (not root, no TUN/TAP device, no ``ip``), said with what is missing."""


def why_not_available() -> str | None:
    """What keeps this machine from making a far network, or ``None``."""
    if os.geteuid() != 0:
        return "network namespaces and TAP devices need root (CAP_NET_ADMIN)"
    if not os.path.exists("/dev/net/tun"):
        return "there is no /dev/net/tun"
    for tool in ("ip", "nsenter"):
        if shutil.which(tool) is None:
            return f"the '{tool}' command is missing (Debian: {'iproute2' if tool == 'ip' else 'util-linux'})"
    return _probe()


@functools.lru_cache(maxsize=1)
def _probe() -> str | None:
    """Make the two devices and the namespace once, and take them down (a container may refuse either)."""
    try:
        done = subprocess.run(
            [sys.executable, "-m", "videocal_sim.far_network", "--probe"],
            capture_output=True,
            text=True,
            timeout=20,
            cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
        )
    except subprocess.TimeoutExpired:
        return "making the far network took over 20 s"
    if done.returncode != 0:
        why = done.stderr.strip().splitlines()
        return why[-1].removeprefix("error: ") if why else f"making the far network failed (exit {done.returncode})"
    return None


def _tap(name: str) -> int:
    """A TAP device (Ethernet frames, broadcast like a NIC: GigE Vision's discovery needs it) held by the fd."""
    fd = os.open("/dev/net/tun", os.O_RDWR)
    fcntl.ioctl(fd, _TUNSETIFF, struct.pack("16sH", name.encode(), _IFF_TAP | _IFF_NO_PI))
    return fd


def _bring_up(name: str, mac: str, own_ip: str, peer_ip: str, peer_mac: str) -> None:
    """Address the device and name the peer's MAC outright: ARP across seconds of delay would give up first."""
    _ip("link", "set", name, "address", mac, "mtu", str(_MTU), "up")
    _ip("addr", "add", f"{own_ip}/24", "brd", "+", "dev", name)
    _ip("neigh", "replace", peer_ip, "lladdr", peer_mac, "nud", "permanent", "dev", name)


def _ip(*args: str) -> None:
    done = subprocess.run(["ip", *args], capture_output=True, text=True)
    if done.returncode:
        raise FarNetworkError(f"ip {' '.join(args)}: {done.stderr.strip()}")


def _free_subnet() -> int:
    """A /30's third octet in 10.77.0.0/16 that no interface here uses."""
    used = subprocess.run(["ip", "-o", "-4", "addr"], capture_output=True, text=True).stdout
    for k in [os.getpid() % 250 + 1, *range(1, 251)]:
        if f" 10.77.{k}." not in used:
            return k
    raise FarNetworkError("no free 10.77.k.0 subnet for the far network")


@dataclass
class RelayStats:
    """Packets per direction (``up``: workstation to cell) and how many were dropped."""

    packets: dict
    dropped: dict


class PacketRelay:
    """Moves Ethernet frames between two TAP file descriptors through ``weather`` (delay, jitter, loss)."""

    def __init__(self, near_fd: int, far_fd: int, weather: LinkWeather, seed: int = 0):
        self.weather = weather
        self.stats = RelayStats({"up": 0, "down": 0}, {"up": 0, "down": 0})
        self._rng = random.Random(seed)
        self._rng_lock = threading.Lock()
        self._stop = threading.Event()
        self._threads = [
            threading.Thread(target=self._pump, args=(near_fd, far_fd, "up"), name="far up", daemon=True),
            threading.Thread(target=self._pump, args=(far_fd, near_fd, "down"), name="far down", daemon=True),
        ]

    def start(self) -> PacketRelay:
        for t in self._threads:
            t.start()
        return self

    def close(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(timeout=1.0)

    def _crossing(self) -> tuple[float, bool]:
        with self._rng_lock:
            w = self.weather
            delay = w.one_way_s * (1.0 + w.jitter * self._rng.uniform(-1.0, 1.0))
            return delay, bool(w.loss) and self._rng.random() < w.loss

    def _pump(self, source: int, sink: int, direction: str) -> None:
        queue: list[tuple[float, int, bytes]] = []
        order, last_due = 0, 0.0
        while not self._stop.is_set():
            now = time.monotonic()
            while queue and queue[0][0] <= now:
                try:
                    os.write(sink, heapq.heappop(queue)[2])
                except OSError:
                    pass  # the far side not up yet: the packet is lost, as on a wire
            wait = min(0.02, max(0.0, queue[0][0] - now)) if queue else 0.02
            ready, _, _ = select.select([source], [], [], wait)
            if not ready:
                continue
            try:
                packet = os.read(source, 65536)
            except OSError:
                return
            self.stats.packets[direction] += 1
            delay, lost = self._crossing()
            if lost:
                self.stats.dropped[direction] += 1
                continue
            last_due = max(last_due, time.monotonic() + delay)
            heapq.heappush(queue, (last_due, order, packet))
            order += 1


class FarNetwork:
    """The far network as a child process (``python -m videocal_sim.far_network``). ``near_ip``: this side's
    address on it, ``far_ip``: the robot side's; :meth:`far_command` runs a command on the robot side;
    :meth:`cyclone_config` is the Cyclone DDS configuration of either side. Close with :meth:`close`."""

    def __init__(self, weather: LinkWeather, seed: int = 0):
        why = why_not_available()
        if why is not None:
            raise FarNetworkError(f"cannot make a far network here: {why}")
        cmd = [
            sys.executable,
            "-m",
            "videocal_sim.far_network",
            "--one-way-ms",
            f"{1000 * weather.one_way_s:g}",
            "--jitter",
            f"{weather.jitter:g}",
            "--loss",
            f"{weather.loss:g}",
            "--seed",
            str(seed),
        ]
        project = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        from videocal_sim.sim_process import _die_with_parent  # the relay ends with the program that made it (SIGTERM)

        self.process = subprocess.Popen(
            cmd,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            text=True,
            cwd=project,
            preexec_fn=_die_with_parent,
        )
        line = self.process.stdout.readline().split()
        if len(line) != 4 or line[0] != "ready":
            self.process.kill()
            raise FarNetworkError(f"the far network did not start: {self.process.stderr.read().strip() or line}")
        self.namespace, self.near_ip, self.far_ip = line[1], line[2], line[3]
        self.weather = weather

    def far_command(self, argv: list[str]) -> list[str]:
        """``argv`` run on the robot's side of the link."""
        return ["nsenter", f"--net={self.namespace}", "--", *argv]

    def cyclone_config(self, side: str) -> str:
        """Cyclone DDS's configuration for ``side`` (``"near"``, ``"far"``): its own address on the link, the other
        side as its one discovery peer (the link carries no multicast)."""
        own, peer = (self.near_ip, self.far_ip) if side == "near" else (self.far_ip, self.near_ip)
        return (
            '<CycloneDDS><Domain id="any"><General><Interfaces>'
            f'<NetworkInterface address="{own}"/></Interfaces><AllowMulticast>false</AllowMulticast></General>'
            f'<Discovery><Peers><Peer address="{peer}"/></Peers><ParticipantIndex>auto</ParticipantIndex>'
            "<MaxAutoParticipantIndex>20</MaxAutoParticipantIndex></Discovery></Domain></CycloneDDS>"
        )

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=3.0)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()

    def __enter__(self) -> FarNetwork:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def main(argv: list[str] | None = None) -> int:
    """Makes the two namespaces' TAP devices, prints ``ready NETNS_PATH NEAR_IP FAR_IP``, relays until SIGTERM."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m videocal_sim.far_network", description=main.__doc__)
    parser.add_argument("--one-way-ms", type=float, default=0.0)
    parser.add_argument("--jitter", type=float, default=0.0, help="fraction of the delay (0.3: +-30 %%)")
    parser.add_argument("--loss", type=float, default=0.0, help="fraction of packets dropped (0.01)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--probe",
        action="store_true",
        help="make the devices and the namespace, then end at once (exit 0: it can be done here)",
    )
    args = parser.parse_args(argv)
    why = "network namespaces and TAP devices need root (CAP_NET_ADMIN)" if os.geteuid() != 0 else None
    if why is not None:
        print(f"error: cannot make a far network here: {why}", file=sys.stderr)
        return 2
    weather = LinkWeather(args.one_way_ms / 1000.0, args.jitter, args.loss)
    k = _free_subnet()
    near_ip, far_ip = f"10.77.{k}.1", f"10.77.{k}.2"
    near_name = f"vcfar{os.getpid() % 100000}"
    near_mac, far_mac = f"02:77:00:00:{k:02x}:01", f"02:77:00:00:{k:02x}:02"
    try:
        near_fd = _tap(near_name)
        _bring_up(near_name, near_mac, near_ip, far_ip, far_mac)
        if ctypes.CDLL(None, use_errno=True).unshare(_CLONE_NEWNET) != 0:
            raise FarNetworkError(f"unshare(CLONE_NEWNET): {os.strerror(ctypes.get_errno())}")
        far_fd = _tap("vcfar0")
        _ip("link", "set", "lo", "up")
        _bring_up("vcfar0", far_mac, far_ip, near_ip, near_mac)
    except (OSError, FarNetworkError) as exc:
        print(f"error: cannot make the far network: {exc}", file=sys.stderr)
        return 2
    if args.probe:
        return 0
    relay = PacketRelay(near_fd, far_fd, weather, seed=args.seed).start()
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    print(f"ready /proc/{os.getpid()}/ns/net {near_ip} {far_ip}", flush=True)
    stop.wait()
    relay.close()
    s = relay.stats
    print(
        f"relayed up {s.packets['up']} (dropped {s.dropped['up']}), down {s.packets['down']} (dropped "
        f"{s.dropped['down']})",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
