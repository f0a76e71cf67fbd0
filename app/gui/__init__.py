"""The operator's window (PySide6). It only shows and edits the models of ``calib_core``."""
