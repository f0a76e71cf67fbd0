"""Questions the window asks before a step it cannot take back: a modal message box whose
buttons say what they do."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QMessageBox, QWidget


def ask(parent: QWidget, title: str, text: str, yes_label: str) -> bool:
    """``True`` when the operator chose ``yes_label`` (the default button is the safe one: no)."""
    box = QMessageBox(QMessageBox.Icon.Warning, title, text, parent=parent)
    box.setTextFormat(Qt.TextFormat.PlainText)  # file and component names come from files: never markup
    yes = box.addButton(yes_label, QMessageBox.ButtonRole.AcceptRole)
    no = box.addButton("Cancel", QMessageBox.ButtonRole.RejectRole)
    box.setDefaultButton(no)
    box.setEscapeButton(no)
    box.setObjectName("confirm")
    box.exec()
    return box.clickedButton() is yes


def ask_save(parent: QWidget, title: str, text: str) -> str:
    """``save``, ``discard`` or ``cancel``."""
    box = QMessageBox(QMessageBox.Icon.Question, title, text, parent=parent)
    box.setTextFormat(Qt.TextFormat.PlainText)
    box.setObjectName("confirm")
    box.setStandardButtons(
        QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard | QMessageBox.StandardButton.Cancel
    )
    box.setDefaultButton(QMessageBox.StandardButton.Save)
    box.setEscapeButton(QMessageBox.StandardButton.Cancel)
    chosen = box.exec()
    return {QMessageBox.StandardButton.Save: "save", QMessageBox.StandardButton.Discard: "discard"}.get(
        QMessageBox.StandardButton(chosen), "cancel"
    )


def ask_choice(parent: QWidget, title: str, text: str, choices: list[tuple[str, str]]) -> str:
    """The key of the button chosen among ``choices`` (``(key, label)``), or ``cancel``; Cancel is the
    default and Esc's answer."""
    box = QMessageBox(QMessageBox.Icon.Warning, title, text, parent=parent)
    box.setTextFormat(Qt.TextFormat.PlainText)
    buttons = {box.addButton(label, QMessageBox.ButtonRole.AcceptRole): key for key, label in choices}
    no = box.addButton("Cancel", QMessageBox.ButtonRole.RejectRole)
    box.setDefaultButton(no)
    box.setEscapeButton(no)
    box.setObjectName("confirm")
    box.exec()
    return buttons.get(box.clickedButton(), "cancel")
