"""A progress bar for a command's long work (finding the board in dozens of large images, a look on many photos): the
count done, the rate and the time left, on the terminal's standard error, as tqdm draws it. Only on a terminal and
never with ``--json``: a script reading the command's output, or a log, gets the lines it always got."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

from tqdm import tqdm


def shown(json_output: bool = False) -> bool:
    """Whether a bar is drawn: standard error is a terminal and the output is not JSON."""
    return not json_output and sys.stderr.isatty()


@contextmanager
def progress(total: int | None, what: str, json_output: bool = False) -> Iterator[tqdm]:
    """A bar of ``total`` steps (``None``: counted, without time left) named ``what``; ``bar.update()`` after each,
    ``bar.write(line)`` for a line that must not break it. Not shown (see :func:`shown`), it writes nothing but its
    lines, to standard error as before."""
    bar = tqdm(
        total=total,
        desc=what,
        unit=" images",
        file=sys.stderr,
        disable=not shown(json_output),
        # the terminal's size (a pseudo-terminal nobody sized says 0 x 0, and tqdm draws nothing on 0 rows)
        ncols=_size()[0],
        nrows=_size()[1],
        leave=False,
    )
    try:
        yield bar
    finally:
        bar.close()


def _size() -> tuple[int, int]:
    """(columns, rows) of the terminal standard error is on, 80 x 24 where it does not say."""
    try:
        size = os.get_terminal_size(sys.stderr.fileno())
    except (OSError, ValueError):
        return 80, 24
    return (size.columns if size.columns > 0 else 80), (size.lines if size.lines > 0 else 24)


def say(bar: tqdm, line: str) -> None:
    """``line`` on standard error, above the bar when one is drawn."""
    if bar.disable:
        print(line, file=sys.stderr)
    else:
        bar.write(line, file=sys.stderr)


def reported(bar: tqdm) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback (as the simulated site's long runs take one) that moves ``bar``."""

    def report(done: int, total: int) -> None:
        if bar.total != total:
            bar.total = total
        bar.update(done - bar.n)

    return report


def counted(items: Iterable, bar: tqdm) -> Iterator:
    """``items`` one by one, the bar advanced after each."""
    for item in items:
        yield item
        bar.update()
