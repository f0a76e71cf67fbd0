"""Grasps from a file: the joints the controller reported with the gripper closed on a task
location's fixture pin, in compliance (the operator does it with the teach pendant; the pin centres
the fingers, so the TCP is where the fixture's survey says).

A CSV with a header row ``task,<joints>``: the task location's name as the workcell spells it, then
one column per joint named as the robot's joints or ``j1..jn`` (deg; mm for a prismatic joint)::

    task,j1,j2,j3,j4,j5,j6
    oru_1_grasp,12.5,-33.0,81.2,0.4,41.8,12.9

An optional ``image`` column after ``task`` names the camera's frame taken while the gripper held the
pin (relative to the file): the grasp is then *seen*
(:mod:`calib_core.robot_calibration.grasp_view`), the tool measured from the held fixture's edges
instead of through the robot and the fixture's survey. The images are read when the tool is measured.

Every mistake is a :class:`~calib_core.errors.FileFormatError` naming the file, the row and the field.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from calib_core.documents import csv_numbers, read_text
from calib_core.errors import FileFormatError
from calib_core.robot_calibration.camera_to_tool import Grasp

MAX_GRASPS = 200


@dataclass(frozen=True)
class GraspRow:
    """One grasp of the file, and the frame taken while it held (``None``: not given)."""

    grasp: Grasp
    image_path: Path | None
    task: str


def load_grasps(path: str | Path, joint_names: list[str], workcell) -> list[GraspRow]:
    """The grasps in ``path`` for a robot with ``joint_names``; each task location's ``tcp2base``
    from ``workcell`` is where its grasp puts the TCP."""
    path = Path(path)
    text = read_text(path, "grasps CSV", 1024 * 1024)
    try:
        rows = [r for r in csv.reader(io.StringIO(text, newline="")) if r and any(c.strip() for c in r)]
    except csv.Error as exc:
        raise FileFormatError(path, f"not a CSV file ({exc})") from None
    if not rows:
        raise FileFormatError(path, "empty: expected a header row task,<joints>")
    header = [c.strip() for c in rows[0]]
    if header[0] != "task":
        raise FileFormatError(path, f"the first column must be 'task', got {header[0]!r}", "header")
    with_images = len(header) > 1 and header[1] == "image"
    columns = header[2:] if with_images else header[1:]
    generic = [f"j{k + 1}" for k in range(len(joint_names))]
    if columns == generic:
        order = list(range(len(columns)))
    elif sorted(columns) == sorted(joint_names) and len(set(columns)) == len(columns):
        order = [columns.index(n) for n in joint_names]
    else:
        raise FileFormatError(
            path,
            f"the joint columns {', '.join(columns) or '(none)'} are not the robot's joints ({', '.join(joint_names)}) "
            f"nor {', '.join(generic)}",
            "header",
        )
    if not 1 <= len(rows) - 1 <= MAX_GRASPS:
        raise FileFormatError(path, f"expected 1 to {MAX_GRASPS} grasps, got {len(rows) - 1}")
    grasps = []
    for n, row in enumerate(rows[1:], start=2):
        where = f"row {n}"
        if len(row) != len(header):
            raise FileFormatError(path, f"{len(row)} values, the header has {len(header)}", where)
        task = row[0].strip()
        if task not in workcell.task_locations:
            raise FileFormatError(
                path,
                f"no task location {task!r} in the workcell; task locations: {', '.join(workcell.task_locations)}",
                f"{where}, task",
            )
        image = row[1].strip() if with_images else ""
        if image and not (path.parent / image).is_file():
            raise FileFormatError(path, f"no such image {path.parent / image}", f"{where}, image")
        q = np.array(csv_numbers(row[2:] if with_images else row[1:], columns, path, where), dtype=float)[order]
        grasps.append(
            GraspRow(
                Grasp(f"{task} (row {n})", q, workcell.task(task).tcp2base),
                path.parent / image if image else None,
                task,
            )
        )
    return grasps
