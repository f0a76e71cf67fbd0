"""The arm as the operator knows it: its controller link, its joints, how its last move stands, and
the moves themselves (previewed, refused or held for a confirmation, sent, followed to the
controller's answer) and Stop.

One model (``core.arm``) with its own events; the overview, the status line and the panes that
follow the joints listen to it. It has no Qt: the link calls back on its reader thread and the arm
hands each call to ``call_soon`` (the window's queues it into the Qt event loop), so its state
changes and events happen on the owner's thread.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from psygnal import Signal

from calib_core.calibration.errors import CalibrationError
from calib_core.connectors.controller import ControllerConnector, ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.link_types import LinkState, MoveHandle, TimedSample
from calib_core.operator.cell import Cell
from calib_core.operator.motion import Motion, MotionState, ended
from calib_core.operator.move_preview import Confirmation, MoveNeedsConfirmation, MovePreview, MoveRefused, preview_move
from calib_core.operator.observations import Observations
from calib_core.robot import solve_ik


class Arm:
    """The robot behind the link.

    Events (psygnal): ``joints_changed(q)`` (model joints, deg/mm; only on a change),
    ``sample_received(sample, q)`` (every joint sample, with its model joints), ``link_state(text)``,
    ``motion_changed(state)`` (a :class:`~calib_core.operator.motion.MotionState`),
    ``move_previewed(preview)`` (a :class:`~calib_core.operator.move_preview.MovePreview`, before every
    move, sent or not), ``move_finished(what, error)`` (``error`` empty when the move arrived),
    ``prompts_withdrawn()`` (a Stop voided every move prompt still waiting), ``message(text)`` (for a
    status line) and ``event(kind, detail)`` (worth recording).

    Its public members are many for a reason: nine events (one for each thing a view shows of the robot), the robot's
    state as the views read it (joints, motion, link, controller clock, last sample, last move sent, stops sent, the
    move waiting for confirmation) and its few actions (connect, close, a sample observed, show joints, preview, move,
    Stop)."""

    joints_changed = Signal(object)
    sample_received = Signal(object, object)
    link_state = Signal(str)
    motion_changed = Signal(object)
    move_previewed = Signal(object)
    move_finished = Signal(str, str)
    prompts_withdrawn = Signal()
    message = Signal(str)
    event = Signal(str, object)

    def __init__(self, cell: Cell, observations: Observations, *, call_soon: Callable[..., None] | None = None):
        self.cell = cell
        self.observations = observations
        """Where the joint samples go (its live history) and whether a recording is being replayed (no moves then)."""
        self._call_soon = call_soon or (lambda fn, *args: fn(*args))
        self.link: ControllerConnector | None = None
        self.joints_deg = cell.home_joints
        """The joints the views show (model joints, deg/mm): the newest sample's, or a replay's."""
        self.state = MotionState()
        self.controller_clock = observations.live_clock
        """Stamps each joint sample with its controller time on the host clock (not its arrival)."""
        self.last_sample_s: float | None = None  # host monotonic s
        self.last_move_sent_s: float | None = None  # host monotonic s: frames from before it show the old pose
        self.stops_sent = 0  # a prompt's confirmation carries the count it saw: a later Stop voids it
        self.pending_move: tuple[str, MoveHandle] | None = None

    @property
    def robot(self):
        return self.cell.robot

    @property
    def link_up(self) -> bool:
        return self.link is not None and self.link.state is LinkState.UP

    # --- the link ---------------------------------------------------------------------------------
    def connect(self, url: str, rate_hz: float = 50.0, options: dict | None = None) -> ControllerConnector:
        """Open the controller connector registered for ``url``'s scheme and listen to it (not started)."""
        self.close()
        context = ControllerContext.of(self.robot, self.cell.joint_map, rate_hz, options)
        link = open_controller(url, context)
        link.sample_received.connect(lambda sample: self._call_soon(self.observe_sample, sample))
        link.state_changed.connect(lambda state, why: self._call_soon(self._on_link_state, state.value, why))
        link.auth_changed.connect(lambda state, failure: self._call_soon(self._on_link_auth, state.value, failure))
        status = getattr(
            link, "status_changed", None
        )  # a controller's own state (a UR's protective stop, speed slider)
        if status is not None:
            status.connect(lambda text: self._call_soon(self._on_link_status, text))
        self.link = link
        return link

    def close(self) -> None:
        if self.link is not None:
            self.link.close()
            self.link = None

    def _on_link_state(self, state: str, why: str) -> None:
        self.event.emit("link_state", {"state": state, "why": why})
        if state in ("down", "closed"):
            # The device is gone: the robot may move unseen, no earlier sample vouches for a later frame.
            # (A stale link, open but late, leaves a gap in the samples: the settle rule sees it.)
            self.observations.live_history.forget(time.monotonic())
            if self.state.motion is Motion.MOVING:
                self._set_state(
                    MotionState(
                        Motion.UNKNOWN,
                        self.state.what,
                        f"the link went {state} during the move to {self.state.what}; waiting for a fresh joint sample",
                    )
                )
        self.link_state.emit(f"{state}: {why}")

    def _on_link_status(self, text: str) -> None:
        self.event.emit("controller_status", {"text": text})
        self.message.emit(f"controller: {text}")
        if self.link is not None:
            self.link_state.emit(f"{self.link.state.value}: {text}")

    def _on_link_auth(self, state: str, failure: str | None) -> None:
        self.event.emit("link_auth", {"state": state, "failure": failure})
        if failure:
            self.message.emit(f"the robot cannot be moved: {failure}")

    # --- joints -----------------------------------------------------------------------------------
    def observe_sample(self, sample: TimedSample) -> None:
        """A joint sample from the link (its reader thread hands it here through ``call_soon``)."""
        self.last_sample_s = time.monotonic()
        joint_map = self.link.joint_map if self.link is not None else self.cell.joint_map
        q = joint_map.to_model(sample.joints_deg)
        restarts = self.controller_clock.restarts
        t_sent = self.controller_clock.stamp(sample.t_host_s, sample.sample.t_ms / 1000.0)
        history = self.observations.live_history
        if self.controller_clock.restarts != restarts:
            history.forget(sample.t_host_s)  # a restarted controller: nothing before vouches for now
        history.add(t_sent, q)
        if self.state.motion is Motion.UNKNOWN:
            pending = self.pending_move
            if pending is not None and not pending[1].finished:
                self._set_state(MotionState(Motion.MOVING, pending[0], "the link is back"))
            else:
                self._set_state(
                    MotionState(Motion.IDLE, self.state.what, "the link is back: the robot stands where its joints say")
                )
        self.sample_received.emit(sample, q)
        if self.observations.replaying:
            return  # the recorded joints drive the views while a recording is replayed
        self.show_joints(q)

    def show_joints(self, q) -> None:
        """The views follow joints ``q`` (deg/mm): a sample's, or a replay's (the robot does not move)."""
        # Emitted only on a change: a still robot streams the same joints 50 times a second, and every
        # pane would redraw (or filter the repeats itself).
        q = np.array(q, dtype=float)
        changed = q.shape != np.shape(self.joints_deg) or not np.array_equal(q, self.joints_deg)
        self.joints_deg = q
        if changed:
            self.joints_changed.emit(self.joints_deg)

    # --- moves ------------------------------------------------------------------------------------
    def _set_state(self, state: MotionState) -> None:
        self.state = state
        self.motion_changed.emit(state)

    def preview(self, q, what: str, allowed_contacts: frozenset[str] = frozenset()) -> MovePreview:
        """The move from the current joints to ``q`` (deg/mm), checked; ``move_previewed`` shows it."""
        preview = preview_move(
            self.robot,
            self.cell.collision_world(),
            self.joints_deg,
            q,
            what,
            self.cell.workcell.safety,
            allowed_contacts,
        )
        self.move_previewed.emit(preview)
        return preview

    def move_to(self, target2base: np.ndarray, what: str, **options) -> MoveHandle:
        """IK for the TCP target (4, 4) mm in base from the current joints, then :meth:`move_joints`."""
        q = solve_ik(self.robot, target2base, self.joints_deg).q_deg
        return self.move_joints(q, what, **options)

    def move_joints(
        self,
        q,
        what: str,
        *,
        wait: bool = False,
        timeout_s: float = 30.0,
        confirmed: bool | Confirmation = False,
        allowed_contacts: frozenset[str] = frozenset(),
    ) -> MoveHandle:
        """Move to model joints ``q`` (deg/mm) over the link; ``move_finished`` tells how it ended.
        The move is previewed first: refused (:class:`MoveRefused`) outside the limits or into a
        collision, and sent only with ``confirmed`` when it turns a joint further than the cell's
        ``confirm_joint_change_deg`` (:class:`MoveNeedsConfirmation`). ``confirmed``: ``True`` (a
        script's), or the prompt's :class:`Confirmation`, void once a Stop was sent after it."""
        if self.observations.replaying:
            raise CalibrationError(
                "a recording is being replayed: the views show it, not the robot; close the replay before moving the "
                "robot"
            )
        if self.link is None:
            raise CalibrationError("no controller link: connect one first")
        robot = self.robot
        q = robot.check_joints(q)
        outside = np.flatnonzero(~robot.within_limits(q))
        if len(outside):
            j = int(outside[0])
            raise CalibrationError(
                f"not moving to {what}: joint {robot.joint_names[j]} target {q[j]:.2f} {robot.joint_units[j]} is "
                "outside its limits "
                f"[{robot.lower_limits_deg[j]:g}, {robot.upper_limits_deg[j]:g}]"
            )
        if self.state.motion is Motion.UNKNOWN:
            raise CalibrationError(
                f"not moving to {what}: the robot's pose is unknown (the link dropped); wait for a fresh joint sample"
            )
        preview = self.preview(q, what, allowed_contacts)
        if preview.blocked:
            raise MoveRefused(preview)
        if preview.needs_confirmation:
            if not confirmed:
                raise MoveNeedsConfirmation(preview, Confirmation(what, self.stops_sent))
            if isinstance(confirmed, Confirmation) and (
                confirmed.stops_seen != self.stops_sent or confirmed.what != what
            ):
                raise CalibrationError(
                    f"not moving to {what}: the robot was stopped after this move was asked for; ask for it again"
                )
            self.event.emit("move_confirmed", {"what": what, "reasons": list(preview.confirm_reasons)})
        handle = self.link.move_joints(self.link.joint_map.to_controller(q), timeout_s=timeout_s)
        if not handle.sent:
            handle.wait(0)  # raises the link's reason
        self.last_move_sent_s = time.monotonic()
        self.message.emit(f"moving to {what}: joints {', '.join(f'{v:.1f}' for v in q)}")
        self._set_state(MotionState(Motion.MOVING, what))
        self.pending_move = (what, handle)
        handle.on_finished(lambda h: self._call_soon(self._move_ended, what, h))
        if wait:
            handle.wait(timeout_s)
        return handle

    def _move_ended(self, what: str, handle: MoveHandle) -> None:
        error = handle.error
        if self.state.motion is Motion.MOVING and self.state.what == what:
            self._set_state(ended(what, error))
        self.event.emit("move_finished", {"what": what, "error": str(error) if error else ""})
        self.move_finished.emit(what, str(error) if error else "")
        self.message.emit(f"move to {what} failed: {error}" if error else f"arrived at {what}")

    def stop(self) -> bool:
        """Stop now: the controller halts the robot where it is; the running move ends with its
        ``STOPPED`` reason. True if the stop went out."""
        # Every prompt still waiting is void, link or not: a Move pressed after Stop must not move the robot.
        self.stops_sent += 1
        self.prompts_withdrawn.emit()
        if self.link is None:
            raise CalibrationError("no controller link: nothing to stop")
        sent = self.link.stop()
        self.event.emit("stop", {"sent": sent, "during": self.state.what if self.state.motion is Motion.MOVING else ""})
        self.message.emit(
            "stop sent to the controller" if sent else f"stop NOT sent: the link is {self.link.state.value}"
        )
        return sent
