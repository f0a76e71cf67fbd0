"""Calibrating the vision system itself: the camera's intrinsics and its mounting on the robot (hand-eye) from views
of a calibration board (ChArUco, chessboard, circle grid, ArUco grid). Finding a workcell object in an image, the
look, is :mod:`calib_core.look`."""
