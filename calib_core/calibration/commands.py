"""The operator's edits as undoable commands on the correspondence set."""

from __future__ import annotations

from dataclasses import replace

from calib_core.calibration.correspondences import Correspondence, CorrespondenceSet, with_pixel
from calib_core.undo import Command


class AddPoint3D(Command):
    """Start a pair with a 3D point picked on the model (its 2D point comes later)."""

    def __init__(self, pairs: CorrespondenceSet, component: str, feature: str | None, point_world_mm):
        self.pairs = pairs
        self.pair = Correspondence(pairs.new_number(), component, feature, tuple(float(v) for v in point_world_mm))
        self.label = f"Pick 3D point {self.pair.label}"

    def do(self) -> None:
        self.pairs._insert(len(self.pairs), self.pair)

    def undo(self) -> None:
        self.pairs._remove(self.pair.number)


class SetPixel(Command):
    """Set (or move) the 2D point of a pair, px."""

    def __init__(self, pairs: CorrespondenceSet, number: int, pixel, view=None):
        self.pairs = pairs
        self.number = number
        self.pixel = (float(pixel[0]), float(pixel[1]))
        self.view = view
        self.old = None
        self.label = f"Pick 2D point of pair {number}"

    def do(self) -> None:
        self.old = self.pairs._replace(with_pixel(self.pairs.get(self.number), self.pixel, self.view))

    def undo(self) -> None:
        self.pairs._replace(self.old)


class DeletePair(Command):
    def __init__(self, pairs: CorrespondenceSet, number: int):
        self.pairs = pairs
        self.number = number
        self.index = 0
        self.pair = None
        self.label = f"Delete pair {number}"

    def do(self) -> None:
        self.index, self.pair = self.pairs._remove(self.number)

    def undo(self) -> None:
        self.pairs._insert(self.index, self.pair)


class SetEnabled(Command):
    """Enable or disable a pair (a disabled pair stays in the table but not in the solve)."""

    def __init__(self, pairs: CorrespondenceSet, number: int, enabled: bool):
        self.pairs = pairs
        self.number = number
        self.enabled = bool(enabled)
        self.old = None
        self.label = f"{'Enable' if enabled else 'Disable'} pair {number}"

    def do(self) -> None:
        self.old = self.pairs._replace(replace(self.pairs.get(self.number), enabled=self.enabled))

    def undo(self) -> None:
        self.pairs._replace(self.old)


class ClearPairs(Command):
    label = "Clear all pairs"

    def __init__(self, pairs: CorrespondenceSet):
        self.pairs = pairs
        self.old: list[Correspondence] = []

    def do(self) -> None:
        self.old = self.pairs._reset([])

    def undo(self) -> None:
        self.pairs._reset(self.old)


class AddPairs(Command):
    """Add complete pairs in one step (Find points' proposals accepted): one undo removes them all.
    ``pairs_spec``: ``(component, feature, point_world_mm (3,), pixel (2,))`` each, all on ``view``."""

    def __init__(self, pairs: CorrespondenceSet, pairs_spec, view=None):
        self.pairs = pairs
        self.added = [
            Correspondence(
                pairs.new_number(),
                component,
                feature,
                tuple(float(v) for v in point),
                (float(pixel[0]), float(pixel[1])),
                True,
                view,
            )
            for component, feature, point, pixel in pairs_spec
        ]
        self.label = f"Accept {len(self.added)} found point{'s' if len(self.added) != 1 else ''}"

    def do(self) -> None:
        for pair in self.added:
            self.pairs._insert(len(self.pairs), pair)

    def undo(self) -> None:
        for pair in reversed(self.added):
            self.pairs._remove(pair.number)
