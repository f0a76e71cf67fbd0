"""Exports of the correction table: JSON and CSV with every stored correction (the displacement, its
sigma and the corrected target pose to command), and controller listings
(:mod:`calib_core.workspace.controller_formats`). Poses are in the cell's base frame, mm and degrees."""

from __future__ import annotations

import csv
import io
import json

import numpy as np

from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.frames import concat, invert, xyz_rpy_from_transform
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.controller_formats import FORMATS, controller_listing
from calib_core.workspace.workspace import _correction_dict, _pose

CSV_COLUMNS = (
    "task",
    "time_s",
    "dx_mm",
    "dy_mm",
    "dz_mm",
    "rx_deg",
    "ry_deg",
    "rz_deg",
    "sd_dx_mm",
    "sd_dy_mm",
    "sd_dz_mm",
    "sd_rx_deg",
    "sd_ry_deg",
    "sd_rz_deg",
    "target_x_mm",
    "target_y_mm",
    "target_z_mm",
    "target_roll_deg",
    "target_pitch_deg",
    "target_yaw_deg",
    "rms_px",
    "pairs",
    "source",
    "tool_x_mm",
    "tool_y_mm",
    "tool_z_mm",
    "tool_roll_deg",
    "tool_pitch_deg",
    "tool_yaw_deg",
)
"""The ``tool_*`` columns: the TCP on the flange the targets are for (empty without the cell's robot)."""
from calib_core.workspace.export_formats import EXPORT_FORMATS, LISTING_FORMATS  # noqa: E402,F401 (EXPORT_FORMATS: the formats by name, for those who import them from here)

assert FORMATS == LISTING_FORMATS, "the listings' names in export_formats.py follow controller_formats.LISTINGS"


def _target(c: Correction, tasks: dict[str, TaskLocation]):
    """The pose to command so the real tool reaches the planned location, with this correction."""
    task = tasks.get(c.task)
    if task is None or c.kind != "correction":  # a measurement at another pose is never commanded
        return None
    return concat(task.tcp2base, invert(c.delta_base))


def corrections_json(
    table: CorrectionTable, tasks: dict[str, TaskLocation] | None = None, tool: np.ndarray | None = None
) -> str:
    """Every correction; with ``tasks``, each also with ``target_to_command`` ({xyz mm, rpy deg} in base); with
    ``tool`` (``tcp2flange`` (4, 4) mm), ``tool_on_flange``: the TCP the targets are for."""
    rows = []
    for t in table.tasks():
        for c in table.history(t):
            row = _correction_dict(c)
            target = _target(c, tasks or {})
            if target is not None:
                row["target_to_command"] = _pose(target)
            rows.append(row)
    doc = {"frame": "base", "units": {"length": "mm", "angle": "deg", "rpy": "fixed axes x, y, z"}, "corrections": rows}
    if tool is not None:
        doc["tool_on_flange"] = _pose(tool)
    return json.dumps(doc, indent=1)


def _cell(text: str) -> str:
    # A spreadsheet runs a cell that starts with one of these as a formula: keep it text.
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def corrections_csv(
    table: CorrectionTable, tasks: dict[str, TaskLocation] | None = None, tool: np.ndarray | None = None
) -> str:
    """Every stored correction (history included), one row each, mm and degrees; the target columns
    are empty for a task location the workspace does not know, the tool columns without ``tool``
    (``tcp2flange`` (4, 4) mm: the TCP the targets are for)."""
    tool_cells = [""] * 6
    if tool is not None:
        xyz, rpy = xyz_rpy_from_transform(tool)
        tool_cells = [f"{v + 0.0:.4f}" for v in xyz] + [f"{v + 0.0:.5f}" for v in rpy]  # (+ 0.0: no "-0.00000")
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(CSV_COLUMNS)
    for task in table.tasks():
        for c in table.history(task):
            target = _target(c, tasks or {})
            pose = [""] * 6
            if target is not None:
                xyz, rpy = xyz_rpy_from_transform(target)
                pose = [f"{v:.4f}" for v in xyz] + [f"{v:.5f}" for v in rpy]
            w.writerow(
                [
                    _cell(c.task),
                    f"{c.time_s:.3f}",
                    *(f"{v:.4f}" for v in c.displacement_mm),
                    *(f"{v:.5f}" for v in c.rotation_deg),
                    *(f"{v:.4f}" for v in c.std_displacement_mm),
                    *(f"{v:.5f}" for v in c.std_rotation_deg),
                    *pose,
                    f"{c.rms_px:.3f}",
                    c.pairs,
                    _cell(c.source),
                    *tool_cells,
                ]
            )
    return out.getvalue()


def corrections_pdl2(table: CorrectionTable, tasks: dict[str, TaskLocation]) -> str:
    """A PDL2 listing of the corrected targets."""
    return controller_listing("pdl2", table, tasks)


def export_corrections(
    fmt: str,
    table: CorrectionTable,
    tasks: dict[str, TaskLocation],
    file_stem: str | None = None,
    robot=None,
    joint_map=None,
) -> str:
    """The correction table in ``fmt`` (:data:`EXPORT_FORMATS`); a controller listing is named after the file it
    goes to (``file_stem``, the name without its suffixes), as the controller requires, and with ``robot`` (the cell's
    :class:`~calib_core.robot.model.RobotModel`) carries the tool data the targets are for and the arm's
    configuration at each (``joint_map``: the cell's model joints to controller axes)."""
    tool = None if robot is None else tool_on_flange(robot)
    if fmt == "json":
        return corrections_json(table, tasks, tool)
    if fmt == "csv":
        return corrections_csv(table, tasks, tool)
    return controller_listing(fmt, table, tasks, file_stem, tool, robot, joint_map)


def tool_on_flange(robot) -> np.ndarray:
    """``tcp2flange`` (4, 4) mm: the robot's TCP on its flange (fixed: taken at the neutral joints)."""
    q = np.zeros(robot.n_joints)
    return concat(robot.fk(q, "tcp"), invert(robot.fk(q, "flange")))
