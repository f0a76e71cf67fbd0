"""*Store correction* with the operator's explicit word wherever the core asks for it: a look made
away from the task location (store it as a measurement, or convert it and see what the commanded
target does), and a result that is not OK."""

from __future__ import annotations

import getpass
from datetime import datetime, timezone

from PySide6.QtWidgets import QWidget

from app.gui.confirm import ask, ask_choice
from calib_core.calibration.look_place import LookNotAtTask
from calib_core.calibration.errors import ConfirmationNeeded


def _who() -> str:
    return f"{getpass.getuser()} at {datetime.now(timezone.utc).isoformat(timespec='seconds')}"


def store_with_consent(parent: QWidget, desk, say) -> None:
    """Store the last result for the task location through the correction ``desk``
    (:class:`~calib_core.operator.correction_desk.CorrectionDesk`), asking in ``parent`` what the desk needs asked;
    ``say(text)`` reports what was (not) stored."""
    convert = ""
    try:
        _store(parent, desk, convert, say)
    except LookNotAtTask as exc:
        task = exc.place.task
        question = "\n".join(
            [
                f"This look cannot be {task}'s correction as it is: {exc.place.text}.",
                "",
                "A robot's error changes with its pose: a look made elsewhere corrects that pose, not the task "
                "location.",
                "",
                f"Store as measurement: kept in {task}'s history at its own pose; nothing the robot does changes.",
                f"Convert into {task}'s correction: the target commanded for {task} moves by {exc.change_mm:.2f} mm "
                f"and {exc.change_deg:.3f} deg. "
                "Your conversion is kept with the correction.",
            ]
        )
        chosen = ask_choice(
            parent,
            "A look from another place",
            question,
            [("measurement", "Store as measurement"), ("convert", f"Convert into {task}'s correction")],
        )
        if chosen == "measurement":
            desk.store_measurement()
        elif chosen == "convert":
            _store(parent, desk, f"converted in the window by {_who()}", say)
        else:
            say("nothing stored")


def _store(parent: QWidget, desk, convert: str, say) -> None:
    try:
        desk.store_correction(convert=convert)
    except ConfirmationNeeded as exc:
        question = "\n".join(
            [
                "This result is not OK:",
                *[f"- {r}" for r in exc.reasons],
                "",
                "Store it as the correction for this task location anyway?",
                "Your confirmation is kept with the correction.",
            ]
        )
        if not ask(parent, "Store an implausible result?", question, "Store anyway"):
            say("nothing stored")
            return
        desk.store_correction(
            convert=convert, confirmation=f"confirmed in the window by {_who()}: {'; '.join(exc.reasons)}"
        )
