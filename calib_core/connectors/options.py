"""A connector's numeric option (from its URL's query or the workcell's ``site:`` section), checked."""

from __future__ import annotations

import math

from calib_core.connectors.link_types import LinkError


def number_option(options: dict, key: str, default: float, low: float, high: float, scheme: str) -> float:
    """``options[key]`` (or ``default``) as a number in [low, high]; :class:`LinkError` names the option."""
    raw = options.get(key, default)
    try:
        value = float(raw)
    except (TypeError, ValueError):
        value = math.nan
    if not low <= value <= high:
        raise LinkError(f"{scheme} option {key}: must be a number in [{low:g}, {high:g}], got {raw!r}")
    return value
