"""The window's status bar: a message too long for the room left of the fields ends in an ellipsis there.

Qt's own bar draws its message from the left edge to the bar's right edge, under the permanent fields (the robot's
motion, the link, the camera, the pairs): a long message (Find points' reasons, an error) ran into them, cut
mid-word with nothing to say it was cut. Here it is drawn only up to the first field, elided. The whole message stays
the bar's :meth:`currentMessage` (and its tooltip, :class:`~app.gui.status_line.StatusLine`).
"""

from __future__ import annotations

from PySide6.QtCore import QRect, Qt
from PySide6.QtGui import QFontMetrics, QPainter
from PySide6.QtWidgets import QStatusBar, QStyle, QStyleOption, QWidget

_LEFT_PX = 6
"""Where Qt's bar starts its message."""
_GAP_PX = 2
"""Between the message and the first field, as Qt keeps it."""


class MessageStatusBar(QStatusBar):
    """A :class:`QStatusBar` whose temporary message is elided at the first visible field instead of running under
    the fields."""

    def message_room_px(self) -> int:
        """The width (px) the message may take: from where it starts to the first field shown (while a message shows,
        Qt hides every field that is not permanent, so the ones shown are the permanent ones)."""
        right = self.width() - 2 * _LEFT_PX
        for child in self.findChildren(QWidget, options=Qt.FindChildOption.FindDirectChildrenOnly):
            if child.isVisible():
                right = min(right, child.x() - _GAP_PX)
        return max(right - _LEFT_PX, 0)

    def shown_message(self) -> str:
        """The message as drawn: whole when it fits, else cut at the room with an ellipsis."""
        return QFontMetrics(self.font()).elidedText(
            self.currentMessage(), Qt.TextElideMode.ElideRight, self.message_room_px()
        )

    def paintEvent(self, event) -> None:  # noqa: N802 (Qt's name)
        if not self.currentMessage():
            super().paintEvent(event)
            return
        painter = QPainter(self)
        panel = QStyleOption()
        panel.initFrom(self)
        self.style().drawPrimitive(QStyle.PrimitiveElement.PE_PanelStatusBar, panel, painter, self)
        for child in self.findChildren(QWidget, options=Qt.FindChildOption.FindDirectChildrenOnly):
            if child.isVisible():
                frame = QStyleOption()
                frame.rect = child.geometry().adjusted(-2, -1, 2, 1)
                frame.palette = self.palette()
                frame.state = QStyle.StateFlag.State_None
                self.style().drawPrimitive(QStyle.PrimitiveElement.PE_FrameStatusBarItem, frame, painter, child)
        painter.setPen(self.palette().windowText().color())
        painter.drawText(
            QRect(_LEFT_PX, 0, self.message_room_px(), self.height()),
            Qt.AlignmentFlag.AlignLeading | Qt.AlignmentFlag.AlignVCenter | Qt.TextFlag.TextSingleLine,
            self.shown_message(),
        )
        painter.end()
