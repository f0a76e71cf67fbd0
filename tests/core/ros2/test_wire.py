"""ROS 2's names on DDS: topics, type names, domain ids."""

import pytest

from calib_core.ros2 import messages as msg
from calib_core.ros2.wire import Ros2NameError, dds_topic, domain_id


def test_topics_take_rt_prefix():
    assert dds_topic("/joint_states") == "rt/joint_states"
    assert (
        dds_topic("/arm/joint_trajectory_controller/joint_trajectory")
        == "rt/arm/joint_trajectory_controller/joint_trajectory"
    )
    assert dds_topic("tf_static") == "rt/tf_static"


@pytest.mark.parametrize("bad", ["", "/", "/9lives", "/a//b", "/a b", "/a/"])
def test_bad_topic_names_are_refused(bad):
    with pytest.raises(Ros2NameError):
        dds_topic(bad)


def test_type_names_are_rmw_cyclonedds_ones():
    assert msg.JointState.__idl_typename__ == "sensor_msgs::msg::dds_::JointState_"
    assert msg.JointTrajectory.__idl_typename__ == "trajectory_msgs::msg::dds_::JointTrajectory_"
    assert msg.TFMessage.__idl_typename__ == "tf2_msgs::msg::dds_::TFMessage_"
    assert msg.CameraInfo.__idl_typename__ == "sensor_msgs::msg::dds_::CameraInfo_"


def test_domain_from_environment(monkeypatch):
    monkeypatch.setenv("ROS_DOMAIN_ID", "42")
    assert domain_id() == 42 and domain_id(3) == 3
    monkeypatch.setenv("ROS_DOMAIN_ID", "300")
    with pytest.raises(Ros2NameError, match="0..232"):
        domain_id()


def test_a_time_round_trips_through_nanoseconds():
    t = msg.Time.of_ns(1_796_303_121_209_123_456)
    assert (t.sec, t.nanosec) == (1_796_303_121, 209_123_456) and t.ns() == 1_796_303_121_209_123_456
    assert msg.Duration.of_s(2.25).seconds() == 2.25
