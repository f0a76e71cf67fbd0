"""Universal Robots controllers through Universal Robots' RTDE interface, with ``ur_rtde`` (SDU Robotics)."""
