"""The measured camera mounting in the two forms a ROS 2 system takes it: a launch file that runs
``tf2_ros``'s ``static_transform_publisher`` (ROS 2 Humble's named arguments: metres and a quaternion), and a URDF (a
document a
parser reads alone) or a xacro macro to include, with a fixed joint from the mount's link to the camera's (metres,
URDF's fixed-axis roll-pitch-yaw in radians). Plain text: no ROS needed to write them. The camera frame is videocal's (z
along
the optical axis, x right, y down), which is ROS's optical frame convention (REP 103: ``*_optical_frame``).
"""

from __future__ import annotations

from datetime import date
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.ros2.frame_names import DEFAULT_CAMERA_FRAME

LAUNCH_SUFFIXES = (".launch.py",)
URDF_SUFFIXES = (".urdf",)
XACRO_SUFFIXES = (".xacro",)


def _clean(camera2mount_mm) -> tuple[np.ndarray, np.ndarray]:
    """``camera2mount`` (4, 4) mm -> (xyz (3,) m, rotation (3, 3)), checked finite and a rotation."""
    T = np.asarray(camera2mount_mm, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise ValueError(f"camera2mount must be a finite (4, 4) transform, got shape {T.shape}")
    R = T[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0:
        raise ValueError("camera2mount's rotation is not a rotation (not orthonormal, or a reflection)")
    return T[:3, 3] / 1000.0, R


def static_transform_launch(camera2mount_mm, parent: str, child: str = DEFAULT_CAMERA_FRAME, note: str = "") -> str:
    """A ROS 2 Python launch file publishing ``child`` in ``parent`` on ``/tf_static``."""
    xyz, R = _clean(camera2mount_mm)
    qx, qy, qz, qw = Rotation.from_matrix(R).as_quat()
    numbers = {"x": xyz[0], "y": xyz[1], "z": xyz[2], "qx": qx, "qy": qy, "qz": qz, "qw": qw}
    args = ", ".join(f'"--{k}", "{v:.9g}"' for k, v in numbers.items())
    return (
        f'"""Written by videocal on {date.today().isoformat()}: the camera mounting{": " + note if note else ""}.\n\n'
        f"ros2 launch ./this_file.launch.py publishes {child} in {parent} on /tf_static (metres, quaternion x y z w).\n"
        '"""\n\n'
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n\n\n"
        "def generate_launch_description():\n"
        "    return LaunchDescription([\n"
        '        Node(package="tf2_ros", executable="static_transform_publisher", name="videocal_camera_mounting",\n'
        f'             arguments=[{args}, "--frame-id", "{parent}", "--child-frame-id", "{child}"]),\n'
        "    ])\n"
    )


def _origin(camera2mount_mm) -> str:
    xyz, R = _clean(camera2mount_mm)
    rpy = Rotation.from_matrix(R).as_euler("xyz")  # URDF's rpy: roll about x, pitch about y, yaw about z, fixed axes
    fmt = lambda v: " ".join(f"{x:.9g}" for x in v)
    return f'<origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>'


def _header(note: str) -> str:
    return (
        f"<!-- Written by videocal on {date.today().isoformat()}: the camera mounting{': ' + note if note else ''}. "
        "Metres and radians. -->\n"
    )


def urdf_document(camera2mount_mm, parent: str, child: str = DEFAULT_CAMERA_FRAME, note: str = "") -> str:
    """A URDF that any parser reads alone: the ``parent`` link, the camera's ``child`` link and the fixed joint between
    them (check_urdf, urdf_parser_py, Pinocchio). Its joint and child link are what a robot's description takes."""
    return (
        '<?xml version="1.0"?>\n' + _header(note) + '<robot name="videocal_camera_mounting">\n'
        f'  <link name="{parent}"/>\n'
        f'  <link name="{child}"/>\n'
        f'  <joint name="{child}_joint" type="fixed">\n'
        f'    <parent link="{parent}"/>\n'
        f'    <child link="{child}"/>\n'
        f"    {_origin(camera2mount_mm)}\n"
        "  </joint>\n"
        "</robot>\n"
    )


def xacro_macro(camera2mount_mm, parent: str, child: str = DEFAULT_CAMERA_FRAME, note: str = "") -> str:
    """A xacro file defining the macro ``videocal_camera_mounting`` (parameters ``parent`` and ``child``, defaulting to
    these frames): ``<xacro:include filename="...">`` it in the robot's description and call
    ``<xacro:videocal_camera_mounting/>`` to add the camera's link and its fixed joint."""
    return (
        '<?xml version="1.0"?>\n' + _header(note) + '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        f'  <xacro:macro name="videocal_camera_mounting" params="parent:={parent} child:={child}">\n'
        '    <link name="${child}"/>\n'
        '    <joint name="${child}_joint" type="fixed">\n'
        '      <parent link="${parent}"/>\n'
        '      <child link="${child}"/>\n'
        f"      {_origin(camera2mount_mm)}\n"
        "    </joint>\n"
        "  </xacro:macro>\n"
        "</robot>\n"
    )


def mounting_text_for(
    path: str | Path, camera2mount_mm, parent: str, child: str = DEFAULT_CAMERA_FRAME, note: str = ""
) -> str | None:
    """The text ``path``'s suffix asks for (``.launch.py``: the launch file; ``.urdf``: a URDF read alone; ``.xacro``:
    the xacro macro), or ``None`` for any other suffix (videocal's own YAML)."""
    name = Path(path).name.lower()
    if name.endswith(LAUNCH_SUFFIXES):
        return static_transform_launch(camera2mount_mm, parent, child, note=note)
    if name.endswith(XACRO_SUFFIXES):
        return xacro_macro(camera2mount_mm, parent, child, note=note)
    if name.endswith(URDF_SUFFIXES):
        return urdf_document(camera2mount_mm, parent, child, note=note)
    return None
