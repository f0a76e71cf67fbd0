"""The recorder as one subscriber: it taps the operator core's events, and nothing else in the
program calls the recorder. What it keeps: the setup (cell, intrinsics, target, task), every
camera frame, every joint sample, every pair edit, every solve with what it was solved from,
every stored correction, link states, moves and operator events.
"""

from __future__ import annotations

from calib_core.calibration.correspondences import pair_to_dict


class RecordingTap:
    """Connects ``recorder`` (a :class:`~calib_core.recording.recorder.SessionRecorder`) to ``core``
    (an :class:`~calib_core.operator.core.OperatorCore`) until :meth:`detach`."""

    def __init__(self, core, recorder):
        self.core = core
        self.recorder = recorder
        core.recorder = recorder
        recorder.record_setup(
            workcell=str(core.workcell.path), cell=core.cell.identity.to_dict(), intrinsics=core.intrinsics.to_dict(),
            target=core.session.target, task=None if core.task is None else core.task.name, joint_names=core.robot.joint_names,
        )
        self._connections = [
            (core.frame_observed, self._frame),
            (core.sample_received, self._sample),
            (core.event, self._event),
            (core.solved, self._solved),
            (core.correction_stored, self._correction),
            (core.session.pairs.changed, self._pairs),
        ]
        for signal, slot in self._connections:
            signal.connect(slot)

    def detach(self) -> None:
        for signal, slot in self._connections:
            signal.disconnect(slot)
        self.core.recorder = None

    def _frame(self, frame) -> None:
        self.recorder.record_frame(frame.image, frame.t_host_s)

    def _sample(self, sample, q_model) -> None:
        self.recorder.record_joints(sample.sample.seq, sample.sample.t_ms, sample.t_host_s, q_model)

    def _event(self, kind: str, detail: dict) -> None:
        self.recorder.record_event(kind, **detail)

    def _solved(self) -> None:
        core, result = self.core, self.core.session.result
        context = {
            "obj2world": core.workcell.component(core.session.target).item2world, "cam2world_model": result.cam2world_model,
            "tcp2base_model": result.tcp2base_model, "joints_deg": core.joints_deg, "target": core.session.target,
        }
        self.recorder.record_solve(core.session.last_solve_inputs, result.solution.to_dict(), context=context)

    def _correction(self, c) -> None:
        self.recorder.record_correction({
            "task": c.task, "displacement_mm": c.displacement_mm, "rotation_deg": c.rotation_deg, "std_displacement_mm": c.std_displacement_mm,
            "std_rotation_deg": c.std_rotation_deg, "joints_deg": c.joints_deg, "rms_px": c.rms_px, "pairs": c.pairs,
        })

    def _pairs(self, event: str, number) -> None:
        pairs = self.core.session.pairs
        detail = {"number": number}
        if number is not None and event in ("added", "changed"):
            detail.update(pair_to_dict(pairs.get(number)))
        elif event == "reset":  # a whole new set (clear, undo of a clear, a workspace): keep it all
            detail["pairs"] = [pair_to_dict(p) for p in pairs]
        self.recorder.record_event(f"pair_{event}", **detail)
