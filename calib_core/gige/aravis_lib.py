"""Aravis, imported once: its GObject-introspection module (``gir1.2-aravis-0.8``) through PyGObject."""

from __future__ import annotations

from calib_core.connectors.frame import VideoSourceError


def aravis():
    """The ``Aravis`` module; :class:`VideoSourceError` saying what to install when it is missing."""
    try:
        import gi

        gi.require_version("Aravis", "0.8")
        from gi.repository import Aravis
    except (ImportError, ValueError) as exc:
        raise VideoSourceError(
            f"GenICam cameras need Aravis 0.8 and PyGObject (apt-get install gir1.2-aravis-0.8; make venv): {exc}"
        ) from None
    return Aravis
