"""``videocal monitor URL [--workcell F]``: print the joint samples of any controller connector (the
paper's "monitoring", without the CAD); with ``--workcell``, in F's robot's joint order and zero. Link
statistics go to stderr at the end.

Exit codes: 0 after ``--count`` samples (or on Ctrl-C), 4 when ``--timeout`` seconds pass
without a sample, 2 for an unusable URL (one ``error:`` line).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from app.cli.options import bounded_float, bounded_int, resolved_path

EXIT_TIMEOUT = 4


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "url",
        help="a controller connector URL: a serial port (/dev/ttyUSB0), a pty, socket://host:port, "
        "rfc2217://host:port, loop://, ros2:///joint_states, ...",
    )
    parser.add_argument(
        "--workcell",
        type=resolved_path,
        help="the cell's workcell file: samples in its robot's joint order and zero, its joint count checked (needed "
        "by connectors that name joints, such as ros2://)",
    )
    rate = parser.add_mutually_exclusive_group()
    rate.add_argument(
        "--poll",
        type=bounded_float(0.0, 1000.0, exclusive_low=True),
        metavar="HZ",
        help="request samples at this rate (the paper's cyclic request)",
    )
    rate.add_argument(
        "--stream",
        type=bounded_float(0.0, 1000.0, exclusive_low=True),
        metavar="HZ",
        help="ask the controller to stream at this rate (default 20)",
    )
    parser.add_argument("--count", type=bounded_int(1, 10**12), help="stop after this many samples")
    parser.add_argument(
        "--timeout",
        type=bounded_float(0.0, 86400.0, exclusive_low=True),
        default=5.0,
        help="give up after this many seconds without a sample (default 5)",
    )
    parser.add_argument(
        "--json",
        action="store_true",
        help="one JSON object per line: seq, t_ms (ms since the epoch), t_controller_ms (the controller's own stamp), "
        "joints_deg",
    )
    parser.add_argument(
        "--baud", type=bounded_int(50, 20_000_000), help="serial baud rate (videocal's protocol; default 115200)"
    )
    parser.add_argument("--parity", choices=("N", "E", "O"), help="serial parity (videocal's protocol; default N)")


def _context(args: argparse.Namespace, rate_hz: float, options: dict):
    """The connector's context: the workcell's robot, or none (any joint count, the controller's order)."""
    from calib_core.connectors.controller import ControllerContext
    from calib_core.connectors.joint_map import JointMap

    if args.workcell is None:
        return ControllerContext((), (), JointMap.identity(0), rate_hz, options)
    from calib_core.operator.cell import Cell

    cell = Cell.open(args.workcell)
    return ControllerContext.of(cell.robot, cell.joint_map, rate_hz, options)


def run(args: argparse.Namespace) -> int:
    import queue

    from calib_core.connectors.registry import open_controller

    if args.count is not None and args.count <= 0:
        raise ValueError(f"--count must be positive, got {args.count}")
    mode, rate = ("poll", args.poll) if args.poll is not None else ("stream", args.stream or 20.0)
    options = {"mode": mode} if args.poll is not None else {}
    options.update({k: v for k, v in (("baudrate", args.baud), ("parity", args.parity)) if v is not None})
    context = _context(args, rate, options)
    link = open_controller(args.url, context)
    samples_in: queue.Queue = queue.Queue(maxsize=100_000)  # bounded: a stalled terminal drops, never grows

    def keep(sample) -> None:
        try:
            samples_in.put_nowait(sample)
        except queue.Full:
            pass

    link.sample_received.connect(keep)
    reasons = []  # the connector's own words for its state: what it waits for
    link.state_changed.connect(lambda state, why: reasons.append(why))
    if hasattr(link, "request_version"):  # videocal's own protocol opens at once and says its joint count
        link.start(wait_open=True)
    else:
        link.start()
    # The robot's joint count: the workcell's, else the controller's own word ($VER), else most of the first
    # sample's. A sample of another count is not this robot's (a second writer, a corrupted line): not
    # printed as if it were.
    expected = context.n_joints or None
    # a far controller answers a round trip later: wait at least twice the link's measured timeout
    wait_s = max(1.0, 2.0 * link.round_trip.rto_s) if hasattr(link, "round_trip") else 1.0
    version = link.request_version(wait_s) if expected is None and hasattr(link, "request_version") else None
    if version is not None:
        link.n_joints = version.n_joints  # the driver then drops and counts them (wrong_joint_count)
        expected = version.n_joints
    skipped = 0
    to_model = link.joint_map.to_model if context.n_joints else None
    epoch_ms = EpochStamps()
    printed = 0
    code = 0
    last = started = time.monotonic()
    pending = []
    try:
        while args.count is None or printed < args.count:
            try:
                samples = [samples_in.get(timeout=0.05)]
            except queue.Empty:
                samples = []
            if samples:
                last = time.monotonic()
            if expected is None:
                # No workcell and no VER: the robot's joint count is the one most of the first samples carry (the
                # very first may be the odd one out): wait for five, or a second.
                pending.extend(samples)
                samples = []
                if pending and (len(pending) >= 5 or time.monotonic() - started >= 1.0):
                    counts = [len(p.sample.joints_deg) for p in pending]
                    expected = max(set(counts), key=counts.count)
                    samples, pending = pending, []
            if not samples:
                if time.monotonic() - last > args.timeout:
                    why = getattr(link, "last_error", None) or (reasons[-1] if reasons else "no reply")
                    print(
                        f"error: no joint sample from {args.url} for {args.timeout:g} s (link {link.state.value}: "
                        f"{why})",
                        file=sys.stderr,
                    )
                    code = EXIT_TIMEOUT
                    break
                continue
            for s in samples:
                if args.count is not None and printed >= args.count:
                    break
                q = s.sample.joints_deg
                if len(q) != expected:
                    skipped += 1
                    print(
                        f"warning: sample {s.sample.seq} has {len(q)} joint values, the robot has {expected}: not "
                        "shown",
                        file=sys.stderr,
                    )
                    continue
                if to_model is not None:
                    q = tuple(float(v) for v in to_model(q))
                t_ms = epoch_ms(s)
                if args.json:
                    print(
                        json.dumps(
                            {"seq": s.sample.seq, "t_ms": t_ms, "t_controller_ms": s.sample.t_ms, "joints_deg": list(q)}
                        ),
                        flush=True,
                    )
                else:
                    print(f"{s.sample.seq:>8} {t_ms:>14} ms  " + " ".join(f"{v:9.4f}" for v in q), flush=True)
                printed += 1
    except KeyboardInterrupt:
        pass
    finally:
        link.close()
        stats = link.stats_snapshot()
        print("link statistics: " + ", ".join(f"{k} {v}" for k, v in stats.items()), file=sys.stderr)
    return code


EPOCH_FLOOR_MS = 1_000_000_000_000
"""A stamp past this (2001-09-09) counts from the Unix epoch (a ROS 2 header); a controller's own clock (since its
start: videocal's protocol, UR's RTDE) would need 31 years of uptime to reach it."""


class EpochStamps:
    """A sample's stamp in ms since the Unix epoch. A ROS 2 header's is one already. A controller's own clock (since its
    start) is put on the epoch by the first sample's arrival: each later stamp keeps its distance from the first as the
    controller stamped it (the steps are the controller's, never reordered), and the whole run sits late by the first
    sample's transit (a millisecond on a near link, the link's one-way delay on a far one). A controller clock that
    goes back (a restart) is anchored again on that sample."""

    def __init__(self):
        self._anchor: tuple[int, float] | None = None  # (controller ms, host epoch s) of the anchoring sample

    def __call__(self, timed) -> int:
        t_ms = int(timed.sample.t_ms)
        if t_ms >= EPOCH_FLOOR_MS:
            return t_ms
        if self._anchor is None or t_ms < self._anchor[0]:
            self._anchor = (t_ms, time.time() - (time.monotonic() - timed.t_host_s))
        first_ms, first_epoch_s = self._anchor
        return int(round(first_epoch_s * 1000.0)) + (t_ms - first_ms)
