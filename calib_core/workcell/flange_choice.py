"""Which frame of a robot description the tool is mounted on (``new-cell``), and which way the tool points.

A URDF may name it (``tool0``, ``flange``, ``ee_link``: ROS-Industrial's convention). Otherwise the arm is followed
from the root while it does not branch and its joints are no gripper's (joints named for fingers or the gripper end
it); the flange is on the last joint's link: the link the two moving chains of a gripper hang from, or, down the
links fixed beyond the last joint, the one named as a tool or flange, never a finger and never a TCP frame beyond the
flange. The JACO2 of example-robot-data (fingers fixed) got a finger tip before: the tool and camera 150 mm sideways.

A flange whose z does not point out of the wrist (JACO2's end effector: 90 deg across) gets the tool placed along the
way out instead, and ``new-cell`` says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from calib_core.errors import VideocalError
from calib_core.frames import make_transform
from calib_core.robot.model import RobotModel


_FINGER_WORDS = ("finger", "knuckle", "jaw", "pad", "thumb", "phalanx", "tip")
"""Links or joints so named belong to a gripper's fingers: the flange is never one of them."""
_FLANGE_NAMES = ("tool0", "flange", "ee_link")
_FLANGE_WORDS = ("tool", "flange", "end_effector", "ee_link")
_TCP_WORDS = ("tcp",)
"""A link so named is a tool centre point beyond the flange (Panda's panda_hand_tcp): the descent stops before it."""


def _is_finger(name: str) -> bool:
    return any(word in name.lower() for word in _FINGER_WORDS)


def _is_gripper_joint(name: str) -> bool:
    """A moving joint of a gripper (a finger's, or one named for the gripper: Unitree Z1's jointGripper)."""
    return _is_finger(name) or "gripper" in name.lower()


@dataclass(frozen=True)
class FlangeChoice:
    """The frame the tool is mounted on and why it was chosen (said by ``new-cell``)."""

    name: str
    why: str


def choose_flange(robot: RobotModel, flange: str | None) -> FlangeChoice:
    """The flange frame (``flange``: the user's, checked) and why it was chosen (see the module)."""
    if flange is not None:
        if not robot.model.existFrame(flange):
            raise VideocalError(f"the URDF has no frame {flange!r}; frames: {', '.join(robot.frame_names)}")
        return FlangeChoice(flange, "given with --flange")
    for name in _FLANGE_NAMES:
        if robot.model.existFrame(name):
            return FlangeChoice(name, f"the URDF names a {name!r} frame (the ROS-Industrial convention)")
    # Follow the arm from the root while it does not branch and its joints are no fingers'; the flange is on the
    # last joint's link (a gripper's moving fingers branch off there and are not part of the arm).
    model = robot.full_model
    joint = 0
    while True:
        children = [
            j for j in range(1, model.njoints) if model.parents[j] == joint and not _is_gripper_joint(model.names[j])
        ]
        if len(children) != 1:
            break
        joint = children[0]
    fingers = [model.names[j] for j in range(1, model.njoints) if model.parents[j] == joint]
    if children:  # the arm branches into two moving chains: the link they hang from (Panda: panda_hand)
        joint_frame = model.frames[model.getFrameId(model.names[children[0]], pin.FrameType.JOINT)]
        return FlangeChoice(
            model.frames[joint_frame.parentFrame].name,
            f"the arm's chain branches there (joints {', '.join(model.names[j] for j in children)})",
        )
    # The links fixed to the last joint: from its own link down the fixed joints, never into a finger, preferring
    # a link named as a tool or flange, stopping where the fixed links branch (JACO2: the end effector beside two
    # fixed fingers, not a finger tip)
    body = next(k for k, f in enumerate(model.frames) if f.type == pin.FrameType.BODY and f.parentJoint == joint)
    children_of: dict[int, list[int]] = {}
    for k, f in enumerate(model.frames):
        if f.type == pin.FrameType.BODY and f.parentJoint == joint and k != body:
            parent = (
                model.frames[f.parentFrame].parentFrame
                if model.frames[f.parentFrame].type == pin.FrameType.FIXED_JOINT
                else f.parentFrame
            )
            children_of.setdefault(parent, []).append(k)
    skipped = []
    chosen, why = body, f"the link of the last joint {model.names[joint]!r}"
    while True:
        kids = children_of.get(chosen, [])
        arm = [
            k
            for k in kids
            if not _is_finger(model.frames[k].name)
            and not _is_finger(model.frames[model.frames[k].parentFrame].name)
            and not any(w in model.frames[k].name.lower() for w in _TCP_WORDS)
        ]
        skipped += [
            model.frames[k].name
            for k in kids
            if k not in arm and not any(w in model.frames[k].name.lower() for w in _TCP_WORDS)
        ]
        named = [k for k in arm if any(w in model.frames[k].name.lower() for w in _FLANGE_WORDS)]
        if len(named) == 1 or len(arm) == 1:
            chosen = (named or arm)[0]
            why = f"the link fixed beyond the last joint {model.names[joint]!r}" + (
                " named as a tool or flange" if named else ""
            )
            continue
        break
    if skipped or fingers:
        why += f"; the gripper's links and joints left out: {', '.join(sorted(set(skipped + fingers)))}"
    return FlangeChoice(model.frames[chosen].name, why)


def tool_alignment(robot: RobotModel, flange: str) -> tuple[np.ndarray, str | None]:
    """The turn (4, 4, in the flange's frame) that makes its z the way out of the wrist, and words for it; the
    identity and ``None`` when z already points out (within 60 deg), or when the flange sits on the wrist's
    centre (nothing to compare). The way out: from the last joint's origin to the flange's, joints at zero
    (clipped to their limits). JACO2's end effector has its z across the hand (90 deg): the tool and camera
    went 150 mm sideways."""
    q = np.clip(np.zeros(robot.n_joints), robot.lower_limits_deg, robot.upper_limits_deg)
    flange2base = robot.fk(q, flange)
    last_joint = robot.model.frames[robot.frame_id(flange)].parentJoint
    wrist = (
        robot.fk(q, robot.model.names[last_joint])[:3, 3] if last_joint > 0 else flange2base[:3, 3]
    )  # (a joint's frame bears its name)
    out = flange2base[:3, 3] - wrist
    if np.linalg.norm(out) < 5.0:
        return np.eye(4), None
    out_in_flange = flange2base[:3, :3].T @ (out / np.linalg.norm(out))
    along = float(out_in_flange[2])
    if along > 0.5:
        return np.eye(4), None
    # the least turn taking z onto the way out (about z x out)
    axis = np.cross([0.0, 0.0, 1.0], out_in_flange)
    angle = float(np.arccos(np.clip(along, -1.0, 1.0)))
    axis = axis / np.linalg.norm(axis) if np.linalg.norm(axis) > 1e-9 else np.array([1.0, 0.0, 0.0])
    from scipy.spatial.transform import Rotation

    align = make_transform(Rotation.from_rotvec(axis * angle).as_matrix(), np.zeros(3))
    words = (
        f"the z axis of {flange!r} points {np.degrees(angle):.0f} deg from the way out of the wrist: the tool and "
        "camera are placed "
        "along the way out instead (from the last joint to the flange); give --flange a frame whose z points out of "
        "the tool to change it"
    )
    return align, words
