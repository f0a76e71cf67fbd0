"""The Cell tab: the paper's RobCAD component and workcell environments. Add a component from a
mesh file, place it by numbers (its surveyed placement) with the views following, name features by
clicking on it in the virtual camera (snapped to circle centres, corners and vertices), add task
locations at the current pose or by numbers, and save the cell back to its workcell file. Every
edit is one undoable command on the session's stack; the panel only shows the core's state."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QSignalBlocker, Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QInputDialog,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from calib_core.operator.panes.cell_editing import CellPaneModel
from calib_core.frames import apply, transform_from_xyz_rpy, xyz_rpy_from_transform

SNAP_RADIUS_PX = 12.0


def _spin(suffix: str, limit: float, decimals: int, name: str) -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setObjectName(name)
    box.setRange(-limit, limit)
    box.setDecimals(decimals)
    box.setSuffix(suffix)
    box.setKeyboardTracking(False)
    return box


class CellPanel(QWidget):
    """``attempt(fn, *args)`` runs an action through the window's error boundary.
    ``feature_mode_changed(component or None)``: features of that component are named by clicking
    in the virtual camera (``None``: not any more)."""

    feature_mode_changed = Signal(object)

    def __init__(self, model: CellPaneModel, attempt, parent=None):
        super().__init__(parent)
        self.model = model
        self._attempt = attempt
        layout = QVBoxLayout(self)

        comps = QGroupBox("Components")
        cl = QVBoxLayout(comps)
        row = QHBoxLayout()
        self.component = QComboBox()
        self.component.setObjectName("cell_component")
        row.addWidget(self.component, 1)
        self.add_component = QPushButton("Add...")
        self.add_component.setToolTip("Add a component from a mesh file (STL, OBJ, DAE, glTF, PLY; mm)")
        row.addWidget(self.add_component)
        cl.addLayout(row)
        grid = QGridLayout()
        self.xyz = [_spin(" mm", 20000.0, 2, f"place_{a}") for a in "xyz"]
        self.rpy = [_spin(" deg", 360.0, 4, f"place_{a}") for a in ("roll", "pitch", "yaw")]
        for i, (label, box) in enumerate(zip(("X", "Y", "Z", "roll", "pitch", "yaw"), self.xyz + self.rpy)):
            grid.addWidget(QLabel(label), i % 3, 2 * (i // 3))
            grid.addWidget(box, i % 3, 2 * (i // 3) + 1)
        cl.addLayout(grid)
        cl.addWidget(QLabel("<small>placement in the robot's base frame, as surveyed</small>"))
        layout.addWidget(comps)

        feats = QGroupBox("Features")
        fl = QVBoxLayout(feats)
        self.pick_features = QCheckBox("Name features by clicking (virtual camera)")
        self.pick_features.setObjectName("pick_features")
        self.pick_features.setToolTip(
            "A click on the chosen component in the virtual camera adds a feature, snapped to a circle centre, a "
            "corner or a vertex"
        )
        fl.addWidget(self.pick_features)
        name_row = QFormLayout()
        self.feature_name = QLineEdit()
        self.feature_name.setObjectName("feature_name")
        self.feature_name.setPlaceholderText("name of the next feature (default: feature_N)")
        name_row.addRow("Name", self.feature_name)
        fl.addLayout(name_row)
        self.feature_info = QLabel("")
        self.feature_info.setTextFormat(Qt.TextFormat.PlainText)  # names from the cell file: never markup
        self.feature_info.setWordWrap(True)
        fl.addWidget(self.feature_info)
        layout.addWidget(feats)

        tasks = QGroupBox("Task locations")
        tl = QFormLayout(tasks)
        self.task_name = QLineEdit()
        self.task_name.setObjectName("task_name")
        self.task_name.setPlaceholderText("location_N")
        tl.addRow("Name", self.task_name)
        self.task_xyz = [_spin(" mm", 20000.0, 2, f"task_{a}") for a in "xyz"]
        self.task_rpy = [_spin(" deg", 360.0, 4, f"task_{a}") for a in ("roll", "pitch", "yaw")]
        for label, box in zip(("X", "Y", "Z", "roll", "pitch", "yaw"), self.task_xyz + self.task_rpy):
            tl.addRow(label, box)
        self.task_approach = _spin(" mm", 2000.0, 1, "task_approach")
        self.task_approach.setRange(0.0, 2000.0)
        tl.addRow("Approach", self.task_approach)
        buttons = QHBoxLayout()
        self.take_pose = QPushButton("Current pose")
        self.take_pose.setToolTip("Fill in the TCP pose the robot is at")
        self.add_task = QPushButton("Add location")
        buttons.addWidget(self.take_pose)
        buttons.addWidget(self.add_task)
        tl.addRow(buttons)
        layout.addWidget(tasks)

        self.save = QPushButton("Save cell")
        self.save.setObjectName("save_cell")
        self.save.setToolTip(
            "Write the components, features and task locations back into the workcell file (its comments are kept)"
        )
        layout.addWidget(self.save)
        layout.addStretch(1)

        self.component.currentTextChanged.connect(self._show_component)
        for box in self.xyz + self.rpy:
            box.valueChanged.connect(self._placement_edited)
        self.add_component.clicked.connect(self._add_component_dialog)
        self.take_pose.clicked.connect(self.fill_current_pose)
        self.add_task.clicked.connect(lambda: self._attempt(self.add_task_location))
        self.save.clicked.connect(lambda: self._attempt(self.model.save))
        model.scene_changed.connect(self._sync)
        self.pick_features.toggled.connect(self._feature_mode)
        self.component.currentTextChanged.connect(lambda _: self._feature_mode(self.picking_features))
        self._sync()
        self.fill_current_pose()

    # --- the core's state into the widgets ------------------------------------------------------
    def _sync(self) -> None:
        names = self.model.component_names
        current = self.component.currentText()
        if [self.component.itemText(i) for i in range(self.component.count())] != names:
            self.component.blockSignals(True)
            self.component.clear()
            self.component.addItems(names)
            self.component.setCurrentText(current if current in names else (self.model.target or names[0]))
            self.component.blockSignals(False)
        self._show_component(self.component.currentText())

    def _show_component(self, name: str) -> None:
        if not name:
            return
        xyz, rpy = xyz_rpy_from_transform(self.model.component(name).item2world)
        for box, v in zip(self.xyz + self.rpy, list(xyz) + list(rpy)):
            with QSignalBlocker(box):  # showing the core's placement is not an edit of it
                box.setValue(float(v))

    # --- edits ------------------------------------------------------------------------------------
    def _placement_edited(self) -> None:
        name = self.component.currentText()
        self._attempt(self.model.place_component, name, [b.value() for b in self.xyz], [b.value() for b in self.rpy])

    def _add_component_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self,
            "Add component",
            str(self.model.cell_folder),
            "Meshes (*.stl *.obj *.dae *.glb *.gltf *.ply)",
        )
        if not path:
            return
        name, ok = QInputDialog.getText(self, "Add component", "Name of the component:", text=Path(path).stem)
        if ok:
            self.add_component_file(path, name)

    def add_component_file(self, path, name: str) -> None:
        """Add the component and select it, so its placement can be typed at once."""
        if self._attempt(self.model.add_component, path, name):
            self.component.setCurrentText(name.strip())

    def fill_current_pose(self) -> None:
        xyz, rpy = xyz_rpy_from_transform(self.model.tcp2base)
        for box, v in zip(self.task_xyz + self.task_rpy, list(xyz) + list(rpy)):
            box.setValue(float(v))

    def add_task_location(self) -> None:
        T = transform_from_xyz_rpy([b.value() for b in self.task_xyz], [b.value() for b in self.task_rpy])
        self.model.add_task_location(self.task_name.text(), T, self.task_approach.value())
        self.task_name.clear()

    def _feature_mode(self, on: bool) -> None:
        self.feature_mode_changed.emit(self.component.currentText() if on else None)

    @property
    def picking_features(self) -> bool:
        return self.pick_features.isChecked()

    def feature_clicked(self, hit, cam2world: np.ndarray, focal_px: float) -> None:
        """A click on the chosen component in the virtual camera: snap it, name it, add it."""
        depth_mm = float(np.linalg.norm(hit.point_world_mm - cam2world[:3, 3]))
        snap = self.model.snap_feature(hit.component, hit.point_component_mm, SNAP_RADIUS_PX * depth_mm / focal_px)
        item = self.model.component(hit.component)
        name = self.feature_name.text().strip() or f"feature_{len(item.features) + 1}"
        self.model.add_feature(hit.component, name, snap.point_mm)
        self.feature_name.clear()
        world = apply(item.item2world, np.asarray(snap.point_mm)[None])[0]
        self.feature_info.setText(
            f"{hit.component}/{name}: {snap.kind.replace('_', ' ')} at "
            f"({', '.join(f'{v:.1f}' for v in snap.point_mm)}) mm, "
            f"{snap.distance_mm:.1f} mm from the click; base ({', '.join(f'{v:.1f}' for v in world)})"
        )
