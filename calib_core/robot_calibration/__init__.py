"""Robot calibration from the camera: the robot's geometric parameters, its camera mounting and
optionally the camera's intrinsics, identified together from views of a board and of surveyed cell
features at many poses (docs/calibration.md)."""
