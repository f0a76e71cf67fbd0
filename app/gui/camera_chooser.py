"""*File > Open camera...*: any camera a connector handles, chosen while the window runs (the camera was
chosen only at launch). The spec is what ``--camera`` takes: a device number, a video file, a folder of images,
``rtsp://``/``http://`` streams, ``aravis://ID``, ``ros2:///topic``... A scheme nobody handles is refused before the
running camera is stopped; a camera that then fails to open says why in the results panel, and the window stays up.
Specs that gave a frame are offered again (``QSettings``)."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QInputDialog, QMenu

from calib_core.connectors.registry import ConnectorNotFoundError, check_camera_spec, open_camera

RECENT_KEY = "camera/recent"
RECENT_MAX = 8


class CameraChooser:
    """Adds *Open camera...* to ``menu``; :meth:`open_camera` switches the window's camera to a spec."""

    def __init__(self, window, menu: QMenu):
        self.window = window
        self.dialog: QInputDialog | None = None
        self.action = QAction(
            "Open ca&mera...", window, shortcut=QKeySequence("Ctrl+Shift+M"), triggered=self.open_dialog
        )
        self.action.setToolTip(
            "a device number, a video file, an image folder, rtsp://..., aravis://ID, ros2:///camera/image_raw"
        )
        menu.addAction(self.action)

    def recent(self) -> list[str]:
        value = self.window.settings.value(RECENT_KEY) or []
        return [v for v in ([value] if isinstance(value, str) else value) if v]

    def open_dialog(self) -> None:
        """The dialog (not blocking): an editable list of the recent specs."""
        dialog = QInputDialog(self.window)
        dialog.setWindowTitle("Open camera")
        dialog.setLabelText(
            "Camera: a device number (0), a video file, a folder of images,\nrtsp:// or http:// stream, aravis://ID, ros2:///camera/image_raw"
        )
        dialog.setComboBoxEditable(True)
        recent = self.recent()
        dialog.setComboBoxItems(recent or [""])
        if recent:
            dialog.setTextValue(recent[0])  # the camera used last, ready to open again
        dialog.textValueSelected.connect(self.open_camera)
        self.dialog = dialog
        dialog.open()

    def open_camera(self, spec: str) -> bool:
        """Switch to the camera ``spec``; False (and said) when no connector handles it: the running camera goes on."""
        spec = spec.strip()
        if not spec:
            return False
        try:
            check_camera_spec(spec)
        except ConnectorNotFoundError as exc:
            self.window.show_error(str(exc))
            return False
        w = self.window
        if w.worker is not None:
            w.worker.stop()
        w.start_camera(lambda: open_camera(spec))
        # remembered once it gives a frame: the list offers cameras that worked
        w.worker.frame.connect(lambda _frame: self._remember(spec), Qt.ConnectionType.SingleShotConnection)
        w.statusBar().showMessage(f"camera: {spec}", 8000)
        return True

    def _remember(self, spec: str) -> None:
        self.window.settings.setValue(RECENT_KEY, ([spec] + [s for s in self.recent() if s != spec])[:RECENT_MAX])
