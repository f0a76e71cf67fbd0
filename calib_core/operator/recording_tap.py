"""The recorder as one subscriber: it taps the operator core's events, and nothing else in the
program calls the recorder. What it keeps: the setup (cell, intrinsics, target, task), every
camera frame, every joint sample, every pair edit, every solve with what it was solved from,
every stored correction, link states, moves and operator events.

For Foxglove's panels it adds, in Foxglove's schemas: the camera's calibration, the robot's frame
tree at every joint sample (through the model robot: these are modelled poses, not measured
ones), the picks and the solve's reprojections on the image, the cell and the robot's meshes in
3D (locked to their frames), and the resolved robot description as an attachment.
"""

from __future__ import annotations

import numpy as np

from calib_core.calibration.correspondences import pair_to_dict
from calib_core.calibration.view_stamp import SAME_STATE_DEG
from calib_core.frames import concat, invert
from calib_core.recording import foxglove_messages as fm
from calib_core.recording.schemas import (
    ANNOTATIONS_TOPIC,
    CALIBRATION_TOPIC,
    FOUND_TOPIC,
    SCENE_TOPIC,
    TRANSFORMS_TOPIC,
)


TF_CHANGE_DEG = 1e-3
TF_REPEAT_S = 1.0


class RecordingTap:
    """Connects ``recorder`` (a :class:`~calib_core.recording.recorder.SessionRecorder`) to ``core``
    (an :class:`~calib_core.operator.core.OperatorCore`) until :meth:`detach`."""

    def __init__(self, core, recorder):
        self.core = core
        self.recorder = recorder
        self.camera_frame = core.robot.roles.get("camera", "camera")
        recorder.camera_frame = self.camera_frame
        recorder.record_setup(
            workcell=str(core.workcell.path),
            cell=core.cell.identity.to_dict(),
            intrinsics=core.intrinsics.to_dict(),
            target=core.session.target,
            task=None if core.task is None else core.task.name,
            joint_names=core.robot.joint_names,
        )
        self._last_frame_s: float | None = None
        self._tf_sent: tuple[float, np.ndarray] | None = None
        self._reprojected: list | None = None
        self._record_static()
        self._connections = [
            (core.observations.frame_observed, self._frame),
            (core.arm.sample_received, self._sample),
            (core.log.event, self._event),
            (core.solved, self._solved),
            (core.desk.correction_stored, self._correction),
            (core.session.pairs.changed, self._pairs),
            (core.finder.points_found, self._found),
        ]
        for signal, slot in self._connections:
            signal.connect(slot)

    def detach(self) -> None:
        for signal, slot in self._connections:
            signal.disconnect(slot)

    # --- once, at the start ----------------------------------------------------------------------
    def _record_static(self) -> None:
        core, rec = self.core, self.recorder
        t_ns = rec.unix_ns()
        rec.record_message(CALIBRATION_TOPIC, fm.camera_calibration(core.intrinsics, self.camera_frame, t_ns))
        rec.record_message(TRANSFORMS_TOPIC, fm.frame_transforms(core.robot.frame_tree(core.joints_deg), t_ns))
        rec.record_message(SCENE_TOPIC, fm.scene_update(self._entities(t_ns)))
        if core.robot.urdf_xml:
            rec.record_attachment("robot.urdf", "application/xml", core.robot.urdf_xml.encode())

    def _entities(self, t_ns: int) -> list:
        """The robot's visuals locked to their links (posed by /tf), the cell's components and the
        target's features in the world."""
        core = self.core
        visuals = core.cell.model_visuals()
        q = core.joints_deg
        links = core.robot.all_frames(q)
        entities = []
        for g, mesh, visual2base in zip(visuals.geometry_model.geometryObjects, visuals.meshes, visuals.poses(q)):
            link = core.robot.model.frames[g.parentFrame].name
            color = tuple(float(c) for c in np.asarray(g.meshColor)[:3])
            entities.append(
                fm.mesh_entity(f"robot/{g.name}", link, mesh, concat(visual2base, invert(links[link])), color, t_ns)
            )
        for item in core.workcell.components:
            entities.append(
                fm.mesh_entity(f"cell/{item.name}", fm.WORLD_FRAME, item.mesh, item.item2world, item.color, t_ns)
            )
            if item.features:
                points = {name: (item.item2world @ np.append(p, 1.0))[:3] for name, p in item.features.items()}
                entities.append(fm.feature_entity(f"features/{item.name}", points, t_ns))
        return entities

    # --- as the session runs ---------------------------------------------------------------------
    def _frame(self, frame) -> None:
        self._last_frame_s = frame.t_host_s
        self.recorder.record_frame(frame.image, frame.t_host_s)

    def _sample(self, sample, q_model) -> None:
        rec = self.recorder
        rec.record_joints(sample.sample.seq, sample.sample.t_ms, sample.t_host_s, q_model)
        q = np.asarray(q_model, float)
        last = self._tf_sent
        # /tf when the robot moved, and once a second while it stands (Foxglove keeps the last
        # transform; the repeat is what a seek finds): most of a calibration the robot is still.
        if last is None or np.max(np.abs(q - last[1])) > TF_CHANGE_DEG or sample.t_host_s - last[0] >= TF_REPEAT_S:
            self._tf_sent = (sample.t_host_s, q)
            rec.record_message(
                TRANSFORMS_TOPIC,
                fm.frame_transforms(self.core.robot.frame_tree(q), rec.unix_ns(sample.t_host_s)),
                sample.t_host_s,
            )

    def _event(self, kind: str, detail: dict) -> None:
        self.recorder.record_event(kind, **detail)

    def _solved(self) -> None:
        core, result = self.core, self.core.session.result.estimate
        context = {
            "obj2world": core.workcell.component(core.session.target).item2world,
            "cam2world_model": result.cam2world_model,
            "tcp2base_model": result.tcp2base_model,
            "joints_deg": core.joints_deg,
            "target": core.session.target,
        }
        inputs = core.session.result.inputs
        self.recorder.record_solve(inputs, result.solution.to_dict(), context=context)
        if result.solution.method == "edges":  # no pairs to draw reprojections of
            self._reprojected = None
        else:
            numbers = list(core.session.pairs.arrays()[2])
            reprojected = np.asarray(inputs["points_2d"], float) - result.solution.residuals_px
            self._reprojected = list(zip(numbers, reprojected.tolist())) if len(numbers) == len(reprojected) else None
        self._annotate()

    def _correction(self, c) -> None:
        self.recorder.record_correction(
            {
                "task": c.task,
                "displacement_mm": c.displacement_mm,
                "rotation_deg": c.rotation_deg,
                "std_displacement_mm": c.std_displacement_mm,
                "std_rotation_deg": c.std_rotation_deg,
                "joints_deg": c.joints_deg,
                "rms_px": c.rms_px,
                "pairs": c.pairs,
                "verdict": c.verdict,
                "confirmation": c.confirmation,
                "time_s": c.time_s,
            }
        )

    def _pairs(self, event: str, number) -> None:
        pairs = self.core.session.pairs
        detail = {"number": number}
        if number is not None and event in ("added", "changed"):
            detail.update(pair_to_dict(pairs.get(number)))
        elif event == "reset":  # a whole new set (clear, undo of a clear, a workspace): keep it all
            detail["pairs"] = [pair_to_dict(p) for p in pairs]
        self.recorder.record_event(f"pair_{event}", **detail)
        self._reprojected = None  # the last solve's reprojections no longer match the pairs
        self._annotate()

    def _found(self, found) -> None:
        """Find points' proposals and its edge fit's edge points, on the frame they were found on."""
        if found is None:
            return  # the proposals withdrawn from the view: the recording keeps them
        t_ns = self.recorder.unix_ns(found.view.t_capture_s)
        edges = found.result.edges.edges_px if found.result.edges is not None and found.result.edges.settled else None
        self.recorder.record_message(
            FOUND_TOPIC,
            fm.found_points_annotations([(p.feature, p.uv_px) for p in found.result.proposals], t_ns, edges),
        )

    def _annotate(self) -> None:
        """The picks (numbered as in the window's table) and the last solve's reprojections, on the
        image they were picked on: stamped with that frame's capture time."""
        core, rec = self.core, self.recorder
        picks = [(p.number, p.pixel) for p in core.session.pairs if p.pixel is not None]
        views = [p.view for p in core.session.pairs if p.pixel is not None and p.view is not None]
        q = np.asarray(core.joints_deg, float)
        stale = [
            p.number
            for p in core.session.pairs
            if p.pixel is not None
            and p.view is not None
            and np.max(np.abs(np.asarray(p.view.joints_deg) - q)) > SAME_STATE_DEG
        ]
        t_s = max((v.t_capture_s for v in views), default=self._last_frame_s)
        t_ns = rec.unix_ns(t_s)
        rec.record_message(ANNOTATIONS_TOPIC, fm.image_annotations(picks, t_ns, self._reprojected, stale))
