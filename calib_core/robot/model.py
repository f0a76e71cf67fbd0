"""A robot loaded from URDF (or xacro) with Pinocchio: forward kinematics and Jacobians of any frame.

Every argument and result is in mm and degrees at the boundary: a joint vector ``q`` holds one
value per *driven* joint, in the URDF's joint order, degrees for a revolute or continuous joint
and millimetres for a prismatic one. Pinocchio works in metres and radians inside this module
only (a continuous joint is two numbers, cos and sin, inside). Poses are in the cell's ``base``
frame, which need not be the URDF's root (UR's ``base`` is turned 180 deg about z from ``base_link``).

The frames the program needs are named by role (``base``, ``flange``, ``tcp``, ``camera``,
:data:`~calib_core.robot.spec.FRAME_ROLES`); ``fk(q, "tcp")`` resolves the role through the
workcell's mapping. Any URDF frame name works too.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from calib_core.errors import FileFormatError
from calib_core.robot.description import read_description
from calib_core.robot.errors import RobotModelError, RobotSpecError, UnknownFrameError
from calib_core.robot.spec import DEFAULT_FRAMES, FRAME_ROLES, NewFrame, RobotSpec
from calib_core.frames import concat, invert

RESOURCES = Path(__file__).resolve().parents[2] / "resources" / "robot"
DEFAULT_URDF = RESOURCES / "videocal_arm.urdf"

REVOLUTE, PRISMATIC, CONTINUOUS = "revolute", "prismatic", "continuous"
_UNIT = {REVOLUTE: "deg", CONTINUOUS: "deg", PRISMATIC: "mm"}
# Internal (rad, m) per user unit (deg, mm).
_INTERNAL_PER_USER = {REVOLUTE: np.pi / 180.0, CONTINUOUS: np.pi / 180.0, PRISMATIC: 1e-3}


def _to_mm(placement: pin.SE3) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = placement.rotation
    T[:3, 3] = placement.translation * 1000.0
    return T


def _to_se3(T_mm: np.ndarray) -> pin.SE3:
    return pin.SE3(np.asarray(T_mm[:3, :3], dtype=float), np.asarray(T_mm[:3, 3], dtype=float) / 1000.0)


def _joint_kind(joint: pin.JointModel) -> str | None:
    name = joint.shortname()
    if "RUB" in name:  # unbounded revolute: URDF "continuous"
        return CONTINUOUS
    if name.startswith("JointModelR") and "Mimic" not in name:
        return REVOLUTE
    if name.startswith("JointModelP") and "Mimic" not in name and "Planar" not in name:
        return PRISMATIC
    return None


@dataclass
class RobotModel:
    """A serial robot. ``model``/``data`` are Pinocchio's (driven joints only: held joints are
    locked out); ``urdf_xml`` the resolved description; ``roles`` maps each frame role to the
    Pinocchio frame that plays it; ``base2root`` (4, 4) mm places the cell's base in the URDF root.

    Its public members are the robot description's read-outs (joints, units, limits, speeds, frames) and what is
    computed from it (forward kinematics, Jacobian, configuration, a frame placed on the flange): the reading side of a
    URDF, as Pinocchio's model has it."""

    model: pin.Model
    data: pin.Data
    urdf_path: Path
    urdf_xml: str = ""
    roles: dict[str, str] = field(default_factory=dict)
    base2root: np.ndarray = field(default_factory=lambda: np.eye(4))
    full_model: pin.Model | None = None
    locked_joint_ids: tuple[int, ...] = ()
    locked_configuration: np.ndarray | None = None
    mesh_uris: dict[str, str] = field(default_factory=dict)
    """Each mesh's absolute path in ``urdf_xml`` -> its reference as the description wrote it (``package://...``)."""

    def __post_init__(self):
        kinds = []
        for i in range(1, self.model.njoints):
            kind = _joint_kind(self.model.joints[i])
            if kind is None:
                raise FileFormatError(
                    self.urdf_path,
                    f"joint '{self.model.names[i]}' is of a kind videocal cannot drive "
                    f"({self.model.joints[i].shortname()}); mark it held in the workcell (robot.held_joints)",
                )
            kinds.append(kind)
        self.joint_kinds: list[str] = kinds
        self._internal_per_user = np.array([_INTERNAL_PER_USER[k] for k in kinds])
        self._root2base = invert(self.base2root)

    # --- joints ----------------------------------------------------------------------------------
    @property
    def joint_names(self) -> list[str]:
        return [self.model.names[i] for i in range(1, self.model.njoints)]

    @property
    def n_joints(self) -> int:
        """Driven joints: one value each (a continuous joint counts once)."""
        return self.model.nv

    @property
    def joint_units(self) -> list[str]:
        """``deg`` or ``mm`` per driven joint."""
        return [_UNIT[k] for k in self.joint_kinds]

    @property
    def internal_per_user(self) -> np.ndarray:
        """(n,) radians per degree or metres per millimetre of each joint: a Jacobian column
        (per internal unit) times this is per user unit."""
        return self._internal_per_user.copy()

    def _per_joint(self, values_q: np.ndarray, unbounded: float) -> np.ndarray:
        out = np.empty(self.n_joints)
        for j, kind in enumerate(self.joint_kinds):
            iq = self.model.joints[j + 1].idx_q
            out[j] = unbounded if kind == CONTINUOUS else values_q[iq] / self._internal_per_user[j]
        return out

    @property
    def lower_limits_deg(self) -> np.ndarray:
        """Lower limits (n,) in each joint's unit (deg or mm; -inf for a continuous joint)."""
        return self._per_joint(self.model.lowerPositionLimit, -np.inf)

    @property
    def upper_limits_deg(self) -> np.ndarray:
        return self._per_joint(self.model.upperPositionLimit, np.inf)

    @property
    def max_speed_deg_s(self) -> np.ndarray:
        """Speed limits (n,) in deg/s or mm/s."""
        return np.asarray(self.model.velocityLimit) / self._internal_per_user

    def check_joints(self, q_deg: ArrayLike) -> np.ndarray:
        """``q_deg`` as a float array (n,); :class:`RobotModelError` if its length or values are wrong."""
        q = np.asarray(q_deg, dtype=float).reshape(-1)
        if q.shape != (self.n_joints,):
            raise RobotModelError(
                f"expected {self.n_joints} joint values ({', '.join(self.joint_names)}), got {q.size}"
            )
        if not np.all(np.isfinite(q)):
            raise RobotModelError(f"joint values must be finite, got {q.tolist()}")
        return q

    def configuration(self, q_deg: ArrayLike) -> np.ndarray:
        """Pinocchio's configuration vector (nq,) of user joints (n,) deg/mm."""
        q = self.check_joints(q_deg)
        out = np.empty(self.model.nq)
        for j, kind in enumerate(self.joint_kinds):
            iq = self.model.joints[j + 1].idx_q
            value = q[j] * self._internal_per_user[j]
            if kind == CONTINUOUS:
                out[iq], out[iq + 1] = np.cos(value), np.sin(value)
            else:
                out[iq] = value
        return out

    def within_limits(self, q_deg: ArrayLike, margin_deg: float = 0.0) -> np.ndarray:
        """Boolean (n,): which joints lie inside their limits by at least ``margin_deg`` (deg or mm)."""
        q = self.check_joints(q_deg)
        return (q >= self.lower_limits_deg + margin_deg) & (q <= self.upper_limits_deg - margin_deg)

    # --- frames -------------------------------------------------------------------------------------
    @property
    def frame_names(self) -> list[str]:
        return [f.name for f in self.model.frames]

    def frame_id(self, name: str) -> int:
        """Pinocchio's id of a frame role (``tcp``...) or URDF frame ``name``;
        :class:`UnknownFrameError` if there is none."""
        name = self.roles.get(name, name)
        if not self.model.existFrame(name):
            raise UnknownFrameError(name, self.frame_names)
        try:
            return self.model.getFrameId(name)
        except ValueError:  # a link and a joint of one name (Unitree Z1's gripperStator): the link is meant
            return self.model.getFrameId(name, pin.FrameType.BODY)

    def fk(self, q_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """``frame2base`` (4, 4), mm, at joints ``q_deg`` (n,) deg/mm."""
        fid = self.frame_id(frame)
        pin.framesForwardKinematics(self.model, self.data, self.configuration(q_deg))
        return concat(_to_mm(self.data.oMf[fid]), self._root2base)

    def all_frames(self, q_deg: ArrayLike) -> dict[str, np.ndarray]:
        """``frame2base`` (4, 4) mm of every frame at ``q_deg``, by URDF name and by role."""
        pin.framesForwardKinematics(self.model, self.data, self.configuration(q_deg))
        poses = {f.name: concat(_to_mm(self.data.oMf[i]), self._root2base) for i, f in enumerate(self.model.frames)}
        poses.update({role: poses[name] for role, name in self.roles.items()})
        return poses

    def frame_tree(self, q_deg: ArrayLike) -> list[tuple[str | None, str, np.ndarray]]:
        """The robot's links and added frames as a tree at ``q_deg``: ``(parent, child, child2parent)``
        with ``child2parent`` (4, 4) mm, parents before children; the URDF root's parent is ``None``
        and its transform is ``root2base``. Joint frames are folded into the links they move (what a
        tf tree or Foxglove's FrameTransforms holds)."""
        pin.framesForwardKinematics(self.model, self.data, self.configuration(q_deg))
        frames = self.model.frames
        kept = [i for i in range(1, len(frames)) if frames[i].type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)]
        kept_set = set(kept)
        tree = []
        for i in kept:
            parent = frames[i].parentFrame
            while parent != 0 and parent not in kept_set:
                parent = frames[parent].parentFrame
            if parent == 0 or parent == i:
                tree.append((None, frames[i].name, concat(_to_mm(self.data.oMf[i]), self._root2base)))
            else:
                tree.append(
                    (frames[parent].name, frames[i].name, _to_mm(self.data.oMf[parent].actInv(self.data.oMf[i])))
                )
        return tree

    def jacobian(self, q_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """Frame Jacobian (6, n) in base axes at the frame's origin: rows ``v`` (mm) then ``omega``
        (rad), per internal joint unit (rad or m); multiply column j by ``internal_per_user[j]``
        for per degree or per millimetre."""
        fid = self.frame_id(frame)
        J = np.array(
            pin.computeFrameJacobian(
                self.model, self.data, self.configuration(q_deg), fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
        )
        R = self._root2base[:3, :3]
        J[:3] = 1000.0 * (R @ J[:3])
        J[3:] = R @ J[3:]
        return J

    def set_frame_placement(self, frame: str, frame2parent_mm: np.ndarray) -> None:
        """Move a fixed frame relative to its parent joint (e.g. a calibrated ``camera``)."""
        self.model.frames[self.frame_id(frame)].placement = _to_se3(frame2parent_mm)

    def frame_placement(self, frame: str) -> np.ndarray:
        """The frame's placement in its parent joint's frame (4, 4), mm."""
        return _to_mm(self.model.frames[self.frame_id(frame)].placement)

    def on_flange(self, pose_on_frame_mm: np.ndarray, frame: str | None, source: str = "the mounting") -> np.ndarray:
        """A pose (4, 4, mm) given on ``frame`` of the arm re-expressed on the ``flange``: the frame must ride on the
        flange's link (a fixed offset, whatever the joints); ``None`` or the flange's own name: as given.
        :class:`~calib_core.errors.VideocalError` names ``source`` and the frame when it is not the arm's or moves
        against the flange."""
        from calib_core.errors import VideocalError

        if frame is None or frame == "flange" or frame == self.roles.get("flange"):
            return np.asarray(pose_on_frame_mm, dtype=float)
        if not self.model.existFrame(frame):
            raise VideocalError(
                f"{source}: frame {frame!r} is not on this cell's robot (its flange is "
                f"{self.roles.get('flange', 'flange')!r})"
            )
        if (
            self.model.frames[self.frame_id(frame)].parentJoint
            != self.model.frames[self.frame_id("flange")].parentJoint
        ):
            raise VideocalError(
                f"{source}: frame {frame!r} is not fixed to the flange's link: a joint moves between them"
            )
        frame2flange = concat(self.frame_placement(frame), invert(self.frame_placement("flange")))
        return concat(np.asarray(pose_on_frame_mm, dtype=float), frame2flange)

    def copy(self) -> RobotModel:
        model = self.model.copy()
        return RobotModel(
            model,
            model.createData(),
            self.urdf_path,
            self.urdf_xml,
            dict(self.roles),
            self.base2root.copy(),
            self.full_model,
            self.locked_joint_ids,
            self.locked_configuration,
            dict(self.mesh_uris),
        )


def _held_configuration(full: pin.Model, held: dict[str, float], path: Path) -> tuple[list[int], np.ndarray]:
    q_ref = pin.neutral(full)
    ids = []
    for name, value in held.items():
        if not full.existJointName(name):
            raise RobotSpecError(
                "robot.held_joints", f"the URDF has no joint {name!r}; joints: {', '.join(full.names[1:])}", path
            )
        jid = full.getJointId(name)
        kind = _joint_kind(full.joints[jid])
        if kind is None:
            raise RobotSpecError(
                f"robot.held_joints.{name}",
                f"joint {name!r} is of an unsupported kind ({full.joints[jid].shortname()})",
                path,
            )
        iq = full.joints[jid].idx_q
        internal = float(value) * _INTERNAL_PER_USER[kind]
        if kind == CONTINUOUS:
            q_ref[iq], q_ref[iq + 1] = np.cos(internal), np.sin(internal)
        else:
            q_ref[iq] = internal
        ids.append(jid)
    return ids, q_ref


def _add_frame(model: pin.Model, name: str, spec: NewFrame, path: Path, role: str) -> None:
    if not model.existFrame(spec.parent):
        raise RobotSpecError(f"robot.frames.{role}.parent", f"the URDF has no frame {spec.parent!r}", path)
    parent_id = model.getFrameId(spec.parent)
    parent = model.frames[parent_id]
    placement = parent.placement * _to_se3(spec.frame2parent)
    model.addFrame(pin.Frame(name, parent.parentJoint, parent_id, placement, pin.FrameType.OP_FRAME))


def _assign_roles(model: pin.Model, frames: dict, path: Path) -> dict[str, str]:
    roles: dict[str, str] = {}
    root = model.frames[1].name if len(model.frames) > 1 else "universe"
    for role in FRAME_ROLES:
        spec = frames.get(role, DEFAULT_FRAMES[role])
        if spec is None:
            roles[role] = root
        elif isinstance(spec, NewFrame):
            name = role if not model.existFrame(role) else f"videocal_{role}"
            _add_frame(model, name, spec, path, role)
            roles[role] = name
        elif model.existFrame(spec):
            roles[role] = spec
        elif role in frames:  # named on purpose but absent: say so now rather than at the first FK
            raise RobotSpecError(
                f"robot.frames.{role}",
                f"the URDF has no frame {spec!r}; give a URDF frame, or a new one as {{parent: FRAME, xyz: [...], rpy: "
                "[...]}",
                path,
            )
    return roles


def load_robot(source: str | Path | RobotSpec = DEFAULT_URDF) -> RobotModel:
    """Load a robot from a URDF/xacro path or a workcell's :class:`RobotSpec`.

    :class:`FileFormatError` names the file (and link or joint) when it is missing, malformed,
    or names a mesh, frame or joint that is not there.
    """
    spec = source if isinstance(source, RobotSpec) else RobotSpec(Path(source))
    path = Path(spec.urdf)
    if not path.is_file():
        raise FileFormatError(path, "no such URDF file")
    mesh_uris: dict[str, str] = {}
    xml = read_description(path, spec.package_paths, spec.xacro_args, mesh_uris)
    try:
        full = pin.buildModelFromXML(xml)
    except (RuntimeError, ValueError) as exc:
        raise FileFormatError(path, f"not a usable URDF: {exc}") from None
    locked, q_ref = _held_configuration(full, spec.held_joints, path)
    model = pin.buildReducedModel(full, locked, q_ref) if locked else full.copy()
    if model.nv == 0:
        raise FileFormatError(path, "the URDF has no movable joints")
    roles = _assign_roles(model, spec.frames, path)
    data = model.createData()
    base_id = model.getFrameId(roles["base"])
    if model.frames[base_id].parentJoint != 0:
        raise RobotSpecError(
            "robot.frames.base",
            f"frame {roles['base']!r} moves with joint {model.names[model.frames[base_id].parentJoint]!r}; the base "
            "must be fixed to the world",
            path,
        )
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    base2root = _to_mm(data.oMf[base_id])
    return RobotModel(model, data, path, xml, roles, base2root, full, tuple(locked), q_ref, mesh_uris)
