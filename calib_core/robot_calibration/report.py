"""The robot calibration's files.

``robot_calibration.yaml``: every parameter with its value and 1-sigma (identified or left at zero),
the observability, the residuals per view, the camera. ``<robot>_calibrated.urdf``: the robot's own
description (xacro expanded) with the corrected joint origins, the same structure otherwise, its meshes named as the
description named them (``package://...`` kept, so ROS finds them where it found the original's), as
robot_calibration writes it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import yaml

from calib_core.atomic_file import atomic_write_text
from calib_core.frames import concat, invert, transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.robot.model import RobotModel, _to_mm
from calib_core.robot_calibration.calibrated_robot import RobotCalibration


def _origin_mm(joint: ET.Element) -> np.ndarray:
    origin = joint.find("origin")
    xyz = [float(v) * 1000.0 for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()]
    rpy = [np.degrees(float(v)) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()]
    return transform_from_xyz_rpy(xyz, rpy)


def _set_origin(joint: ET.Element, T_mm: np.ndarray) -> None:
    origin = joint.find("origin")
    if origin is None:
        origin = ET.SubElement(joint, "origin")
    xyz, rpy = xyz_rpy_from_transform(T_mm)
    origin.set("xyz", " ".join(f"{v / 1000.0:.9g}" for v in xyz))
    origin.set("rpy", " ".join(f"{np.radians(v):.9g}" for v in rpy))


def calibrated_urdf(nominal: RobotModel, calibrated: RobotModel, camera_frame: str = "camera") -> tuple[str, list[str]]:
    """The nominal URDF text with each driven joint's origin (and the camera's and the TCP's fixed
    joints, when they are URDF links) replaced by the calibrated one; and what could not be written there."""
    root = ET.fromstring(nominal.urdf_xml)
    joints = {j.get("name"): j for j in root.iter("joint")}
    by_child = {j.find("child").get("link"): j for j in root.iter("joint") if j.find("child") is not None}
    left = []
    for k in range(1, nominal.model.njoints):
        name = nominal.model.names[k]
        element = joints.get(name)
        if element is None:
            left.append(f"joint {name}: not in the URDF")
            continue
        before, after = _to_mm(nominal.model.jointPlacements[k]), _to_mm(calibrated.model.jointPlacements[k])
        # Pinocchio folds fixed joints before this one into its placement: keep them, change this origin.
        folded = concat(invert(_origin_mm(element)), before)
        _set_origin(element, concat(after, invert(folded)))
    for role in (camera_frame, "tcp"):
        frame = nominal.roles.get(role, role)
        element = by_child.get(frame)
        before, after = nominal.frame_placement(role), calibrated.frame_placement(role)
        if np.allclose(before, after, atol=1e-9):
            continue
        if element is not None and element.get("type") == "fixed":
            folded = concat(invert(_origin_mm(element)), before)
            _set_origin(element, concat(after, invert(folded)))
        else:
            left.append(
                f"the {role} frame {frame!r} is not a URDF link: its calibrated placement is in robot_calibration.yaml "
                f"({'camera_on_parent' if role == camera_frame else 'tcp2cam'})"
            )
    for mesh in root.iter("mesh"):  # package:// meshes as the description named them, not where this machine found them
        original = nominal.mesh_uris.get(mesh.get("filename", ""), "")
        if original.startswith("package://"):
            mesh.set(
                "filename", original
            )  # (a path relative to the original URDF stays absolute: the file is written elsewhere)
    return ET.tostring(root, encoding="unicode"), left


def _xyz_rpy(T_mm: np.ndarray) -> dict:
    xyz, rpy = xyz_rpy_from_transform(T_mm)
    return {"xyz": [round(float(v), 4) for v in xyz], "rpy": [round(float(v), 5) for v in rpy]}


def calibration_document(result: RobotCalibration, nominal: RobotModel, camera_frame: str = "camera") -> dict:
    identified = set(result.observability.identified)
    i = result.intrinsics
    return {
        "units": {"length": "mm", "angle": "mrad for corrections, deg for rpy", "pixels": "px"},
        "model": "each joint's placement in its parent, and the camera's on its joint, corrected by a small transform "
        "applied before it, in the parent's frame",
        "parameters": {
            name: {
                "value": round(float(v), 5),
                "sigma": (round(float(s), 5) if k in identified else None),
                "identified": k in identified,
            }
            for k, (name, v, s) in enumerate(zip(result.names, result.values, result.sigmas))
        },
        "observability": {
            "identified": len(result.observability.identified),
            "of": len(result.names),
            "rank": result.observability.rank,
            "condition_number": round(result.observability.condition, 2),
            "unidentifiable_directions": [[f"{w:+.2f} {n}" for n, w in d] for d in result.observability.directions],
            "correlations_over_0_9": [[a, b, r] for a, b, r in result.observability.correlations],
        },
        "camera_on_parent": _xyz_rpy(result.robot.frame_placement(camera_frame)),
        "intrinsics": {
            "fu": i.fu,
            "fv": i.fv,
            "cx": i.cx,
            "cy": i.cy,
            "distortion": list(i.distortion),
            "distortion_model": i.model,
        },
        "board2base": None if result.board2base is None else _xyz_rpy(result.board2base),
        "rms_px": round(result.rms_px, 4),
        "start_rms_px": round(result.start_rms_px, 4),
        "noise_px": round(result.noise_px, 4),
        "noise_by_target_px": {k: round(v, 4) for k, v in result.noise_by_target_px.items()},
        "per_view_rms_px": {k: round(v, 4) for k, v in result.per_view_rms_px.items()},
        "warnings": list(result.warnings),
    }


def save_robot_calibration(
    folder: str | Path,
    result: RobotCalibration,
    nominal: RobotModel,
    camera_frame: str = "camera",
    *,
    robot: RobotModel | None = None,
    tool=None,
) -> tuple[Path, Path]:
    """Write ``robot_calibration.yaml`` and ``<urdf stem>_calibrated.urdf`` into ``folder``, atomically.
    ``robot``: the robot to write (default the identification's; with the TCP from the grasps, say);
    ``tool``: the :class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool` it came from."""
    folder = Path(folder)
    robot = robot or result.robot
    doc = calibration_document(result, nominal, camera_frame)
    if tool is not None:
        doc["tcp2cam"] = {
            **_xyz_rpy(tool.tcp2cam),
            "grasps": len(tool.per_grasp),
            "spread_mm": round(tool.spread_mm, 4),
            "spread_deg": round(tool.spread_deg, 5),
            "measured": "the TCP in the camera frame, from the gripper closed on surveyed fixtures",
        }
    doc["measured"] = [
        "the intrinsics (from the board views)",
        "the joints' placements the observability report lists as identified",
        "the camera's placement",
        "the board's placement",
    ] + (["the TCP from the camera (grasps)"] if tool is not None else [])
    doc["from_the_model"] = ["every parameter listed as not identified (left at the nominal value)"] + (
        [] if tool is not None else ["the TCP's placement on the flange"]
    )
    urdf, left = calibrated_urdf(nominal, robot, camera_frame)
    doc["warnings"] += left
    yaml_path = folder / "robot_calibration.yaml"
    urdf_path = folder / f"{Path(nominal.urdf_path).stem}_calibrated.urdf"
    atomic_write_text(urdf_path, urdf)
    atomic_write_text(yaml_path, yaml.safe_dump(doc, sort_keys=False))
    return yaml_path, urdf_path
