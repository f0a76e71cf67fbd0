"""A starting cell for a robot description: ``videocal new-cell``.

From a vendor URDF (or xacro) it writes a folder that loads and renders at once: the workcell
file (the robot with its frames named, no vendor file edited), a floor, an example target
component with named features, the camera file, and a task location the robot reaches with the
camera seeing the target. The operator then replaces the example by the real components.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from calib_core.errors import FileWriteError, VideocalError
from calib_core.frames import concat, invert, make_transform, transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.workcell.flange_choice import choose_flange, tool_alignment
from calib_core.robot import UnreachableTargetError, solve_ik
from calib_core.robot.model import RobotModel, load_robot
from calib_core.robot.spec import NewFrame, RobotSpec
from calib_core.robot.reach import reach_of
from calib_core.workcell.task_pose import find_task

BUNDLED_CAMERA = Path(__file__).resolve().parents[2] / "resources" / "camera" / "gripper_camera.yaml"
TCP_MM = 150.0
CAMERA_OUT_MM = 40.0
"""The example camera sits this far out along the tool from the flange, off the tool axis on the
side where the hand leaves room (the side the task location points up)."""
GRASP_STANDOFF_MM = 30.0
"""The task location puts the TCP this far in front of the target's face (at its pin tip)."""
APPROACH_MM = 150.0

# The example target, in its own frame: x out of its front face (toward the robot), y to the robot's
# right, z up. A plate with a raised block on it, turned up by BLOCK_TILT_DEG about y so that its face
# is lit differently from the plate's and its four corners stand out in the camera image, and a pin.
PLATE = (10.0, 130.0, 90.0)
BLOCK = (12.0, 70.0, 40.0)
BLOCK_TILT_DEG = 20.0
_BLOCK2TARGET = transform_from_xyz_rpy([0.0, 0.0, 0.0], [0.0, -BLOCK_TILT_DEG, 0.0])


def _block_corner(y: float, z: float) -> list[float]:
    return [float(v) for v in (_BLOCK2TARGET @ np.array([BLOCK[0], y, z, 1.0]))[:3]]


# Left and right as seen from the robot.
FEATURES = {
    "plate_corner_top_left": [0.0, -PLATE[1] / 2, PLATE[2] / 2],
    "plate_corner_top_right": [0.0, PLATE[1] / 2, PLATE[2] / 2],
    "plate_corner_bottom_left": [0.0, -PLATE[1] / 2, -PLATE[2] / 2],
    "plate_corner_bottom_right": [0.0, PLATE[1] / 2, -PLATE[2] / 2],
    "block_corner_top_left": _block_corner(-BLOCK[1] / 2, BLOCK[2] / 2),
    "block_corner_top_right": _block_corner(BLOCK[1] / 2, BLOCK[2] / 2),
    "block_corner_bottom_left": _block_corner(-BLOCK[1] / 2, -BLOCK[2] / 2),
    "block_corner_bottom_right": _block_corner(BLOCK[1] / 2, -BLOCK[2] / 2),
    "pin_tip": [GRASP_STANDOFF_MM, 0.0, 0.0],
}


class StarterCellError(VideocalError, RuntimeError):
    """No starting cell can be made for this robot (the message says why)."""


@dataclass(frozen=True)
class StarterCell:
    """What :func:`write_starter_cell` wrote: the workcell file, and the frames and poses it chose."""

    workcell_path: Path
    flange: str
    base: str | None
    held_joints: dict[str, float]
    home_joints: np.ndarray
    task_tcp2base: np.ndarray
    target2base: np.ndarray
    flange_why: str = ""
    """Why this frame was taken as the flange (said by ``new-cell``)."""
    tool_axis_warning: str | None = None
    """Words for a flange whose z did not point away from the wrist (the tool was placed along the way out), else
    ``None``."""


def _target_mesh() -> trimesh.Trimesh:
    plate = trimesh.creation.box(extents=PLATE)
    plate.apply_translation([-PLATE[0] / 2, 0.0, 0.0])
    block = trimesh.creation.box(extents=BLOCK)
    block.apply_translation([BLOCK[0] / 2, 0.0, 0.0])
    block.apply_transform(_BLOCK2TARGET)
    pin = trimesh.creation.cylinder(radius=4.0, height=GRASP_STANDOFF_MM - BLOCK[0], sections=24)
    pin.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    pin.apply_translation([BLOCK[0] + (GRASP_STANDOFF_MM - BLOCK[0]) / 2, 0.0, 0.0])
    return trimesh.util.concatenate([plate, block, pin])


def _chain_to(full_model, frame: str) -> set[int]:
    """Joint ids on the path from the root to ``frame``."""
    return set(_chain_ids(full_model, full_model.frames[full_model.getFrameId(frame)].parentJoint))


