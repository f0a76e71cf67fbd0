"""``videocal demo``: drive the real window through a whole calibration at a task location of any cell
(by default the bundled cell and the paper's task location).

The simulated operator clicks the panes' widgets like a person would. At the task location it presses
Find points (F6), Accept all and Calibrate (``method="find-points"``, the default), or Calibrate on
edges (``"edges"``), or picks each feature by hand (``"picks"``): in the virtual camera, then the same
feature in the zoomed camera image (sub-pixel refinement on corners, clicked again without it when the
refined cross-hair leaves the corner), accepts and calibrates; where the features are in the camera
image the hand learns from the test bed's truth, as a person learns it by looking. Either way it stores
the correction, moves to the corrected location, looks again the same way, stores the refined
correction and moves there.
A PNG of the window is written after each step, ``report.json`` with the figures and ``workspace.json`` with the
pairs and the corrections (for ``videocal export``).
"""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QEventLoop, QPointF, QSettings, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication

from calib_core.calibration.commands import DeletePair
from calib_core.errors import OperatorError, VideocalError
from calib_core.atomic_file import atomic_write_text
from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference
from videocal_sim.demo_report import OperatorLog, demo_report
from videocal_sim.demo_site import demo_site
from calib_core.workcell import DEFAULT_WORKCELL

_MIN_FEATURES = 4
_REFINE_TRUST_PX = 0.35
_HAND_PX = 0.3  # how close to a corner the operator's own click lands, zoomed in (image px)
_EDGE_MARGIN_PX = 12.0


def _is_corner(name: str) -> bool:
    """Features the demo's operator refines to sub-pixel (cornerSubPix): sharp corners by name."""
    return name.startswith("plate") or "corner" in name


def _visible_features(component, cam2world: np.ndarray, intrinsics) -> list[str]:
    """Features of ``component`` in front of the camera and inside the image (by their projection)."""
    names = []
    for name, point in component.features.items():
        p_cam = apply(invert(cam2world), apply(component.item2world, point)[None])
        if p_cam[0, 2] <= 1.0:
            continue
        u, v = project(p_cam, intrinsics)[0]
        if (
            _EDGE_MARGIN_PX <= u <= intrinsics.width - 1 - _EDGE_MARGIN_PX
            and _EDGE_MARGIN_PX <= v <= intrinsics.height - 1 - _EDGE_MARGIN_PX
        ):
            names.append(name)
    return names


class DemoTimeoutError(VideocalError, TimeoutError):
    """The scripted operator waited too long for something: one ``error:`` line naming it, not a traceback."""


class DemoStoppedError(VideocalError):
    """The scripted operator cannot go on (the window refused a move, a look does not count, too few features in
    view): one ``error:`` line saying what the window said, not a traceback."""


def _plain(text: str) -> str:
    """A status line's words without its markup (the window colours it)."""
    return re.sub(r"<[^>]+>", "", text).strip()


def _wait(app: QApplication, condition, timeout_s: float, what: str, state=None) -> None:
    """Process events until ``condition()``; after ``timeout_s`` a :class:`DemoTimeoutError` naming ``what`` and,
    when given, ``state()`` (what the window and the robot say then)."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise DemoTimeoutError(
                f"demo: waited {timeout_s:g} s for {what}" + (f" ({state()})" if state is not None else "")
            )
        app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 20)
        time.sleep(0.01)


def _pause(app: QApplication, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        app.processEvents(QEventLoop.ProcessEventsFlag.AllEvents, 20)
        time.sleep(0.01)


_operator_actions = [0]
"""The operator's actions so far (a click, a key, a zoom, a box ticked): what a look asks of a person, counted."""


def _act(n: int = 1) -> None:
    _operator_actions[0] += n


def _click(widget, x: float, y: float, button=Qt.MouseButton.LeftButton) -> None:
    _act()
    pos = QPointF(round(x), round(y))
    for kind in (QMouseEvent.Type.MouseButtonPress, QMouseEvent.Type.MouseButtonRelease):
        event = QMouseEvent(
            kind,
            pos,
            widget.mapToGlobal(pos),
            button,
            button if kind == QMouseEvent.Type.MouseButtonPress else Qt.MouseButton.NoButton,
            Qt.KeyboardModifier.NoModifier,
        )
        QApplication.sendEvent(widget, event)


