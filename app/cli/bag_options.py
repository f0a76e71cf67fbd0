"""The options of a command whose source may be a ROS 2 bag (the calibrations of the mounting and of the robot)."""

from __future__ import annotations

import argparse

from app.cli.options import bounded_int


def add_bag_arguments(parser: argparse.ArgumentParser) -> None:
    """``--topic``, ``--joint-topic`` and ``--every``: which images of a bag, and which joint states go with them."""
    parser.add_argument("--topic", help="with a bag: the image topic (needed when it has several)")
    parser.add_argument(
        "--joint-topic", help="with a bag: the JointState topic (default: the only one, else /joint_states)"
    )
    parser.add_argument(
        "--every", type=bounded_int(1, 100_000), default=1, help="with a bag: use every n-th image (default 1)"
    )
