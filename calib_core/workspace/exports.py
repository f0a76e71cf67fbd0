"""Exports of the correction table: JSON, CSV, and a PDL2-style listing of the corrected
positions for the robot controller."""

from __future__ import annotations

import csv
import io
import json
import time

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.calibration.corrections import CorrectionTable
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.workspace import _correction_dict

CSV_COLUMNS = ("task", "time_s", "dx_mm", "dy_mm", "dz_mm", "rx_deg", "ry_deg", "rz_deg", "sd_dx_mm", "sd_dy_mm", "sd_dz_mm", "sd_rx_deg", "sd_ry_deg", "sd_rz_deg", "rms_px", "pairs", "source")


def corrections_json(table: CorrectionTable) -> str:
    return json.dumps({"corrections": [_correction_dict(c) for t in table.tasks() for c in table.history(t)]}, indent=1)


def corrections_csv(table: CorrectionTable) -> str:
    """Every stored correction (history included), one row each, mm and degrees."""
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(CSV_COLUMNS)
    for task in table.tasks():
        for c in table.history(task):
            w.writerow([c.task, f"{c.time_s:.3f}", *(f"{v:.4f}" for v in c.displacement_mm), *(f"{v:.5f}" for v in c.rotation_deg), *(f"{v:.4f}" for v in c.std_displacement_mm), *(f"{v:.5f}" for v in c.std_rotation_deg), f"{c.rms_px:.3f}", c.pairs, c.source])
    return out.getvalue()


def corrections_pdl2(table: CorrectionTable, tasks: dict[str, TaskLocation]) -> str:
    """A PDL2-style listing: for each corrected task, ``POS(x, y, z, e1, e2, e3, '')`` of the target to
    command (mm; Euler angles ZYZ in degrees, COMAU's convention), with the measured displacement."""
    lines = [f"-- videocal corrected task locations, {time.strftime('%Y-%m-%d %H:%M:%S')}", "-- POS(x, y, z, e1, e2, e3, cnfg): mm, Euler ZYZ deg; the target to command so the real tool reaches the planned location", "VAR"]
    body = []
    for name in table.tasks():
        if name not in tasks:
            continue
        c = table.latest(name)
        target = table.corrected_target(name, tasks[name].tcp2base)
        e = Rotation.from_matrix(target[:3, :3]).as_euler("ZYZ", degrees=True)
        var = "".join(ch if ch.isalnum() else "_" for ch in name)[:24] + "_c"
        lines.append(f"  {var} : POSITION  -- displacement {np.linalg.norm(c.displacement_mm):.2f} mm, {np.linalg.norm(c.rotation_deg):.3f} deg; rms {c.rms_px:.2f} px, {c.pairs} pairs")
        x, y, z = target[:3, 3]
        body.append(f"  {var} := POS({x:.3f}, {y:.3f}, {z:.3f}, {e[0]:.4f}, {e[1]:.4f}, {e[2]:.4f}, '')")
    return "\n".join(lines + ["BEGIN"] + body + ["END", ""])
