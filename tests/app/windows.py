"""Helpers for the window tests."""

from PySide6.QtCore import QSettings


def window_settings(folder, name: str = "settings") -> QSettings:
    """A window's settings in ``folder``, its autosaves there too (a test's windows never see another test's)."""
    settings = QSettings(str(folder / f"{name}.ini"), QSettings.Format.IniFormat)
    settings.setValue("files/autosave_dir", str(folder / f"{name}_autosave"))
    return settings
