"""Corrected task locations as listings for the controllers people have: a URScript, a RAPID module, a KRL data
list, a FANUC TP program, a PDL2 program, each target written as the vendor's language declares a Cartesian pose
(:mod:`calib_core.workspace.vendor_poses`).

A pose alone does not fix the arm's configuration. Given the cell's robot, each target carries the one the arm takes
there (:mod:`calib_core.workspace.arm_configuration`: IK from the joints the look was made at): ABB ``confdata``,
KUKA ``S``/``T`` (a ``POS`` in place of a ``FRAME``), and for a UR the joints to pass as ``qnear`` to the controller's
own ``get_inverse_kin``; a target near a configuration boundary says so. FANUC's ``CONFIG`` is left to be taught
(docs/decisions/ says why), as is every configuration without the robot.
Variable names are made unique within a listing after the vendor's length limit. The listing's own name (RAPID's
``MODULE``, KRL's ``DEFDAT``, FANUC's ``/PROG``) is the file's, as the controllers require (a KRL data list whose
``DEFDAT`` differs from its file name is refused when loaded; a FANUC ``.ls`` is loaded under its ``/PROG`` name).
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from calib_core.calibration.corrections import CorrectionTable
from calib_core.workspace.arm_configuration import (
    ArmConfiguration,
    NotASixAxisArmError,
    abb_confdata,
    arm_configuration,
    kuka_status_turn,
)
from calib_core.errors import VideocalError
from calib_core.names import InvalidNameError, check_name
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.vendor_poses import (
    fanuc_position,
    krl_frame,
    pdl2_pos,
    rapid_robtarget,
    rapid_tooldata,
    urscript_pose,
)


def unique_identifiers(names: list[str], max_len: int, suffix: str = "_c") -> dict[str, str]:
    """Identifiers (letters, digits, ``_``; starting with a letter) for ``names``, at most
    ``max_len`` characters with ``suffix``, all different: truncated ones that collide get a number."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for name in names:
        base = "".join(ch if ch.isalnum() and ch.isascii() else "_" for ch in name) or "task"
        if not base[0].isalpha():
            base = "t_" + base
        stem = base[: max_len - len(suffix)]
        ident, k = stem + suffix, 2
        while ident.lower() in used:
            tail = f"{k}{suffix}"
            ident, k = stem[: max_len - len(tail)] + tail, k + 1
        used.add(ident.lower())
        out[name] = ident
    return out


_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def _remark(name: str) -> str:
    """A checked name as it may stand in any listing's comment: characters that end a comment or a
    line in some language (``;`` in FANUC TP, quotes) become ``_``."""
    return "".join(c if (c.isalnum() and c.isascii()) or c in " _-." else "_" for c in name)


@dataclass(frozen=True)
class Entry:
    """``ident``: the variable's name; ``pose`` (4, 4) mm in base: the target to command; ``note``: a remark;
    ``arm``: the arm's configuration there (``None`` without the robot; a string: why it is not known)."""

    ident: str
    pose: np.ndarray
    note: str
    arm: ArmConfiguration | str | None = None

    def arm_note(self, vendor_terms: str) -> str:
        """What a listing says of the configuration beside the target."""
        if isinstance(self.arm, ArmConfiguration):
            return f"{vendor_terms} from the arm at this target (IK from the look's joints)" + (
                f"; near a boundary: {'; '.join(self.arm.near)}: check it" if self.arm.near else ""
            )
        return f"{vendor_terms} must be taught" + (f" ({self.arm})" if self.arm else " (no robot given)")


DEFAULT_NAME = "videocal_corrections"


def listing_name(fmt: str, stem: str | None) -> str:
    """The listing's own name for a file named ``stem`` (``None``: :data:`DEFAULT_NAME`), as ``fmt`` requires it: an
    identifier within the language's limit (KRL 24, RAPID 32, FANUC 36 upper case). :class:`InvalidNameError` says why
    a file name cannot be one (the controller would refuse the file)."""
    name = stem or DEFAULT_NAME
    limit = {"krl": 24, "rapid": 32, "fanuc": 36}.get(fmt)
    if limit is None:
        return name
    if not _IDENTIFIER.fullmatch(name) or len(name) > limit:
        raise InvalidNameError(
            f"{name!r}: a {fmt} file's name is its "
            f"{'DEFDAT' if fmt == 'krl' else 'MODULE' if fmt == 'rapid' else 'program'} name: "
            f"a letter, then letters, digits or _, at most {limit} characters; rename the output file"
        )
    return name.upper() if fmt == "fanuc" else name


