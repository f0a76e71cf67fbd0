"""Calibrating the vision system itself: the camera's intrinsics from ChArUco board views."""
