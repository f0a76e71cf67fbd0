"""videocal's own protocol as a controller connector (``serial``, ``socket``, ``rfc2217``, ``loop``)."""

from __future__ import annotations

from calib_core.connectors.controller import ControllerContext
from calib_core.link.driver import ControllerLink


def open_link(url: str, context: ControllerContext) -> ControllerLink:
    """A :class:`ControllerLink` streaming at the context's rate; the controller speaks in its own axes
    (the workcell's ``robot.controller`` map). Options from the ``site:`` section: ``mode``
    (``stream``/``poll``), ``deadman_ms``, ``baudrate``, ``parity``."""
    options = dict(context.options or {})
    link = ControllerLink(
        url, mode=options.pop("mode", "stream"), rate_hz=context.rate_hz, n_joints=context.n_joints or None, **options
    )
    link.joint_map = context.cell_joint_map
    return link
