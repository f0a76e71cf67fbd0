"""The command panels' push buttons: a label, an object name the tests and the demo find it by, a tip."""

from __future__ import annotations

from PySide6.QtWidgets import QPushButton


def button(text: str, name: str, tip: str = "") -> QPushButton:
    b = QPushButton(text)
    b.setObjectName(name)
    if tip:
        b.setToolTip(tip)
    return b
