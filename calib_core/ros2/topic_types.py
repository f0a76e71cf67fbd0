"""Which message types the publishers on a topic send, from DDS discovery (the built-in DCPSPublication topic).

A reader of one type never matches a writer of another: without this a topic of the wrong type looks like a
silent one ("waiting for joint_states" while a publisher sends std_msgs/String there)."""

from __future__ import annotations


def ros_type_name(dds_type: str) -> str:
    """``sensor_msgs::msg::dds_::JointState_`` -> ``sensor_msgs/msg/JointState`` (other names as they are)."""
    parts = dds_type.split("::")
    if len(parts) == 4 and parts[2] == "dds_" and parts[3].endswith("_"):
        return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"
    return dds_type


class TopicTypes:
    """Publishers' types seen by ``participant`` (a :class:`cyclonedds.domain.DomainParticipant`)."""

    def __init__(self, participant):
        from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication

        self._reader = BuiltinDataReader(participant, BuiltinTopicDcpsPublication)

    def close(self) -> None:
        """Delete the discovery reader (once no thread reads it)."""
        from calib_core.ros2.participant import delete

        delete(self._reader)

    def on(self, dds_topic: str) -> set[str]:
        """The DDS type names of the writers now on ``dds_topic`` (``rt/joint_states``)."""
        return {s.type_name for s in self._reader.read(N=4096) if s.topic_name == dds_topic}

    def foreign(self, dds_topic: str, wanted_dds_type: str) -> list[str]:
        """The ROS names of the other types than ``wanted_dds_type`` sent on ``dds_topic``, sorted."""
        return sorted(ros_type_name(t) for t in self.on(dds_topic) - {wanted_dds_type})
