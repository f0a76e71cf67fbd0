"""Argument types with the ranges a command can honour: a value outside is a usage error (one line,
exit 2) before anything starts, not a hang (``--timeout inf``), a 22 GiB allocation (``--scale 100``)
or an hour of rendering (``--poses 1000000``)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path


def bounded_int(low: int, high: int):
    """An ``argparse`` type: a whole number in [low, high]."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"must be between {low} and {high}, got {value}")
        return value

    return parse


def bounded_float(low: float, high: float, *, exclusive_low: bool = False):
    """An ``argparse`` type: a finite number in [low, high] (``(low, high]`` with ``exclusive_low``)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
        if not math.isfinite(value) or value > high or value < low or (exclusive_low and value == low):
            raise argparse.ArgumentTypeError(
                f"must be a finite number {'above' if exclusive_low else 'from'} {low:g} up to {high:g}, got {text}"
            )
        return value

    return parse


def resolved_path(text: str) -> Path:
    """An ``argparse`` type: a path made absolute where the user gave it (the current folder), so a
    child process or a later change of folder reads the same file."""
    return Path(text).expanduser().resolve()