def _urscript(entries: list[Entry], when: str, name: str = DEFAULT_NAME, tool: np.ndarray | None = None) -> list[str]:
    lines = [
        f"# videocal corrected task locations, {when}",
        "# p[x, y, z, rx, ry, rz]: m and a rotation vector (rad) in the base frame: the target to command so the real "
        "tool reaches the planned location",
    ]
    if tool is not None:
        lines += [
            "# the tool (TCP) the targets are for, on the flange: set it before moving to them",
            f"set_tcp({urscript_pose(tool)})",
        ]
    for e in entries:
        lines += [f"# {e.note}", f"global {e.ident} = {urscript_pose(e.pose)}"]
        if isinstance(e.arm, ArmConfiguration):
            q = ", ".join(f"{v:.6f}" for v in np.radians(e.arm.axes_deg[:6]))
            lines += [
                f"# the joints (rad) near which the arm stands there: movej(get_inverse_kin({e.ident}, "
                f"qnear={e.ident}_qnear))" + (f"; near: {'; '.join(e.arm.near)}" if e.arm.near else ""),
                f"global {e.ident}_qnear = [{q}]",
            ]
    return lines


def _rapid(entries: list[Entry], when: str, name: str = DEFAULT_NAME, tool: np.ndarray | None = None) -> list[str]:
    lines = [
        f"MODULE {name}",
        f"  ! videocal corrected task locations, {when}",
        "  ! robtarget: mm and a quaternion [q1 (w), q2, q3, q4] in the base frame (wobj0), confdata [cf1, cf4, cf6, "
        "cfx]",
    ]
    if tool is not None:
        lines += [
            "  ! the tool (TCP) the targets are for; its load data is tool0's (0.001 kg): enter the real mass and "
            "centre of gravity",
            f"  PERS tooldata videocal_tool := {rapid_tooldata(tool)};",
        ]
    for e in entries:
        conf = abb_confdata(e.arm) if isinstance(e.arm, ArmConfiguration) else (0, 0, 0, 0)
        lines += [
            f"  ! {e.note}; {e.arm_note('confdata')}",
            f"  CONST robtarget {e.ident} := {rapid_robtarget(e.pose, conf)};",
        ]
    return lines + ["ENDMODULE"]


def _krl(entries: list[Entry], when: str, name: str = DEFAULT_NAME, tool: np.ndarray | None = None) -> list[str]:
    lines = [
        f"DEFDAT {name} PUBLIC",
        f"; videocal corrected task locations, {when}",
        "; {X, Y, Z, A, B, C}: mm and deg (A about Z, B about Y, C about X) in the robot's base frame; a POS carries S "
        "and T",
    ]
    if tool is not None:
        lines += [
            "; the tool (TCP) the targets are for, on the flange: TOOL_DATA[n]=videocal_tool, then $TOOL=TOOL_DATA[n]",
            f"DECL GLOBAL FRAME videocal_tool={krl_frame(tool)}",
        ]
    for e in entries:
        if isinstance(e.arm, ArmConfiguration):
            lines += [
                f"; {e.note}; {e.arm_note('S and T')}",
                f"DECL GLOBAL POS {e.ident}={krl_frame(e.pose, kuka_status_turn(e.arm))}",
            ]
        else:
            lines += [f"; {e.note}; {e.arm_note('S and T')}", f"DECL GLOBAL FRAME {e.ident}={krl_frame(e.pose)}"]
    return lines + ["ENDDAT"]


