"""Make ``resources/recordings/sample_session.mcap``: a short calibration on the simulated test bed,
recorded in real time (about 9 s) the way the window records one.

The robot drives from home to the task location ``oru_1_grasp`` (where the camera sees the fixture) (joints at 50 Hz, 1280 x 960
H.264 frames at 15 fps), then the operator picks six pairs, solves twice (plain and robust) and
stores a correction, with the camera running throughout. Run from the project root:
``.venv/bin/python scripts/make_sample_recording.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.recording.playback import pair_to_dict
from calib_core.recording.recorder import SessionRecorder
from calib_core.robot import solve_ik
from calib_core.testbed.test_bed import TestBed

OUT = Path(__file__).resolve().parents[1] / "resources" / "recordings" / "sample_session.mcap"
FEATURES = ["plate_top_left", "plate_top_right", "plate_bottom_right", "plate_bottom_left", "pin_tip", "boss_top_left"]
DRIVE_S, PICK_EVERY_S, FPS, JOINT_HZ = 3.0, 0.6, 15.0, 50.0


def main() -> None:
    bed = TestBed.create()
    cell = bed.workcell
    task = cell.task("oru_1_grasp")
    q_home = np.array(cell.home_joints_deg, dtype=float)
    q_task = solve_ik(bed.model_robot, task.tcp2base, q_home).q_deg
    camera = bed.camera(seed=1)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(5)
    session = CalibrationSession()
    session.set_target("oru_1_fixture")
    fx = cell.component("oru_1_fixture")
    with SessionRecorder(OUT, drop_when_busy=False) as rec:
        rec.record_setup(workcell="resources/workcell/workcell.yaml", intrinsics=bed.intrinsics.to_dict(), task=task.name, target="oru_1_fixture")

        def on_pairs(event, number):
            detail = {"number": number}
            if number is not None and event in ("added", "changed"):
                detail.update(pair_to_dict(session.pairs.get(number)))
            rec.record_event(f"pair_{event}", **detail)

        session.pairs.subscribe(on_pairs)
        start = time.monotonic()
        next_frame = next_joint = start
        steps = [("pick", name) for name in FEATURES] + [("solve", False), ("solve", True), ("store", None), ("idle", None)]
        next_step = start + DRIVE_S + 0.5
        seq = 0
        while steps:
            now = time.monotonic()
            s = min(1.0, (now - start) / DRIVE_S)
            bed.joints_deg = q_home + (q_task - q_home) * (3 * s * s - 2 * s * s * s)  # smooth start and stop
            if now >= next_joint:
                rec.record_joints(seq, 1000 + 20 * seq, now, bed.joints_deg)
                seq += 1
                next_joint += 1 / JOINT_HZ
            if now >= next_frame:
                frame = camera.read()
                rec.record_frame(frame.image, frame.t_host_s)
                next_frame += 1 / FPS
            if now >= next_step:
                kind, arg = steps.pop(0)
                q = bed.joints_deg.copy()
                if kind == "pick":
                    p = apply(fx.item2world, fx.features[arg])
                    session.pick_3d("oru_1_fixture", arg, p)
                    session.pick_2d(project(apply(invert(bed.true_cam2world(q)), p[None]), bed.intrinsics)[0] + rng.normal(0, 0.3, 2))
                elif kind == "solve":
                    session.robust = arg
                    est = session.calibrate(bed.intrinsics, fx.item2world, bed.model_cam2world(q), bed.model_robot.fk(q), q)
                    context = {"obj2world": fx.item2world, "cam2world_model": est.cam2world_model, "tcp2base_model": est.tcp2base_model, "joints_deg": q, "target": "oru_1_fixture"}
                    rec.record_solve(session.last_solve_inputs, est.solution.to_dict(), context=context)
                elif kind == "store":
                    c = session.store_correction(task.name)
                    rec.record_correction({"task": c.task, "displacement_mm": c.displacement_mm, "rotation_deg": c.rotation_deg, "std_displacement_mm": c.std_displacement_mm, "std_rotation_deg": c.std_rotation_deg, "joints_deg": c.joints_deg, "rms_px": c.rms_px, "pairs": c.pairs})
                next_step += PICK_EVERY_S
            time.sleep(max(0.0, min(next_frame, next_joint, next_step) - time.monotonic()))
    camera.close()
    print(f"wrote {OUT} ({OUT.stat().st_size // 1024} KiB, {rec.frames_written} frames)")


if __name__ == "__main__":
    main()
