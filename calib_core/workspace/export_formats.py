"""The formats the corrections export to, by name (the writers: :mod:`calib_core.workspace.exports`)."""

LISTING_FORMATS = ("urscript", "rapid", "krl", "fanuc", "pdl2")
"""The controller listings (:data:`calib_core.workspace.controller_formats.LISTINGS`, in this order)."""
EXPORT_FORMATS = ("json", "csv") + LISTING_FORMATS