def _fanuc_attr(line_count: int, when: str) -> list[str]:
    """The ``/ATTR`` section every ``.ls`` file the controller writes has (dates as ``DATE yy-mm-dd TIME hh:mm:ss``)."""
    stamp = time.strptime(when, "%Y-%m-%d %H:%M:%S")
    date = f"DATE {time.strftime('%y-%m-%d', stamp)}  TIME {time.strftime('%H:%M:%S', stamp)}"
    return [
        "/ATTR",
        "OWNER\t\t= MNEDITOR;",
        'COMMENT\t\t= "videocal";',
        "PROG_SIZE\t= 0;",
        f"CREATE\t\t= {date};",
        f"MODIFIED\t= {date};",
        "FILE_NAME\t= ;",
        "VERSION\t\t= 0;",
        f"LINE_COUNT\t= {line_count};",
        "MEMORY_SIZE\t= 0;",
        "PROTECT\t\t= READ_WRITE;",
        "TCD:  STACK_SIZE\t= 0,",
        "      TASK_PRIORITY\t= 50,",
        "      TIME_SLICE\t= 0,",
        "      BUSY_LAMP_OFF\t= 0,",
        "      ABORT_REQUEST\t= 0,",
        "      PAUSE_REQUEST\t= 0;",
        "DEFAULT_GROUP\t= 1,*,*,*,*;",
        "CONTROL_CODE\t= 00000000 00000000;",
    ]


FANUC_UNTAUGHT = "TEACH ME"
"""What a FANUC position's CONFIG says until taught: not a configuration (those are 'F|N U|D T|B, t1, t4, t6'), so the
controller refuses the listing rather than loading a guessed one (docs/decisions/ says why none is derived)."""


def _fanuc(
    entries: list[Entry], when: str, name: str = DEFAULT_NAME.upper(), tool: np.ndarray | None = None
) -> list[str]:
    notes = [
        f"videocal corrected task locations, {when}",
        "positions in the robot's world frame: X Y Z mm, W P R deg (R = Rz(R) Ry(P) Rx(W))",
        f"CONFIG is not known: each P[n] says '{FANUC_UNTAUGHT}', which the controller refuses: teach it (TOUCHUP) "
        "before use",
    ]
    if tool is not None:
        x, y, z, w, p, r = fanuc_position(tool)
        notes += [
            "the tool frame (UTOOL 1) the targets are for, on the faceplate:",
            f"X {x:.3f} Y {y:.3f} Z {z:.3f} W {w:.3f} P {p:.3f} R {r:.3f}",
        ]
    notes += [f"P[{k}] {e.ident}: {e.note}" for k, e in enumerate(entries, start=1)]
    lines = (
        [f"/PROG  {name}"]
        + _fanuc_attr(len(notes), when)
        + ["/MN"]
        + [f"  {k:3d}:  ! {text} ;" for k, text in enumerate(notes, start=1)]
        + ["/POS"]
    )
    for k, e in enumerate(entries, start=1):
        x, y, z, w, p, r = fanuc_position(e.pose)
        lines += [
            f'P[{k}:"{e.ident}"]{{',
            "   GP1:",
            f"\tUF : 0, UT : 1,\t\tCONFIG : '{FANUC_UNTAUGHT}',",
            f"\tX = {x:10.3f}  mm,\tY = {y:10.3f}  mm,\tZ = {z:10.3f}  mm,",
            f"\tW = {w:10.3f} deg,\tP = {p:10.3f} deg,\tR = {r:10.3f} deg",
            "};",
        ]
    return lines + ["/END"]


def _pdl2(entries: list[Entry], when: str, name: str = DEFAULT_NAME, tool: np.ndarray | None = None) -> list[str]:
    lines = [
        f"-- videocal corrected task locations, {when}",
        "-- POS(x, y, z, e1, e2, e3, cnfg): mm, Euler ZYZ deg; the target to command so the real tool reaches the "
        "planned location",
        "VAR",
    ]
    lines += [f"  {e.ident} : POSITION  -- {e.note}" for e in entries]
    body = [f"  {e.ident} := {pdl2_pos(e.pose)}" for e in entries]
    if tool is not None:
        body = ["  $TOOL := " + pdl2_pos(tool) + "  -- the tool (TCP) the targets are for, on the flange"] + body
    return lines + ["BEGIN"] + body + ["END"]


