"""A recorded set of chessboard views for the camera-calibration tests: the simulated camera's frames written
as a recording would."""

from pathlib import Path


def recorded_set(folder: Path, moved_view: int, moved_mm: float) -> Path:
    """A hand-eye set as a robot cell records one: the simulated camera's PNG images of a ChArUco board and a JSON of
    each image's flange pose from the controller (mm), one view's pose recorded ``moved_mm`` off (a pose read before
    the robot settled)."""
    import json

    import cv2

    from calib_core.vision.board import BoardSpec
    from videocal_sim.hand_eye_views import board_facing_robot, hand_eye_poses, simulated_hand_eye_images
    from videocal_sim.test_bed import TestBed

    spec = BoardSpec()
    bed = TestBed.create()
    board2base = board_facing_robot(spec)
    joints = hand_eye_poses(bed, spec, board2base, 10)
    (folder / "images").mkdir(parents=True)
    poses = []
    for k, (name, image, q) in enumerate(simulated_hand_eye_images(bed, spec, joints, board2base)):
        cv2.imwrite(str(folder / "images" / f"{name}.png"), image[:, :, ::-1])
        flange = bed.model_robot.fk(q, "flange")
        if k == moved_view:
            flange[:3, 3] += [moved_mm, 0.0, 0.0]
        poses.append({"image": f"images/{name}.png", "flange2base": flange.tolist()})
    path = folder / "poses.json"
    path.write_text(json.dumps({"length_unit": "mm", "poses": poses}))
    return path
