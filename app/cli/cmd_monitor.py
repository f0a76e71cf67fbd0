"""``videocal monitor URL``: print the joint samples of a controller link (the paper's
"monitoring", without the CAD). Link statistics go to stderr at the end.

Exit codes: 0 after ``--count`` samples (or on Ctrl-C), 4 when ``--timeout`` seconds pass
without a sample, 2 for an unusable URL (one ``error:`` line).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from app.cli.options import bounded_float, bounded_int

EXIT_TIMEOUT = 4


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("url", help="a serial port (/dev/ttyUSB0), a pty, socket://host:port, rfc2217://host:port or loop://")
    rate = parser.add_mutually_exclusive_group()
    rate.add_argument("--poll", type=bounded_float(0.0, 1000.0, exclusive_low=True), metavar="HZ", help="request samples at this rate (the paper's cyclic request)")
    rate.add_argument("--stream", type=bounded_float(0.0, 1000.0, exclusive_low=True), metavar="HZ", help="ask the controller to stream at this rate (default 20)")
    parser.add_argument("--count", type=bounded_int(1, 10**12), help="stop after this many samples")
    parser.add_argument("--timeout", type=bounded_float(0.0, 86400.0, exclusive_low=True), default=5.0, help="give up after this many seconds without a sample (default 5)")
    parser.add_argument("--json", action="store_true", help="one JSON object per line: seq, t_ms, joints_deg")
    parser.add_argument("--baud", type=bounded_int(50, 20_000_000), default=115200, help="serial baud rate")
    parser.add_argument("--parity", choices=("N", "E", "O"), default="N", help="serial parity")


def run(args: argparse.Namespace) -> int:
    from calib_core.link.driver import ControllerLink

    if args.count is not None and args.count <= 0:
        raise ValueError(f"--count must be positive, got {args.count}")
    mode, rate = ("poll", args.poll) if args.poll is not None else ("stream", args.stream or 20.0)
    link = ControllerLink(args.url, mode=mode, rate_hz=rate, baudrate=args.baud, parity=args.parity)
    link.start(wait_open=True)
    # The robot's joint count: the controller's own word ($VER), else the first sample's. A sample of
    # another count is not this robot's (a second writer, a corrupted line): not printed as if it were.
    version = link.request_version(1.0)
    if version is not None:
        link.n_joints = version.n_joints  # the driver then drops and counts them (wrong_joint_count)
    expected, skipped = (version.n_joints if version is not None else None), 0
    printed = 0
    code = 0
    last = time.monotonic()
    try:
        while args.count is None or printed < args.count:
            samples = link.drain()
            if not samples:
                if time.monotonic() - last > args.timeout:
                    print(f"error: no joint sample from {args.url} for {args.timeout:g} s (link {link.state.value}: {link.last_error or 'no reply'})", file=sys.stderr)
                    code = EXIT_TIMEOUT
                    break
                time.sleep(0.002)
                continue
            last = time.monotonic()
            for s in samples:
                if args.count is not None and printed >= args.count:
                    break
                q = s.sample.joints_deg
                expected = expected or len(q)
                if len(q) != expected:
                    skipped += 1
                    print(f"warning: sample {s.sample.seq} has {len(q)} joint values, the robot has {expected}: not shown", file=sys.stderr)
                    continue
                if args.json:
                    print(json.dumps({"seq": s.sample.seq, "t_ms": s.sample.t_ms, "joints_deg": list(q)}), flush=True)
                else:
                    print(f"{s.sample.seq:>8} {s.sample.t_ms:>10} ms  " + " ".join(f"{v:9.4f}" for v in q), flush=True)
                printed += 1
    except KeyboardInterrupt:
        pass
    finally:
        link.close()
        stats = link.stats_snapshot()
        print("link statistics: " + ", ".join(f"{k} {v}" for k, v in stats.items()), file=sys.stderr)
    return code
