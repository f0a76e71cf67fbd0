"""ROS 2 on the wire without a ROS install: ROS 2's message types, topic names and QoS profiles over Cyclone
DDS (``cyclonedds``, the middleware of ``rmw_cyclonedds_cpp``). Imported only when a ``ros2://`` URL is used."""
