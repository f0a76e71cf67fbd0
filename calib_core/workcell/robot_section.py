"""The ``robot`` section of a workcell file: its description, package paths, frames, joints and
the controller's numbering. Every error names the workcell file and the field."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from calib_core.frames import transform_from_xyz_rpy
from calib_core.robot.spec import FRAME_ROLES, ControllerMap, NewFrame, RobotSpec

ROBOT_KEYS = {"urdf", "package_paths", "xacro_args", "frames", "home_joints_deg", "held_joints", "controller"}


def _frame(reader, value, field: str) -> str | NewFrame | None:
    if value is None:  # the URDF's root link (for base)
        return None
    if isinstance(value, str):
        return reader.text(value, field)
    raw = reader.mapping(value, field, {"parent", "xyz", "rpy"}, {"parent", "xyz", "rpy"})
    placement = transform_from_xyz_rpy(
        reader.vector(raw["xyz"], 3, f"{field}.xyz"), reader.vector(raw["rpy"], 3, f"{field}.rpy")
    )
    return NewFrame(reader.text(raw["parent"], f"{field}.parent"), placement)


def _folder(reader, value, field: str) -> Path:
    path = (reader.path.parent / reader.text(value, field)).resolve()
    if not path.is_dir():
        raise reader.fail(field, f"folder not found: {path}")
    return path


def _numbers(reader, value, field: str) -> np.ndarray:
    if not isinstance(value, (list, tuple)) or not value:
        raise reader.fail(field, f"must be a non-empty list of numbers, got {value!r}")
    return np.array([reader.number(v, f"{field}[{i}]") for i, v in enumerate(value)])


def read_robot_section(reader, raw) -> RobotSpec:
    """A :class:`RobotSpec` from the parsed ``robot`` mapping; ``reader`` is the workcell's."""
    raw = reader.mapping(raw, "robot", ROBOT_KEYS, {"urdf"})
    urdf = reader.file(raw["urdf"], "robot.urdf")
    paths_raw = raw.get("package_paths", []) or []
    if not isinstance(paths_raw, list):
        raise reader.fail("robot.package_paths", "must be a list of folders (relative to the workcell file)")
    package_paths = tuple(_folder(reader, p, f"robot.package_paths[{i}]") for i, p in enumerate(paths_raw))
    args_raw = raw.get("xacro_args", {}) or {}
    if not isinstance(args_raw, dict):
        raise reader.fail("robot.xacro_args", "must be a mapping of xacro argument: value (ur_type: ur10e)")
    xacro_args = {}
    for k, v in args_raw.items():
        if not isinstance(k, str) or not isinstance(v, (str, int, float, bool)):
            raise reader.fail(f"robot.xacro_args.{k}", f"must be a plain value (text or number), got {v!r}")
        xacro_args[k] = str(v).lower() if isinstance(v, bool) else str(v)
    frames_raw = raw.get("frames", {}) or {}
    reader.mapping(frames_raw, "robot.frames", set(FRAME_ROLES), set())
    frames = {"base": None, "flange": "flange", "tcp": "tcp", "camera": "camera"}
    frames.update({role: _frame(reader, v, f"robot.frames.{role}") for role, v in frames_raw.items()})
    home = (
        _numbers(reader, raw["home_joints_deg"], "robot.home_joints_deg")
        if raw.get("home_joints_deg") is not None
        else None
    )
    held_raw = raw.get("held_joints", {}) or {}
    if not isinstance(held_raw, dict):
        raise reader.fail("robot.held_joints", "must be a mapping of joint name: value (deg or mm)")
    held = {str(k): reader.number(v, f"robot.held_joints.{k}") for k, v in held_raw.items()}
    controller = None
    if raw.get("controller") is not None:
        c = reader.mapping(raw["controller"], "robot.controller", {"joints", "zero_offsets"}, {"joints"})
        if not isinstance(c["joints"], list) or not c["joints"]:
            raise reader.fail(
                "robot.controller.joints", "must be the list of URDF joint names in the controller's axis order"
            )
        joints = tuple(reader.text(j, f"robot.controller.joints[{i}]") for i, j in enumerate(c["joints"]))
        offsets = (
            _numbers(reader, c["zero_offsets"], "robot.controller.zero_offsets")
            if c.get("zero_offsets") is not None
            else np.zeros(len(joints))
        )
        if len(offsets) != len(joints):
            raise reader.fail(
                "robot.controller.zero_offsets",
                f"needs one value per controller joint ({len(joints)}), got {len(offsets)}",
            )
        controller = ControllerMap(joints, offsets)
    return RobotSpec(urdf, package_paths, frames, home, held, controller, xacro_args)


def check_against_robot(reader, spec: RobotSpec, robot) -> np.ndarray:
    """Validate the section against the loaded robot; returns the home joints (n,) deg/mm."""
    n = robot.n_joints
    if spec.home_joints is None:
        home = np.clip(np.zeros(n), robot.lower_limits_deg, robot.upper_limits_deg)
    else:
        if len(spec.home_joints) != n:
            raise reader.fail(
                "robot.home_joints_deg",
                f"the robot drives {n} joints ({', '.join(robot.joint_names)}), the list has {len(spec.home_joints)} "
                "values",
            )
        home = spec.home_joints
        outside = np.flatnonzero(~robot.within_limits(home))
        if len(outside):
            j = int(outside[0])
            raise reader.fail(
                f"robot.home_joints_deg[{j}]",
                f"{home[j]:g} {robot.joint_units[j]} is outside joint '{robot.joint_names[j]}' limits "
                f"[{robot.lower_limits_deg[j]:g}, {robot.upper_limits_deg[j]:g}]",
            )
    if spec.controller is not None:
        unknown = [j for j in spec.controller.joints if j not in robot.joint_names]
        if unknown:
            raise reader.fail(
                "robot.controller.joints",
                f"not driven joints of the robot: {', '.join(unknown)}; driven joints: {', '.join(robot.joint_names)}",
            )
        if sorted(spec.controller.joints) != sorted(robot.joint_names):
            raise reader.fail(
                "robot.controller.joints", f"must name each driven joint once: {', '.join(robot.joint_names)}"
            )
    return np.asarray(home, dtype=float)
