"""Re-solving every calibration of a recording and comparing with what was recorded.

With the same version of videocal the results agree exactly (the solver is deterministic and
JSON round-trips doubles exactly); a newer solver shows here how its answers differ, and one that
reaches the same minimum by another path (differences at round-off, below 1e-6 mm) is ``equivalent``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from calib_core.errors import FileFormatError
from calib_core.recording.reader import read_recording
from calib_core.recording.recorder import to_jsonable
from calib_core.recording.schemas import SOLVE_TOPIC


def solve_from_inputs(inputs: dict):
    prior = None
    if inputs.get("prior"):
        prior = make_transform(inputs["prior"]["R_obj2cam"], inputs["prior"]["t_obj2cam_mm"])
    from calib_core.solver.solve import solve_pose  # the solver's compiled kernels load on first use

    return solve_pose(
        inputs["points_3d"],
        inputs["points_2d"],
        Intrinsics.from_dict(inputs["intrinsics"]),
        prior=prior,
        estimate_focal=inputs.get("estimate_focal", False),
        model=inputs.get("model", "pinhole"),
        sigma_px=inputs.get("sigma_px"),
        robust=inputs.get("robust", False),
    )


@dataclass(frozen=True)
class ReplayedSolve:
    """One recorded solve re-computed: ``agree`` when status and pose match exactly; ``equivalent``
    when they match to round-off (translation within 1e-6 mm, rotation matrix entries within 1e-9,
    RMS within 1e-6 px); ``translation_diff_mm`` and ``rms_diff_px`` the largest differences."""

    id: int
    recorded: dict
    recomputed: dict
    agree: bool
    translation_diff_mm: float
    rotation_diff: float
    rms_diff_px: float
    skipped: str | None = None
    """Why this solve was not re-computed (one made on the image's edges needs the frame and the renderer)."""

    @property
    def equivalent(self) -> bool:
        return (
            self.agree
            or self.skipped is not None
            or (
                self.recorded["status"] == self.recomputed["status"]
                and self.translation_diff_mm <= 1e-6
                and self.rotation_diff <= 1e-9
                and self.rms_diff_px <= 1e-6
            )
        )


def _diff(a, b) -> float:
    """Largest difference; JSON keeps a non-finite number as null: two missing values agree."""
    a, b = np.atleast_1d(np.array(a, dtype=float)), np.atleast_1d(np.array(b, dtype=float))
    if a.shape != b.shape:
        return float("inf")
    d = np.abs(a - b)
    d[np.isnan(a) & np.isnan(b)] = 0.0
    return float(np.max(np.where(np.isnan(d), np.inf, d))) if a.size else 0.0


def replay(path: str | Path) -> list[ReplayedSolve]:
    contents = read_recording(path)
    out = []
    for k, message in enumerate(contents.topic(SOLVE_TOPIC)):
        payload = message.payload
        number = payload.get("id", k + 1) if isinstance(payload, dict) else k + 1
        recorded = payload.get("result") if isinstance(payload, dict) else None
        if not isinstance(recorded, dict) or not all(
            key in recorded for key in ("status", "t_obj2cam_mm", "R_obj2cam", "rms_px")
        ):
            raise FileFormatError(
                path, f"solve {number} has no complete result (status, R_obj2cam, t_obj2cam_mm, rms_px)", SOLVE_TOPIC
            )
        inputs = payload.get("inputs")
        if isinstance(inputs, dict) and inputs.get("method") == "edges":
            out.append(
                ReplayedSolve(
                    int(number),
                    recorded,
                    recorded,
                    False,
                    0.0,
                    0.0,
                    0.0,
                    skipped="solved on the image's edges: not re-computed from a recording",
                )
            )
            continue
        try:
            recomputed = to_jsonable(solve_from_inputs(payload["inputs"]).to_dict())  # as it would be recorded
        except (KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(
                path, f"solve {number}: its inputs cannot be solved again ({type(exc).__name__}: {exc})", SOLVE_TOPIC
            ) from None
        dt = _diff(recorded["t_obj2cam_mm"], recomputed["t_obj2cam_mm"])
        dr = _diff(recorded["R_obj2cam"], recomputed["R_obj2cam"])
        drms = _diff(recorded["rms_px"], recomputed["rms_px"])
        agree = recorded["status"] == recomputed["status"] and dt == 0.0 and dr == 0.0 and drms == 0.0
        out.append(ReplayedSolve(int(message.payload["id"]), recorded, recomputed, agree, dt, dr, drms))
    return out
