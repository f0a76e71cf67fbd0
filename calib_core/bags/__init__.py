"""ROS bags (ROS 2: MCAP or sqlite3 storage; ROS 1 too) as a source of images, camera info and joints, through
``rosbags``: no ROS install."""
