"""The one correspondence model every pane shares: point pairs picked by the operator.

A pair joins a 3D point on a workcell component (mm, world = robot base frame, with the
component and feature it came from) and the same point on the camera image (px). A pair
may be half made (3D picked, 2D not yet), and may be disabled without being deleted.
Listeners are told of every change; panes subscribe and never reach into each other.
"""

from __future__ import annotations

from psygnal import Signal

from dataclasses import dataclass, replace

import numpy as np
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.errors import UnknownNameError


@dataclass(frozen=True)
class Correspondence:
    """One pair. ``number``: shown to the operator, from 1, never reused in a session.
    ``point_world_mm`` (3,): the picked 3D point in the robot base frame; ``component`` and
    ``feature`` where it was picked (feature ``None`` for a plain surface point);
    ``pixel`` (2,) px or ``None`` until the 2D point is picked; ``enabled``: used by the solve;
    ``view``: the frame the pixel was picked on and the robot's joints then (``None``: picked outside
    the operator core, e.g. by a script, or by a videocal older than the stamps)."""

    number: int
    component: str
    feature: str | None
    point_world_mm: tuple[float, float, float]
    pixel: tuple[float, float] | None = None
    enabled: bool = True
    view: ViewStamp | None = None

    @property
    def complete(self) -> bool:
        return self.pixel is not None

    @property
    def label(self) -> str:
        return f"{self.number} ({self.feature})" if self.feature else str(self.number)


class CorrespondenceSet:
    """The ordered pairs of a calibration. Edits go through the commands in
    :mod:`calib_core.calibration.commands` so they can be undone.

    Event: ``changed(event, number)``, event ``added``, ``removed``, ``changed`` or ``reset``
    (``number`` None for a reset)."""

    changed = Signal(str, object)

    def __init__(self) -> None:
        self._pairs: list[Correspondence] = []
        self._next_number = 1

    def _emit(self, event: str, number: int | None) -> None:
        self.changed.emit(event, number)

    def __len__(self) -> int:
        return len(self._pairs)

    def __iter__(self):
        return iter(list(self._pairs))

    def pairs(self) -> list[Correspondence]:
        return list(self._pairs)

    def get(self, number: int) -> Correspondence:
        for p in self._pairs:
            if p.number == number:
                return p
        raise UnknownNameError(f"no pair number {number}")

    def index_of(self, number: int) -> int:
        for i, p in enumerate(self._pairs):
            if p.number == number:
                return i
        raise UnknownNameError(f"no pair number {number}")

    def new_number(self) -> int:
        n = self._next_number
        self._next_number += 1
        return n

    def usable(self) -> list[Correspondence]:
        """Complete, enabled pairs: what the solve uses."""
        return [p for p in self._pairs if p.complete and p.enabled]

    def pending(self) -> Correspondence | None:
        """The pair waiting for its 2D point, if any."""
        return next((p for p in self._pairs if not p.complete), None)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, list[int]]:
        """Usable pairs as ``points_world_mm`` (n, 3), ``pixels`` (n, 2) and their numbers."""
        use = self.usable()
        return (
            np.array([p.point_world_mm for p in use], dtype=float).reshape(-1, 3),
            np.array([p.pixel for p in use], dtype=float).reshape(-1, 2),
            [p.number for p in use],
        )

    # Low-level edits used by the commands only.
    def _insert(self, index: int, pair: Correspondence) -> None:
        self._pairs.insert(index, pair)
        self._emit("added", pair.number)

    def _remove(self, number: int) -> tuple[int, Correspondence]:
        i = self.index_of(number)
        pair = self._pairs.pop(i)
        self._emit("removed", number)
        return i, pair

    def _replace(self, pair: Correspondence) -> Correspondence:
        i = self.index_of(pair.number)
        old, self._pairs[i] = self._pairs[i], pair
        self._emit("changed", pair.number)
        return old

    def replace_all(self, pairs: list[Correspondence]) -> None:
        """Put a whole other set in place, outside the undo stack: a workspace opened, a recording's
        pairs shown at an instant of its replay. Operator edits go through the commands instead."""
        self._reset(pairs)

    def open(self, pairs: list[Correspondence]) -> None:
        """A saved set in place of this one (a workspace opened), outside the undo stack; new pairs are numbered
        on from its highest."""
        self._next_number = 1
        self._reset(pairs)

    def _reset(self, pairs: list[Correspondence]) -> list[Correspondence]:
        old, self._pairs = self._pairs, list(pairs)
        # New pairs are numbered after every pair ever shown: a pick in a replay's branch once took
        # number 1 beside recorded pair 1, and its image click moved the recorded pair.
        self._next_number = max([self._next_number] + [p.number + 1 for p in self._pairs])
        self._emit("reset", None)
        return old


def with_pixel(
    pair: Correspondence, pixel: tuple[float, float] | None, view: ViewStamp | None = None
) -> Correspondence:
    return replace(
        pair, pixel=None if pixel is None else (float(pixel[0]), float(pixel[1])), view=None if pixel is None else view
    )


def pair_to_dict(pair: Correspondence) -> dict:
    """The JSON form of a pair (workspaces, recorded ``pair_*`` events)."""
    d = {
        "number": pair.number,
        "component": pair.component,
        "feature": pair.feature,
        "point_world_mm": list(pair.point_world_mm),
        "pixel": None if pair.pixel is None else list(pair.pixel),
        "enabled": pair.enabled,
    }
    if pair.view is not None:
        d["view"] = pair.view.to_dict()
    return d


def pair_from_dict(d: dict) -> Correspondence:
    """The inverse of :func:`pair_to_dict` (``KeyError``/``TypeError``/``ValueError`` on a bad dict)."""
    pixel = d.get("pixel")
    view = d.get("view")
    return Correspondence(
        int(d["number"]),
        str(d["component"]),
        d.get("feature"),
        tuple(float(v) for v in d["point_world_mm"]),
        None if pixel is None else (float(pixel[0]), float(pixel[1])),
        bool(d.get("enabled", True)),
        None if view is None or pixel is None else ViewStamp.from_dict(view),
    )
