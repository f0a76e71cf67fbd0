"""What a controller connector gives the operator core, whichever controller is behind it.

Every connector keeps the guarantees the core relies on: samples in order with the controller's own stamp
(``JointSample.t_ms``), a state that says when samples stop (``stale``/``down``: "pose unknown"), moves that
end exactly once (done, refused, stopped or timed out), a Stop that needs no handshake.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState, MoveHandle, TimedSample  # noqa: F401 (the types a connector speaks)


@dataclass(frozen=True)
class ControllerContext:
    """What the core tells a connector it opens: the robot's driven joints (``joint_names``, URDF order;
    ``joint_units`` ``deg`` or ``mm`` each), the workcell's map to its own controller's axes
    (``cell_joint_map``: order and zero offsets, for a controller that numbers and zeroes its axes its own
    way), the sample rate the core asks for (``rate_hz``) and the connector's options from the workcell's
    ``site:`` section (``options``)."""

    joint_names: tuple[str, ...]
    joint_units: tuple[str, ...]
    cell_joint_map: JointMap
    rate_hz: float = 50.0
    options: dict | None = None

    @property
    def n_joints(self) -> int:
        return len(self.joint_names)

    @classmethod
    def of(cls, robot, joint_map: JointMap, rate_hz: float = 50.0, options: dict | None = None) -> ControllerContext:
        return cls(tuple(robot.joint_names), tuple(robot.joint_units), joint_map, rate_hz, options)


class ControllerConnector(Protocol):
    """A controller connector (registered in ``videocal.controllers`` as ``open(url, context)``).

    Events, psygnal signals emitted on the connector's own thread (the core marshals them):
    ``sample_received(TimedSample)``: a joint sample, its ``joints_deg`` in the connector's axis order (deg,
    mm), its ``t_ms`` the controller's stamp in ms; ``state_changed(LinkState, reason)``;
    ``auth_changed(state, failure)``: where moves need a session, when it is ready or failed (a connector
    without one never emits it).
    """

    url: str
    joint_map: JointMap
    """Model joints (URDF order and zero) to this connector's axes: the cell's map for a controller that
    speaks in its own axes, :meth:`JointMap.identity` for one that takes joints by URDF name."""

    @property
    def state(self) -> LinkState: ...

    def start(self) -> ControllerConnector:
        """Begin connecting (returns at once; the state tells the rest)."""

    def close(self) -> None:
        """Stop a running move, disconnect; safe to call twice, returns within about 1 s."""

    def move_joints(self, joints_deg, *, timeout_s: float = 60.0) -> MoveHandle:
        """Start a joint move to ``joints_deg`` (n,) in the connector's axes (deg, mm); returns at once.
        A move that cannot be sent finishes its handle with the reason and ``sent = False``."""

    def stop(self) -> bool:
        """Stop the robot where it is; True if the request went out."""

    def stats_snapshot(self) -> dict[str, int]:
        """Counters (samples delivered, gaps, errors...) since the start."""

    @property
    def delay_s(self) -> float | None:
        """The link's one-way delay (s) where the connector measures it, else ``None``."""

    def stale_after_now_s(self) -> float:
        """No joint sample for this long marks the link stale by the connector's own rule now (s); 0 for none."""

    publishes_transforms: bool
    """Declared by the connector (False in :class:`~calib_core.connectors.events.ConnectorEvents`): it takes the
    results through ``publish_static_transforms(transforms)``."""