def _click_image(view, u: float, v: float, zoom: float | None = None) -> None:
    if zoom is not None:
        _act()  # the wheel, zooming in on the feature
        view.set_zoom(zoom, QPointF(u, v))
    _click(view, *view.image_to_widget(u, v))


METHODS = ("find-points", "picks", "edges")


def run_demo(
    out_dir: Path,
    *,
    scale: float = 1.0,
    workcell: Path = DEFAULT_WORKCELL,
    location: str | None = None,
    method: str = "find-points",
    site_kind: str = "sim",
    link_delay_ms: float = 0.0,
    look: str = "plain",
) -> dict:
    from app.gui.main_window import MainWindow
    from app.gui.warm_up import warm_up_in_background
    from app.gui.workbench import Workbench

    out_dir.mkdir(parents=True, exist_ok=True)
    app = QApplication.instance() or QApplication([])
    cell, site = demo_site(workcell, scale=scale, site_kind=site_kind, link_delay_ms=link_delay_ms, look=look)
    bed = site.bed  # the truth: read by the simulated operator's eyes and by the score only
    wb = Workbench(cell, site)
    if location is not None:
        wb.set_task(location)
    if wb.task is None or wb.task.component is None:
        wb.close()
        raise ValueError(
            f"{workcell}: the demo needs a task location with a component to look at (task_locations[].component)"
        )
    wb.start_controller()
    settings = QSettings(str(out_dir / "settings.ini"), QSettings.Format.IniFormat)
    settings.setValue("files/autosave_dir", str(out_dir))  # the demo's session stays in its folder
    settings.setValue("window/ask_unsaved", False)  # a scripted run: its workspace is saved, nobody answers questions
    win = MainWindow(wb, settings=settings)
    win.resize(1600, 1000)
    win.start_camera(site.camera_factory())
    win.show()
    warm_up_in_background(wb.intrinsics)  # as videocal gui does
    log = OperatorLog()
    shooting_s = [0.0]  # time spent on screenshots, left out of the looks' times

    def shot(name: str, widget=None) -> None:
        """The window (or ``widget``: a dialog of its own) as the operator sees it now, saved as a PNG."""
        t0 = time.monotonic()
        _pause(app, 0.3)
        path = out_dir / f"{len(log.shots) + 1:02d}_{name}.png"
        (widget or win).grab().save(str(path))
        log.shots.append(path.name)
        shooting_s[0] += time.monotonic() - t0

    moves_seen: list[str] = []
    last_go = [time.monotonic()]
    wb.arm.motion_changed.connect(lambda state: moves_seen.append(f"{time.monotonic():.2f} {state.text}"))
    hand = np.random.default_rng(0)
    try:
        # (60 s: a loaded machine starts the simulator, the camera's process and the link slowly)
        def handshake_done() -> bool:
            # samples flow while the handshake is under way; a move waits for it, and on a loaded machine the
            # demo's first move once waited past its budget: the demo starts once the link takes moves
            state = getattr(wb.arm.link, "auth_state", None)
            return state is None or getattr(state, "value", state) in ("ready", "off")

        _wait(
            app,
            lambda: wb.link_up and handshake_done() and win.camera.last_frame is not None,
            60,
            "the controller link and the camera",
            lambda: (
                f"link {'up' if wb.link_up else 'not up'}"
                f"{'' if handshake_done() else ', its handshake under way'}; camera "
                f"{'sending' if win.camera.last_frame is not None else 'no frame yet'}; "
                f"status: {win.results.status.text()!r}"
            ),
        )
        shot("start")
        task = wb.task

        def at(target) -> bool:
            return np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), target)[0]) < 0.01

        def where(target):
            """What a move's timeout reports: the motion's state, the distance left, the status line."""
            return lambda: (
                f"motion {wb.motion.motion.value}, "
                f"{np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), target)[0]):.3f} mm from the target; "
                f"status: {win.results.status.text()!r}"
            )

        def settle(what: str) -> None:
            # a frame the core accepts for picks (the robot settled before it, its own rule), captured after the
            # robot arrived: the scripted operator clicks where the features are now, not on an older still
            since = time.monotonic()

            def usable() -> bool:
                # the frame a click would hold: the newest whose joint samples have arrived (a far link's lag behind)
                frame = wb.observations.newest_usable()
                return frame is not None and frame.t_host_s >= since and wb.observations.stillness(frame).settled

            _wait(app, usable, 60, f"a camera frame with the robot settled {what}")
            log.go_to_settled_s.append(time.monotonic() - last_go[0])
            _wait(app, win.virtual.is_current, 10, "the virtual camera")

        def go(button) -> None:
            """A move button; the operator looks at the ghost in the overview and presses Move when asked."""
            last_go[0] = time.monotonic()
            _click(button, 10, 10)
            if win.overview.preview_bar.isVisible() and win.overview.move_button.isVisible():
                log.confirmed.append(win.overview.preview.what)
                _click(win.overview.move_button, 10, 10)
            if wb.motion.motion.value not in ("moving", "arrived"):
                raise DemoStoppedError(f"demo: the move was not sent: {_plain(win.results.status.text())}")

        def store() -> None:
            """Store correction, checked: one more entry in the task location's history."""
            stored_before = len(wb.session.corrections.history(task.name))
            place = wb.desk.look_place()
            if place is None or not place.counts:  # the window would ask; the demo's looks are made where they count
                raise DemoStoppedError(
                    f"demo: the look does not count for {task.name}: {place.text if place else 'no robot pose'}"
                )
            _click(win.commands.store, 10, 10)
            if len(wb.session.corrections.history(task.name)) != stored_before + 1:
                raise DemoStoppedError(
                    f"demo: Store correction stored nothing ({_plain(win.results.verdict.text())}; "
                    f"{_plain(win.results.status.text())})"
                )
            _act()
            win.camera.freeze.setChecked(False)

        def find_and_calibrate(round_name: str) -> None:
            """One calibration with Find points (F6): Accept all and Calibrate, or Calibrate on edges."""
            _act()
            win.camera.freeze.setChecked(True)
            if len(wb.session.pairs):
                _click(win.commands.clear, 10, 10)
            clicked = time.monotonic()
            _click(win.commands.find_points, 10, 10)  # Find points runs in the click: its dialog is up when it returns
            log.proposals_s.append(time.monotonic() - clicked)
            if (
                win.finder.dialog is None or not win.finder.dialog.isVisible()
            ):  # Find points runs in the click: it showed why not
                raise OperatorError(
                    f"demo ({round_name} look): Find points proposed nothing: "
                    f"{win.statusBar().currentMessage() or win.results.status.text()}"
                )
            dialog = win.finder.dialog
            shot(f"{round_name}_points_found")
            shot(f"{round_name}_points_found_list", dialog)  # the proposals and what was missed, with the reasons
            if method == "edges":
                if not dialog.edges_button.isEnabled():
                    raise OperatorError(
                        f"demo ({round_name} look): Find points found no settled edge fit: "
                        f"{dialog.found.result.message}"
                    )
                _click(dialog.edges_button, 10, 10)
            else:
                if not dialog.accept_button.isEnabled():
                    raise OperatorError(
                        f"demo ({round_name} look): Find points found nothing to accept: {dialog.found.result.message}"
                    )
                _click(dialog.accept_button, 10, 10)
                _click(win.commands.calibrate, 10, 10)
            _wait(app, lambda: wb.session.result.estimate is not None, 30, "the solve")
            shot(f"{round_name}_calibrated")
            store()

        def pick_and_calibrate(round_name: str) -> None:
            """One calibration where the robot stands (timed, screenshots left out)."""
            t0, shooting0, acted0 = time.monotonic(), shooting_s[0], _operator_actions[0]
            if method != "picks":
                find_and_calibrate(round_name)
            else:
                pick_each_and_calibrate(round_name)
            log.look_s.append(time.monotonic() - t0 - (shooting_s[0] - shooting0))
            log.look_actions.append(_operator_actions[0] - acted0)

        def pick_each_and_calibrate(round_name: str) -> None:
            """Every feature picked in both panes (scripted clicks), solved, stored."""
            _act()
            win.camera.freeze.setChecked(True)
            if len(wb.session.pairs):
                _click(win.commands.clear, 10, 10)
            fixture = wb.workcell.component(wb.session.target)
            model_cam, true_cam = wb.model_cam2world(), bed.true_cam2world(wb.joints_deg)
            names = [
                n
                for n in _visible_features(fixture, model_cam, wb.intrinsics)
                if n in _visible_features(fixture, true_cam, wb.intrinsics)
            ]
            picked = []
            for name in names:
                p_world = apply(fixture.item2world, fixture.features[name])
                uv_model = project(apply(invert(model_cam), p_world[None]), win.virtual.intrinsics, distort=False)[0]
                _click_image(win.virtual.view, *uv_model)
                pending = wb.session.pairs.pending()
                if pending is None or pending.feature != name:
                    if pending is not None:
                        wb.session.undo.push(DeletePair(wb.session.pairs, pending.number))
                    log.skipped.append(
                        f"{round_name}: {name} ({win.virtual.info.text() or 'hidden in the virtual camera'})"
                    )
                    continue
                picked.append(name)
                uv_true = project(apply(invert(true_cam), p_world[None]), wb.intrinsics)[0]
                if win.camera.subpixel.isChecked() != _is_corner(name):
                    _act()
                win.camera.subpixel.setChecked(_is_corner(name))
                _click_image(win.camera.view, *uv_true, zoom=8.0)
                refined = wb.session.pairs.get(pending.number).pixel
                if refined is None:
                    h = wb.observations.live_history
                    tail = [
                        (round(t - h.latest_s, 3), np.round(q, 3).tolist()) for t, q in list(zip(h._t, h._q))[-40::4]
                    ]
                    frame = win.camera.last_frame_received
                    raise DemoStoppedError(
                        f"demo: the click on {name} in the camera image picked nothing: "
                        f"{_plain(win.results.status.text())}; "
                        f"{wb.motion.text}; "
                        f"frame {frame.index} at {frame.t_host_s - h.latest_s:.3f} s; samples {tail}; events "
                        f"{moves_seen}"
                    )
                if np.hypot(*(np.asarray(refined) - uv_true)) > _REFINE_TRUST_PX:
                    # The operator sees the refined cross-hair leave the corner (a junction of faces the
                    # refinement takes for another corner): clicks it again, refinement off.
                    _act()
                    win.camera.subpixel.setChecked(False)
                    _click_image(win.camera.view, *(uv_true + hand.uniform(-_HAND_PX, _HAND_PX, 2)))
                    log.refined_away.append(f"{round_name}: {name}")
                _act(2)  # the view reset and the pair accepted (two keys)
                win.camera.view.reset_view()
                win.actions.accept()
                app.processEvents()
            if len(picked) < _MIN_FEATURES:
                raise DemoStoppedError(
                    f"demo: the camera sees {len(picked)} features of {fixture.name} from {task.name} "
                    f"({', '.join(picked) or 'none'}); a calibration needs {_MIN_FEATURES}"
                )
            shot(f"{round_name}_pairs_picked")
            _click(win.commands.calibrate, 10, 10)
            _wait(app, lambda: wb.session.result.estimate is not None, 30, "the solve")
            shot(f"{round_name}_calibrated")
            store()

        # As in the paper, the camera looks at the object from the task location itself: the correction is
        # measured where it is used. Moving by the correction changes the robot's error a little (its joints
        # change), so a second look from the corrected location refines it.
        go(win.commands.go_task)
        _wait(app, lambda: at(task.tcp2base), 60, "the robot at the task location", where(task.tcp2base))
        settle("at the task location")
        shot("at_task")
        q_first = wb.joints_deg.copy()
        pick_and_calibrate("first")
        first = wb.session.result.estimate
        go(win.commands.go_corrected)
        once = wb.session.corrections.corrected_target(task.name, task.tcp2base)
        _wait(app, lambda: at(once), 60, "the robot at the corrected task location", where(once))
        settle("at the corrected task location")
        q_measured = wb.joints_deg.copy()
        pick_and_calibrate("second")
        go(win.commands.go_corrected)
        corrected = wb.session.corrections.corrected_target(task.name, task.tcp2base)
        _wait(app, lambda: at(corrected), 60, "the robot at the twice-corrected task location", where(corrected))
        shot("at_corrected_task")
        report = demo_report(
            workcell=workcell,
            method=method,
            look=look,
            site_kind=site_kind,
            link_delay_ms=link_delay_ms,
            wb=wb,
            bed=bed,
            log=log,
            first=first,
            q_first=q_first,
            q_measured=q_measured,
        )
        wb.files.save_workspace(out_dir / "workspace.json")  # the corrections, for videocal export
        report["workspace"] = "workspace.json"
        atomic_write_text(out_dir / "report.json", json.dumps(report, indent=2))
        return report
    finally:
        win.close()
