"""The scheme of a connector URL: the name its connector is registered under.

Controller URLs: ``/dev/ttyUSB0`` or ``COM3`` (a serial port: scheme ``serial``), ``socket://host:port``,
``rfc2217://host:port``, ``loop://``, ``ros2:///joint_states``, ``ur-rtde://host`` ...
Camera specs: ``0`` (an OpenCV device index: scheme ``opencv``), a video file (``file``), a folder of images
(``folder``), ``rtsp://`` / ``http://`` streams, ``aravis://<device id>``, ``ros2:///camera/image_raw`` ...
"""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import SplitResult, urlsplit

_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*)://")


def url_scheme(url: str) -> str | None:
    """The scheme before ``://`` (lower case), or None for a bare path or number."""
    m = _SCHEME.match(url)
    return m.group(1).lower() if m else None


def controller_scheme(url: str) -> str:
    """The connector name of a controller URL: its scheme, ``serial`` for a bare port path."""
    return url_scheme(url) or "serial"


def camera_scheme(spec: str) -> str:
    """The connector name of a camera spec: its scheme; ``opencv`` for a device index,
    ``folder`` for a folder, ``file`` for anything else without a scheme."""
    scheme = url_scheme(spec)
    if scheme is not None:
        return scheme
    if spec.strip().isdigit():
        return "opencv"
    return "folder" if Path(spec).is_dir() else "file"


def split_url(url: str, error: type[Exception]) -> SplitResult:
    """``url`` split as :func:`urllib.parse.urlsplit` splits it; ``error`` (the connector's own, naming the URL) where
    it cannot be (an unmatched ``[`` or ``]``: ``ros2://]x`` once escaped as Python's "Invalid IPv6 URL")."""
    try:
        return urlsplit(url)
    except ValueError as exc:
        raise error(
            f"{url!r}: not a URL the connector can read ({exc}; a bracket belongs round an IPv6 address)"
        ) from None