def _chain_ids(model, joint: int) -> list[int]:
    out = []
    while joint > 0:
        out.append(joint)
        joint = model.parents[joint]
    return out


def _tool_side(robot: RobotModel, flange: str, align: np.ndarray | None = None) -> tuple[float, float]:
    """Where the camera clears the tool: (yaw of the TCP about the tool axis, deg; the camera's offset
    from the tool axis, mm). The camera goes on the side where the links fixed to the flange (hand,
    fingers) reach out least between the flange and the TCP. ``align`` (4, 4): the tool's frame in the
    flange's (:func:`tool_alignment`), identity by default."""
    from calib_core.robot.visuals import RobotVisuals

    visuals = RobotVisuals.from_robot(robot)
    q = np.clip(np.zeros(robot.n_joints), robot.lower_limits_deg, robot.upper_limits_deg)
    flange2base = concat(np.eye(4) if align is None else align, robot.fk(q, flange))  # the tool's frame
    last_joint = robot.model.frames[robot.frame_id(flange)].parentJoint
    points = []
    for g, mesh, pose in zip(visuals.geometry_model.geometryObjects, visuals.meshes, visuals.poses(q)):
        if g.parentJoint == last_joint:
            p = concat(pose, invert(flange2base)) @ np.c_[mesh.vertices, np.ones(len(mesh.vertices))].T
            points.append(p[:3].T)
    points = np.concatenate(points) if points else np.zeros((1, 3))
    points = points[(points[:, 2] > -20.0) & (points[:, 2] < TCP_MM)]
    if len(points) == 0:
        points = np.zeros((1, 3))
    # yaw such that the TCP's -y (where the camera sits) is this flange direction
    sides = {0.0: -points[:, 1].min(), 180.0: points[:, 1].max(), 90.0: points[:, 0].max(), -90.0: -points[:, 0].min()}
    yaw = min(sides, key=sides.get)
    return yaw, max(float(sides[yaw]) + 25.0, 50.0)


def _camera_frame(offset_mm: float) -> np.ndarray:
    """cam2tcp-aligned frame: off-axis on the TCP's -y side, ``CAMERA_OUT_MM`` out along the tool,
    looking along the tool axis, tilted to aim at the target face at the grasp."""
    aim = TCP_MM + GRASP_STANDOFF_MM
    tilt = -np.degrees(
        np.arctan2(offset_mm, aim - CAMERA_OUT_MM)
    )  # about x: the optical axis turns toward the tool axis
    return transform_from_xyz_rpy([0.0, -offset_mm, CAMERA_OUT_MM], [tilt, 0.0, 0.0])


