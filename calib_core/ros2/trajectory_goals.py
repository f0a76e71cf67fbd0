"""A streamed move as ``FollowJointTrajectory`` goals: each renewal of the move's horizon is a goal that preempts the
last (what ros2_control's joint_trajectory_controller does with a new goal), so the dead-man behaviour of the topic
interface is kept: when the goals stop coming the arm stops at the last one's end, within the horizon.

What the action adds is the controller's word: a refused goal, or one that ends aborted (a path or goal tolerance
broken, joints the controller does not have) ends the move with the controller's reason; Stop cancels the running
goal (the controller holds where the arm is).
"""

from __future__ import annotations

import threading

from calib_core.ros2 import action_types as at
from calib_core.ros2.action_client import FollowJointTrajectoryClient


class GoalStream:
    """The goals of one connector (``client``); ``current`` is the goal of the move under way, if any."""

    def __init__(self, client: FollowJointTrajectoryClient):
        self.client = client
        self.current: bytes | None = None
        self._lock = threading.Lock()

    def send(self, trajectory) -> None:
        """Send ``trajectory`` (``trajectory_msgs/JointTrajectory``) as the move's next goal."""
        goal_id = self.client.send_goal(at.FollowJointTrajectoryGoal(trajectory=trajectory))
        with self._lock:
            self.current = goal_id

    def cancel(self) -> bool:
        """Cancel the running goal (Stop); False when there is none."""
        with self._lock:
            goal_id, self.current = self.current, None
        if goal_id is None:
            return False
        self.client.cancel(goal_id)
        return True

    def release(self) -> None:
        """The move ended (reached, failed): its goal's later news is not the move's."""
        with self._lock:
            self.current = None

    def poll(self) -> str | None:
        """Why the move under way must end, from what the controller answered since the last call; else None.
        Answers about goals that are not the current one (preempted by the next renewal, cancelled by Stop) are not the
        move's."""
        reason = None
        for event in self.client.poll(0.0):
            with self._lock:
                mine = event.goal == self.current
            if not mine:
                continue
            if event.kind == "refused":
                reason = (
                    f"the controller refused the goal on {self.client.name} (its log says why: joints it does not "
                    "have, a point "
                    "past a limit, or the controller not active)"
                )
            elif event.kind == "ended" and event.status in (at.ABORTED, at.CANCELED):
                code = at.ERROR_NAMES.get(event.error_code, str(event.error_code))
                reason = (
                    f"the controller {at.STATUS_NAMES[event.status]} the move "
                    f"({code}{': ' + event.error_string if event.error_string else ''})"
                )
        if reason is not None:
            self.release()
        return reason
