"""The Robot tab's camera-to-tool group: record a grasp at the current task location (the gripper
closed on its fixture pin in compliance, by the teach pendant), then measure the TCP from the grasps."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtWidgets import QGroupBox, QHBoxLayout, QLabel, QVBoxLayout

from app.gui.buttons import button
from app.gui.error_boundary import guarded


class ToolGroup(QGroupBox):
    """``changed`` is called after the robot's TCP changed (the panel's buttons follow)."""

    def __init__(self, measuring, show_error: Callable[[str], None], changed: Callable[[], None], parent=None):
        super().__init__("Camera to tool", parent)
        self.measuring = measuring  # the core's ToolMeasuring
        self.changed = changed
        self.measured_tool = None
        guard = guarded(show_error)
        layout = QVBoxLayout(self)
        how = QLabel(
            "Gripper closed on the task's pin in compliance (pendant), the camera seeing its fixture, then Record "
            "grasp; "
            "two tasks give the spread."
        )
        how.setWordWrap(True)
        layout.addWidget(how)
        row = QHBoxLayout()
        self.record_button = button(
            "Record grasp",
            "tool_record",
            "Keep the joints the controller reports now, the TCP on the current task location's pin",
        )
        self.record_button.clicked.connect(guard(self.record))
        self.measure_button = button(
            "Measure tool",
            "tool_measure",
            "The TCP in the camera frame from the grasps, through the robot as it is now (calibrate it first); Revert "
            "takes it back",
        )
        self.measure_button.clicked.connect(guard(self.measure))
        self.clear_button = button("Clear", "tool_clear", "Forget the recorded grasps")
        self.clear_button.clicked.connect(guard(self.clear))
        for b in (self.record_button, self.measure_button, self.clear_button):
            row.addWidget(b)
        layout.addLayout(row)
        self.text = QLabel("No grasp recorded.")
        self.text.setWordWrap(True)
        # Room for two lines from the start: a wrapped label that grows later is not given the height in a scroll area.
        self.text.setMinimumHeight(2 * self.text.fontMetrics().lineSpacing() + 4)
        layout.addWidget(self.text)
        self.refresh()

    def refresh(self) -> None:
        n = len(self.measuring.grasps)
        self.measure_button.setEnabled(n > 0)
        self.clear_button.setEnabled(n > 0)

    def record(self) -> None:
        g = self.measuring.record_grasp()
        self.text.setText(f"{len(self.measuring.grasps)} grasps (last: {g.name})")
        self.text.setToolTip("joints " + " ".join(f"{v:.3f}" for v in g.joints_deg) + " deg")
        self.refresh()

    def measure(self) -> None:
        t = self.measured_tool = self.measuring.measure_tool()
        self.text.setText(
            f"TCP from {len(t.per_grasp)} grasps ({t.seen_grasps} seen by the camera), spread {t.spread_mm:.3f} mm, "
            f"{t.spread_deg:.4f} deg: "
            "in use (Revert takes it back)"
        )
        self.text.setToolTip(
            f"TCP in the camera frame: {t.tcp2cam[0, 3]:.3f} {t.tcp2cam[1, 3]:.3f} {t.tcp2cam[2, 3]:.3f} mm; saved "
            "with the robot calibration"
        )
        self.refresh()
        self.changed()

    def clear(self) -> None:
        self.measuring.clear_grasps()
        self.text.setText("No grasp recorded.")
        self.refresh()
