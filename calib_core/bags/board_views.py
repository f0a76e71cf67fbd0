"""Board views from a ROS 2 bag with the arm's pose at each (its joints, or its flange from ``/tf``): what the hand-eye
and the robot calibration take
from a user's recording (images, ``/joint_states``, CameraInfo) with no conversion.

A frame counts only where the arm stood still around its header stamp
(:func:`~calib_core.bags.joint_track.settled_joints`):
the joints interpolated at a frame taken mid-move would pair the image with a pose the camera was not at.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from calib_core.bags.bag_source import bag_stamped_images
from calib_core.bags.joint_track import read_joint_track, settled_joints
from calib_core.bags.tf_track import read_tf_track, settled_flange
from calib_core.errors import VideocalError
from calib_core.ros2.joint_units import user_per_si
from calib_core.vision.intrinsics_calibration import BoardView, detect_view


@dataclass
class BagBoardViews:
    """The board views of a bag. ``views``: each detected view with the arm's pose at its stamp (the model
    joints, deg/mm in the robot's order, or ``flange2base`` (4, 4) mm, as the ``settled`` rule gives it); ``skipped``:
    frames taken while the arm moved, with why; ``rejected``: still frames
    without the board, with why; ``images``: frames read; ``size``: (width, height) px."""

    views: list[tuple[BoardView, np.ndarray]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    rejected: list[str] = field(default_factory=list)
    images: int = 0
    size: tuple[int, int] | None = None

    @property
    def summary(self) -> str:
        return (
            f"{self.images} images, {self.images - len(self.skipped)} taken while the arm stood still, "
            f"{len(self.views)} with the board"
        )


def bag_board_views(
    source: Path,
    spec,
    detector,
    settled: Callable[[int], tuple[object, str | None]],
    *,
    topic: str | None = None,
    every: int = 1,
    say: Callable[[str], None] = lambda text: None,
) -> BagBoardViews:
    """Every ``every``-th image of ``topic`` (the only image topic by default) in the bag ``source``, with what
    ``settled(stamp_ns)`` says of the arm at the image's header stamp: ``(pose, None)`` where it stood still (the
    joints, or the flange pose), ``(None, why)`` where not. ``say`` hears each frame left out and why. One camera
    mode per bag: a frame of another size is a :class:`~calib_core.errors.VideocalError` naming it."""
    out = BagBoardViews()
    for stamp, name, image in bag_stamped_images(source, topic, every):
        out.images += 1
        size = (image.shape[1], image.shape[0])
        if out.size is None:
            out.size = size
        elif size != out.size:
            raise VideocalError(
                f"{source} {name}: {size[0]} x {size[1]} px, the first image is {out.size[0]} x {out.size[1]} px: one "
                "calibration is for one camera mode"
            )
        pose, why = settled(stamp)
        if pose is None:
            out.skipped.append(f"{name}: {why}")
            say(f"skipped {name}: {why}")
            continue
        v = detect_view(name, image, spec, detector)
        if not isinstance(v, BoardView):
            out.rejected.append(f"{name}: {v.reason}")
            say(f"rejected {name}: {v.reason}")
            continue
        out.views.append((v, pose))
    return out


def joints_settled(
    source: Path, robot, joint_topic: str | None = None
) -> Callable[[int], tuple[np.ndarray | None, str | None]]:
    """``settled`` for :func:`bag_board_views` from the bag's JointState (``joint_topic``, else the only one, else
    ``/joint_states``): ``robot``'s joints (deg/mm, its order) where the arm stood still."""
    track = read_joint_track(source, robot.joint_names, user_per_si(robot.joint_units), joint_topic)
    return lambda stamp: settled_joints(track, stamp)


def flange_settled(source: Path, base: str, flange: str) -> Callable[[int], tuple[np.ndarray | None, str | None]]:
    """``settled`` for :func:`bag_board_views` from the bag's ``/tf``: ``flange2base`` (4, 4) mm where it stood
    still."""
    track = read_tf_track(source, base, flange)
    return lambda stamp: settled_flange(track, stamp)
