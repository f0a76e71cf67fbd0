"""The operator's edits of the pairs as undoable commands, each checking itself when pushed
(:meth:`~calib_core.undo.Command.check`): the paper's *Point* in its two halves, a moved or ticked point, a deleted
pair, Clear, and Find points' proposals accepted."""

from __future__ import annotations

from dataclasses import replace

from calib_core.calibration.correspondences import Correspondence, CorrespondenceSet, with_pixel
from calib_core.calibration.errors import CalibrationError
from calib_core.undo import Command


class AddPoint3D(Command):
    """*Point*, first half: start a pair with a 3D point picked on the model, (3,) mm in the world frame (its 2D
    point comes later). Refused on another object than the ``target`` (when one is chosen) and while a pair still
    waits for its image point. ``number``: the new pair's."""

    def __init__(
        self, pairs: CorrespondenceSet, component: str, feature: str | None, point_world_mm, target: str | None = None
    ):
        self.pairs, self.target = pairs, target
        self.pair = Correspondence(pairs.new_number(), component, feature, tuple(float(v) for v in point_world_mm))
        self.number = self.pair.number
        self.label = f"Pick 3D point {self.pair.label}"

    def check(self) -> None:
        if self.target is not None and self.pair.component != self.target:
            raise CalibrationError(f"pick on the target object '{self.target}' (the click hit '{self.pair.component}')")
        pending = self.pairs.pending()
        if pending is not None:
            raise CalibrationError(f"pair {pending.number} still needs its 2D point on the camera image")

    def do(self) -> None:
        self.pairs._insert(len(self.pairs), self.pair)

    def undo(self) -> None:
        self.pairs._remove(self.pair.number)


class SetPixel(Command):
    """Set (or move) the 2D point of pair ``number``, (u, v) px, picked on ``view`` (a
    :class:`~calib_core.calibration.view_stamp.ViewStamp`); ``number`` ``None``: *Point*'s second half, the pair
    waiting for its image point (refused when none waits)."""

    def __init__(self, pairs: CorrespondenceSet, number: int | None, pixel, view=None):
        self.pairs = pairs
        self.number = number
        self.pixel = (float(pixel[0]), float(pixel[1]))
        self.view = view
        self.old = None
        self.label = f"Pick 2D point of pair {number}"

    def check(self) -> None:
        if self.number is None:
            pending = self.pairs.pending()
            if pending is None:
                raise CalibrationError("pick the point on the model (virtual camera) first, then on the camera image")
            self.number = pending.number
            self.label = f"Pick 2D point of pair {self.number}"
        self.pairs.get(self.number)  # (names a pair that is not there)

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

    def check(self) -> None:
        self.pairs.get(self.number)

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

    def check(self) -> None:
        self.pairs.get(self.number)

    @property
    def changes_nothing(self) -> bool:
        return self.pairs.get(self.number).enabled == self.enabled

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
