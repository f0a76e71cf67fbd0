"""videocal's window (PySide6) and command line. Owns no domain state: that lives in calib_core.

Importing ``app`` or ``app.cli`` does not import Qt; only ``app.gui`` and below do.
"""