# format -> (writer, longest variable name the language takes)
LISTINGS: dict[str, tuple[Callable[[list[Entry], str], list[str]], int]] = {
    "urscript": (_urscript, 63),
    "rapid": (_rapid, 32),
    "krl": (_krl, 24),
    "fanuc": (_fanuc, 16),
    "pdl2": (_pdl2, 24),
}
FORMATS = tuple(LISTINGS)


def corrected_targets(table: CorrectionTable, tasks: dict[str, TaskLocation]) -> dict[str, np.ndarray]:
    """The target to command (4, 4) mm in base for every corrected task location the workspace knows (one that holds
    only a measurement has none: it is left out, :func:`left_out`)."""
    return {
        name: table.corrected_target(name, tasks[name].tcp2base) for name in table.corrected_tasks() if name in tasks
    }


def left_out(table: CorrectionTable) -> list[str]:
    """One line for each task location an export leaves out because it holds only a measurement."""
    return [
        f"{task}: left out, it holds only a measurement (a look made away from its pose or on a recording), never a "
        "target to command"
        for task in table.measured_only()
    ]


REFERENCE_POSES = {"rapid": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0), "krl": (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)}
"""Each vendor's pose (controller axes, deg) whose elbow is the normal one: ABB's zero (cfx's "in front of the lower
arm"), KUKA's home (Status bit 1 set: A3 past the stretched arm's angle)."""


def _arm_at(fmt: str, robot, joint_map, target: np.ndarray, look_joints) -> ArmConfiguration | str | None:
    """The arm's configuration at ``target`` for ``fmt`` (``None``: the language has none here, or no robot)."""
    if robot is None or fmt not in ("rapid", "krl", "urscript"):
        return None
    from calib_core.connectors.joint_map import JointMap
    from calib_core.robot import solve_ik

    joint_map = joint_map or JointMap.identity(robot.n_joints)
    try:
        q = solve_ik(robot, target, np.asarray(look_joints, dtype=float)).q_deg
    except VideocalError as exc:
        return f"no IK at this target from the look's joints: {str(exc).splitlines()[0]}"
    if fmt == "urscript":
        return ArmConfiguration.of_axes(joint_map.to_controller(q))
    try:
        return arm_configuration(robot, joint_map, q, REFERENCE_POSES[fmt])
    except NotASixAxisArmError as exc:
        return str(exc)


def controller_listing(
    fmt: str,
    table: CorrectionTable,
    tasks: dict[str, TaskLocation],
    file_stem: str | None = None,
    tool: np.ndarray | None = None,
    robot=None,
    joint_map=None,
) -> str:
    """The corrected targets as a ``fmt`` listing (:data:`FORMATS`), one variable per task location,
    each with its measured displacement as a remark; named after the file it goes to (``file_stem``); with ``tool``
    (``tcp2flange`` (4, 4) mm), the tool data the targets are for, in the language's own form; with ``robot`` (the
    cell's :class:`~calib_core.robot.model.RobotModel`) and ``joint_map`` (model joints to controller axes; default
    the same), the arm's configuration at each target."""
    writer, max_name = LISTINGS[fmt]
    listing = listing_name(fmt, file_stem)
    targets = corrected_targets(table, tasks)
    for name in targets:  # never write a name that was not checked, whatever let it in
        check_name(name, "task location")
    idents = unique_identifiers(list(targets), max_name)
    for ident in idents.values():
        if not _IDENTIFIER.fullmatch(ident) or len(ident) > max_name:
            raise InvalidNameError(f"{ident!r} is not a {fmt} identifier")  # unique_identifiers' promise, kept here too
    entries = []
    for name, T in targets.items():
        c = table.latest(name)
        note = (
            f"{_remark(name)}: displacement {np.linalg.norm(c.displacement_mm):.2f} mm, "
            f"{np.linalg.norm(c.rotation_deg):.3f} deg; rms {c.rms_px:.2f} px, {c.pairs} pairs"
        )
        entries.append(Entry(idents[name], T, note, _arm_at(fmt, robot, joint_map, T, c.joints_deg)))
    return "\n".join(writer(entries, time.strftime("%Y-%m-%d %H:%M:%S"), listing, tool) + [""])