def _find_task(
    robot: RobotModel, home: np.ndarray, camera_yaw_deg: float, floor_z_mm: float
) -> tuple[np.ndarray, np.ndarray]:
    """A reachable grasp (tcp2base) facing +x in front of the robot, and the joints that reach its approach: unfolded
    where the arm's joints are read (:mod:`calib_core.workcell.task_pose`), else the first reached, from the middle
    of the workspace outward."""
    # The camera's side of the tool (OpenCV axes, turned camera_yaw_deg about the tool from the TCP's -y) up, the tool
    # along base +x (toward the target): the camera looks from above with the image upright.
    upright = np.column_stack([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    R = upright @ transform_from_xyz_rpy([0, 0, 0], [0, 0, -camera_yaw_deg])[:3, :3]
    unfolded = find_task(robot, R, home, APPROACH_MM, max(150.0, floor_z_mm + 150.0))
    if unfolded is not None:
        return unfolded
    reach, height = reach_of(robot)
    for fraction in (0.55, 0.45, 0.65, 0.35, 0.75):
        for z in (height, 0.8 * height, 1.2 * height, 0.5 * reach):
            tcp = make_transform(R, [fraction * reach, 0.0, max(z, 150.0)])
            approach = concat(make_transform(np.eye(3), [0.0, 0.0, -APPROACH_MM]), tcp)
            try:
                q_approach = solve_ik(robot, approach, home, extra_seeds=16).q_deg
                solve_ik(robot, tcp, q_approach, extra_seeds=4)
            except UnreachableTargetError:
                continue
            return tcp, q_approach
    raise StarterCellError(
        "found no grasp pose in front of the robot that it reaches with the tool pointing forward; give --flange (the "
        "frame whose z points out of the tool)"
    )


def _yaml_pose(T: np.ndarray) -> str:
    xyz, rpy = xyz_rpy_from_transform(T)
    return "{xyz: [%s], rpy: [%s]}" % (", ".join(f"{v:.2f}" for v in xyz), ", ".join(f"{v:.4f}" for v in rpy))


def _frame_yaml(parent: str, T: np.ndarray) -> str:
    xyz, rpy = xyz_rpy_from_transform(T)
    return "{parent: %s, xyz: [%s], rpy: [%s]}" % (
        parent,
        ", ".join(f"{v:.2f}" for v in xyz),
        ", ".join(f"{v:.4f}" for v in rpy),
    )


def write_starter_cell(
    folder: str | Path,
    urdf: str | Path,
    package_paths: list[str | Path] = (),
    *,
    flange: str | None = None,
    name: str | None = None,
    xacro_args: dict[str, str] | None = None,
) -> StarterCell:
    """Write a starting cell for the robot ``urdf`` into ``folder`` (created; an existing
    ``workcell.yaml`` there is refused). Returns what was chosen."""
    folder = Path(folder)
    urdf = Path(urdf).resolve()
    package_paths = [Path(p).resolve() for p in package_paths]
    if (folder / "workcell.yaml").exists():
        raise StarterCellError(f"{folder / 'workcell.yaml'} exists already: choose an empty folder")
    xacro_args = dict(xacro_args or {})
    plain = load_robot(RobotSpec(urdf, tuple(package_paths), {"base": None}, xacro_args=xacro_args))
    choice = choose_flange(plain, flange)
    flange = choice.name
    align, axis_warning = tool_alignment(plain, flange)
    base = (
        "base"
        if plain.model.existFrame("base") and plain.model.frames[plain.model.getFrameId("base")].parentJoint == 0
        else None
    )
    driven = _chain_to(plain.full_model, flange)
    held = {plain.full_model.names[j]: 0.0 for j in range(1, plain.full_model.njoints) if j not in driven}
    robot = load_robot(RobotSpec(urdf, tuple(package_paths), {"base": base}, None, held, xacro_args=xacro_args))
    yaw, offset = _tool_side(robot, flange, align)
    turn = concat(
        transform_from_xyz_rpy([0, 0, 0], [0, 0, yaw]), align
    )  # (in the flange's frame: aligned, then turned about the tool)
    # The TCP is the flange moved along its z, not turned (the tool data a controller takes is a pure offset, for every
    # vendor's flange); the camera goes on the side the hand leaves room, turned about the tool from the TCP's -y.
    frames = {
        "base": base,
        "flange": flange,
        "tcp": NewFrame(flange, align @ transform_from_xyz_rpy([0, 0, TCP_MM], [0, 0, 0])),
        "camera": NewFrame(flange, turn @ _camera_frame(offset)),
    }
    robot = load_robot(RobotSpec(urdf, tuple(package_paths), frames, None, held, xacro_args=xacro_args))
    home = np.clip(np.zeros(robot.n_joints), robot.lower_limits_deg, robot.upper_limits_deg)
    floor_z = _floor_z_mm(robot, home)
    tcp, q_approach = _find_task(robot, home, yaw, floor_z)
    home = q_approach  # start where the camera already sees the target from the approach
    # The target's face centre sits GRASP_STANDOFF_MM beyond the TCP, facing the robot (its x toward -x base).
    target2base = make_transform(
        np.column_stack([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]),
        tcp[:3, 3] + [GRASP_STANDOFF_MM, 0.0, 0.0],
    )
    reach, _ = reach_of(robot)

    made_parents = [d for d in folder.parents if not d.exists()]
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        # Written into a folder beside the target and moved into place whole: a full disk, a read-only folder or an
        # error half-way leaves nothing behind
        staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.partial-", dir=folder.parent))
    except OSError as exc:
        raise FileWriteError(folder, f"cannot make the cell's folder ({exc.strerror or exc})") from None
    try:
        _write_files(
            staging,
            folder,
            urdf,
            package_paths,
            name,
            xacro_args,
            base,
            flange,
            frames,
            home,
            held,
            tcp,
            target2base,
            reach,
            floor_z,
        )
        _move_into(staging, folder)
    except OSError as exc:
        raise FileWriteError(
            folder, f"cannot write the cell ({exc.strerror or exc}); nothing was left behind"
        ) from None
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if not (folder / "workcell.yaml").exists():
            for d in made_parents:
                try:
                    d.rmdir()
                except OSError:
                    break
    from calib_core.workcell.loader import load_workcell

    load_workcell(folder / "workcell.yaml")  # what was written must load
    return StarterCell(folder / "workcell.yaml", flange, base, held, home, tcp, target2base, choice.why, axis_warning)


def _move_into(staging: Path, folder: Path) -> None:
    """Everything in ``staging`` into ``folder``: renamed whole when ``folder`` is new, else file by file."""
    if not folder.exists():
        os.rename(staging, folder)
        staging.mkdir()  # for the caller's clean-up
        return
    for item in sorted(staging.rglob("*"), key=lambda q: len(q.parts)):
        target = folder / item.relative_to(staging)
        if item.is_dir():
            target.mkdir(exist_ok=True)
        else:
            os.replace(item, target)


def _floor_z_mm(robot: RobotModel, q_deg) -> float:
    """The height (mm, base frame z) of the floor's top: under the robot's fixed links (the mounting that moves with
    no joint), which on FANUC's and Yaskawa's packages reach 330 mm below their ``base`` frame; 0 when they stand
    on or above it, or have no geometry."""
    from calib_core.robot.visuals import RobotVisuals

    visuals = RobotVisuals.from_robot(robot)
    lows = [
        float(trimesh.transform_points(trimesh.bounds.corners(mesh.bounds), pose)[:, 2].min())
        if len(mesh.vertices)
        else 0.0
        for g, mesh, pose in zip(visuals.geometry_model.geometryObjects, visuals.meshes, visuals.poses(q_deg))
        if g.parentJoint == 0
    ]
    return min(0.0, min(lows, default=0.0))


def _write_files(
    folder: Path,
    final: Path,
    urdf,
    package_paths,
    name,
    xacro_args,
    base,
    flange,
    frames,
    home,
    held,
    tcp,
    target2base,
    reach,
    floor_z=0.0,
) -> None:
    """The cell's files into ``folder`` (paths in them relative to ``final``, a sibling: the same relative paths);
    the floor's top at ``floor_z`` (mm, base frame)."""
    meshes = folder / "meshes"
    meshes.mkdir(exist_ok=True)
    floor = trimesh.creation.box(extents=(3.0 * reach, 3.0 * reach, 10.0))
    floor.apply_translation([0.0, 0.0, -5.0])
    floor.export(meshes / "floor.stl")
    target = _target_mesh()
    post_height = max(target2base[2, 3] - floor_z - PLATE[2] / 2, 1.0)
    post = trimesh.creation.box(extents=(20.0, 20.0, post_height))  # from the plate's back down to the floor
    post.apply_translation([-PLATE[0] - 10.0, 0.0, -PLATE[2] / 2 - post_height / 2 + 20.0])
    trimesh.util.concatenate([target, post]).export(meshes / "target.stl")
    shutil.copyfile(BUNDLED_CAMERA, folder / "camera.yaml")

    rel = lambda p: os.path.relpath(p, final.resolve())  # noqa: E731 - paths relative to the workcell file
    lines = [
        f"# A starting cell for {json.dumps(urdf.name)}, written by videocal new-cell. Schema: docs/workcell.md.",
        "# Replace the example target by your components (placements as surveyed, in the robot's base frame).",
        "schema_version: 2",
        # JSON's strings are YAML's: a newline or '#' stays in the value
        f"name: {json.dumps(name or urdf.stem + ' cell')}",
        "units: {length: mm, angle: deg}",
        "",
        "robot:",
        f"  urdf: {json.dumps(rel(urdf))}",
    ]
    if package_paths:
        lines.append("  package_paths: [" + ", ".join(json.dumps(rel(p)) for p in package_paths) + "]")
    if xacro_args:
        lines.append("  xacro_args: {" + ", ".join(f"{k}: {json.dumps(v)}" for k, v in xacro_args.items()) + "}")
    lines += [
        "  frames:",
        f"    base: {json.dumps(base) if base else '~'}" + ("" if base else "                # the URDF's root link"),
        f"    flange: {json.dumps(flange)}",
        f"    tcp: {_frame_yaml(flange, frames['tcp'].frame2parent)}",
        f"    camera: {_frame_yaml(flange, frames['camera'].frame2parent)}   # OpenCV axes",
        "  home_joints_deg: [" + ", ".join(f"{v:.3f}" for v in home) + "]",
    ]
    if held:
        lines.append("  held_joints: {" + ", ".join(f"{k}: 0" for k in held) + "}   # not driven (deg or mm)")
    lines += (
        [
            "",
            "camera:",
            "  intrinsics: camera.yaml",
            "",
            "components:",
            "  - name: floor",
            "    kind: fixture",
            "    mesh: meshes/floor.stl",
            "    mesh_units: mm",
            "    color: [0.55, 0.56, 0.58]",
            f"    placement: {{xyz: [0, 0, {floor_z:.2f}], rpy: [0, 0, 0]}}"
            + ("   # under the robot's base link" if floor_z < 0 else ""),
            "  - name: target",
            "    kind: component",
            "    mesh: meshes/target.stl",
            "    mesh_units: mm",
            "    color: [0.80, 0.78, 0.72]",
            f"    placement: {_yaml_pose(target2base)}",
            "    features:",
        ]
        + [f"      {k}: [{', '.join(f'{v:.6g}' for v in p)}]" for k, p in FEATURES.items()]
        + [
            "",
            "task_locations:",
            "  - name: target_grasp",
            "    component: target",
            f"    tcp2base: {_yaml_pose(tcp)}",
            f"    approach_mm: {APPROACH_MM:g}",
            "",
        ]
    )
    (folder / "workcell.yaml").write_text("\n".join(lines), encoding="utf-8")
