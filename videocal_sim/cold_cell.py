"""The cold cell: a test bed where nothing the program is given is exact, as on a real site.

- The camera's true intrinsics differ from its file: focal lengths 1-3 % off, the principal point
  5-20 px off, and radial and tangential distortion the file does not have (the file's own
  coefficients are replaced by others of the same kind and size).
- The camera's true mounting differs from the model (0.5-1 mm, 0.05-0.2 deg), and the robot has its
  typical joint offsets, link and base errors (:meth:`RobotErrors.typical`).
- The cell's components stand within 0.1 mm of their surveyed placements (a theodolite survey).

Nothing downstream of the test bed reads these: the calibration is given the workcell file and the
camera file, and the truth only scores (:class:`ColdTruth`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.frames import concat, make_transform
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors
from calib_core.workcell import Workcell, load_workcell

SURVEY_MM = 0.1


@dataclass(frozen=True)
class ColdTruth:
    """What the cold cell really is: ``intrinsics`` of the camera, the robot's ``errors``, and each
    component's ``survey_error_mm`` (3,) (true minus surveyed, base frame)."""

    intrinsics: Intrinsics
    errors: RobotErrors
    survey_error_mm: dict[str, np.ndarray]


def true_intrinsics(nominal: Intrinsics, rng: np.random.Generator) -> Intrinsics:
    """Intrinsics that differ from ``nominal`` the way a real lens differs from its data sheet."""

    def signed(lo, hi):
        return rng.uniform(lo, hi) * rng.choice([-1.0, 1.0])

    scale = 1.0 + signed(0.01, 0.03)
    fu = nominal.fu * scale
    fv = nominal.fv * scale * (1.0 + rng.uniform(-0.002, 0.002))
    cx = nominal.cx + signed(5.0, 20.0)
    cy = nominal.cy + signed(5.0, 20.0)
    k1 = -rng.uniform(0.08, 0.25)
    distortion = (k1, rng.uniform(0.02, 0.1), signed(2e-4, 1e-3), signed(2e-4, 1e-3), 0.0)
    return Intrinsics(fu, fv, cx, cy, nominal.width, nominal.height, distortion)


def cold_test_bed(workcell: Workcell | None = None, seed: int = 0) -> tuple[TestBed, ColdTruth]:
    """The cold cell of ``workcell`` (default: the bundled one) and its truth; ``seed`` draws it."""
    cell = workcell or load_workcell()
    rng = np.random.default_rng(1000 + seed)
    nominal = load_intrinsics(cell.intrinsics_path)
    intrinsics = true_intrinsics(nominal, rng)
    errors = RobotErrors.typical(seed, n_joints=cell.load_robot().n_joints)
    bed = TestBed.create(cell, errors=errors, intrinsics=intrinsics)
    survey: dict[str, np.ndarray] = {}
    moved = []
    for item in cell.components:
        if item.name == "floor":
            moved.append(item)
            continue
        d = rng.uniform(-1.0, 1.0, 3)
        d *= rng.uniform(0.0, SURVEY_MM) / max(np.linalg.norm(d), 1e-9)
        survey[item.name] = d
        moved.append(replace(item, item2world=concat(item.item2world, make_transform(np.eye(3), d))))
    bed.true_components = moved
    return bed, ColdTruth(intrinsics, errors, survey)
