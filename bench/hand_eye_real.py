"""The camera's mounting from real robots' data, beside the field's methods: every set in the shared folder's
``handeye/`` (a real robot's recorded tool poses, its gripper camera's images of a board), videocal's joint fit and
OpenCV's ``calibrateHandEye`` (Tsai, Park, Horaud, Daniilidis) and ``calibrateRobotWorldHandEye`` (Shah, Li) on the
same detected corners and the same intrinsics (the set's own, else videocal's from the same images).

For each answer: the camera in the tool (mm); the board's place in the base predicted from each view through it
(RMS spread: how well the poses agree through that answer); the corners' residual with the board where that answer
puts it on average; the stated 1-sigma (videocal's); and how far the answer moves when a third of the views is left
out (:data:`DRAWS` seeded draws of which third, the RMS of the moves, per axis). An honest 1-sigma predicts those
moves: leaving m of n views out, an answer's variance grows from sigma^2 to sigma^2 n / (n - m), so it moves by
sigma sqrt(n / (n - m) - 1) RMS (about sqrt(1/2) sigma for a third). Three folds (every third view out) gave only
three such moves: a ratio from them may lie a factor of two either way of the truth by chance alone.

Writes ``docs/benchmarks/hand_eye_real.md``. Run: ``.venv/bin/python -m bench hand_eye_real [--datasets FOLDER]``.
"""

from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

import cv2
import numpy as np

PROJECT = Path(__file__).resolve().parent.parent
OUT = PROJECT / "docs" / "benchmarks" / "hand_eye_real.md"
CLOSED_FORMS = {
    "Tsai": cv2.CALIB_HAND_EYE_TSAI,
    "Park": cv2.CALIB_HAND_EYE_PARK,
    "Horaud": cv2.CALIB_HAND_EYE_HORAUD,
    "Daniilidis": cv2.CALIB_HAND_EYE_DANIILIDIS,
}
ROBOT_WORLD = {"Shah": cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH, "Li": cv2.CALIB_ROBOT_WORLD_HAND_EYE_LI}


def board_text(board: dict) -> str:
    """videocal's ``--board`` text for a shared set's ``board.json``."""
    if board["pattern"] == "chessboard":
        return f"chessboard:{board['cols']}x{board['rows']}:{board['square_size_mm']:g}"
    if board["pattern"] == "charuco":
        return (
            f"charuco:{board['squares_x']}x{board['squares_y']}:{board['square_size_mm']:g}:"
            f"{board['marker_size_mm']:g}:{board['dictionary']}"
        )
    raise ValueError(f"unknown pattern {board['pattern']!r}")


def set_intrinsics(folder: Path, views, spec):
    """The set's own intrinsics (``intrinsics.json``, read as the commands read it), else videocal's from its views."""
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.vision.intrinsics_calibration import calibrate_intrinsics

    given = folder / "intrinsics.json"
    if given.exists():
        return load_intrinsics(given), "the set's own"
    result = calibrate_intrinsics(views, spec)
    return result.intrinsics, f"videocal's from the same {len(views)} images (RMS {result.rms_px:.2f} px)"


def closed_form(name, moving, board2cam):
    """``cam2flange`` (4, 4, mm) by OpenCV's method ``name``."""
    from calib_core.frames import make_transform

    if name in CLOSED_FORMS:
        R, t = cv2.calibrateHandEye(
            [T[:3, :3] for T in moving],
            [T[:3, 3] for T in moving],
            [T[:3, :3] for T in board2cam],
            [T[:3, 3] for T in board2cam],
            method=CLOSED_FORMS[name],
        )
        return make_transform(R, np.ravel(t))
    # robot-world: world = the board, "base2gripper" the inverse of the tool's pose
    inverse = [np.linalg.inv(T) for T in moving]
    world2cam = board2cam
    _, _, R, t = cv2.calibrateRobotWorldHandEye(
        [T[:3, :3] for T in world2cam],
        [T[:3, 3] for T in world2cam],
        [T[:3, :3] for T in inverse],
        [T[:3, 3] for T in inverse],
        method=ROBOT_WORLD[name],
    )
    gripper2cam = make_transform(R, np.ravel(t))
    return np.linalg.inv(gripper2cam)


def residual_px(cam2flange, moving, board2cam, views, spec, intrinsics) -> float:
    """The corners' RMS distance (px) with the board where ``cam2flange`` puts it on average in the base."""
    from scipy.spatial.transform import Rotation

    from calib_core.camera.projection import project
    from calib_core.frames import apply, concat, invert, make_transform

    placed = [concat(B, cam2flange, F) for F, B in zip(moving, board2cam)]
    board2base = make_transform(
        Rotation.from_matrix([P[:3, :3] for P in placed]).mean().as_matrix(), np.mean([P[:3, 3] for P in placed], 0)
    )
    corners = spec.corners_mm()
    squared = []
    for v, F in zip(views, moving):
        seen = concat(board2base, invert(F), invert(cam2flange))
        squared.append(np.sum((project(apply(seen, corners[v.ids]), intrinsics) - v.corners_px) ** 2, axis=1))
    return float(np.sqrt(np.mean(np.concatenate(squared))))


DRAWS = 30
"""How many different thirds of the views are left out, each a refit (seeded: the page is the same each run)."""


def run_set(folder: Path) -> list[str]:
    from calib_core.vision.board import parse_board
    from calib_core.vision.hand_eye import board_pose, calibrate_hand_eye, pose_agreement
    from calib_core.vision.hand_eye_data import load_posed_images
    from calib_core.vision.intrinsics_calibration import BoardView, detect_view

    spec = parse_board(board_text(json.loads((folder / "board.json").read_text())))
    data = load_posed_images(folder / "poses.json")
    views, moving = [], []
    for posed in data.views:
        v = detect_view(posed.name, data.read_image(posed), spec)
        if isinstance(v, BoardView):
            views.append(v)
            moving.append(posed.flange2base)
    intrinsics, where = set_intrinsics(folder, views, spec)
    board2cam = [board_pose(v, spec, intrinsics) for v in views]
    names = [v.name for v in views]
    n, left_out = len(views), len(views) // 3
    rng = np.random.default_rng(0)
    folds = [sorted(rng.choice(n, n - left_out, replace=False)) for _ in range(DRAWS)]

    t0 = time.perf_counter()
    ours = calibrate_hand_eye(views, moving, spec, intrinsics)
    seconds = time.perf_counter() - t0
    answers = {"videocal (joint fit)": ours.cam2flange}
    fold_answers = {
        "videocal (joint fit)": [
            calibrate_hand_eye([views[k] for k in f], [moving[k] for k in f], spec, intrinsics).cam2flange
            for f in folds
        ]
    }
    for name in list(CLOSED_FORMS) + list(ROBOT_WORLD):
        label = f"OpenCV {name}"
        answers[label] = closed_form(name, moving, board2cam)
        fold_answers[label] = [closed_form(name, [moving[k] for k in f], [board2cam[k] for k in f]) for f in folds]
    lines = [
        f"### {folder.name}",
        "",
        f"{len(views)} of {len(data.views)} views with the board found ({spec}); intrinsics: {where}. The corners' "
        f"own noise (each view's board pose fitted alone): {ours.noise_px:.3f} px. videocal took {seconds:.1f} s.",
        "",
        "| method | camera in the tool, mm | from videocal's, mm | board's spread in the base, mm / deg | corners' "
        "residual, px | stated 1-sigma, mm | leaving a third out moves it, mm (RMS per axis over "
        f"{DRAWS} draws) |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, X in answers.items():
        agreement = pose_agreement(moving, X, board2cam, names)
        moves = np.array([F[:3, 3] - X[:3, 3] for F in fold_answers[label]])
        rms_moves = np.sqrt(np.mean(moves**2, axis=0))
        stated = ", ".join(f"{s:.2f}" for s in ours.std_xyz_mm) if label.startswith("videocal") else "-"
        lines.append(
            f"| {label} | {', '.join(f'{v:.1f}' for v in X[:3, 3])} | "
            f"{np.linalg.norm(X[:3, 3] - ours.cam2flange[:3, 3]):.1f} | "
            f"{agreement.spread_mm:.2f} / {agreement.spread_deg:.3f} | "
            f"{residual_px(X, moving, board2cam, views, spec, intrinsics):.2f} | {stated} | "
            f"{', '.join(f'{m:.2f}' for m in rms_moves)} |"
        )
    moves = np.array([F[:3, 3] - ours.cam2flange[:3, 3] for F in fold_answers["videocal (joint fit)"]])
    predicted = np.sqrt(n / (n - left_out) - 1.0) * ours.std_xyz_mm
    ratio = np.sqrt(np.mean(moves**2, axis=0)) / np.maximum(predicted, 1e-9)
    lines += [
        "",
        f"Leaving {left_out} of {n} views out ({DRAWS} seeded draws), videocal's answer moved "
        f"{', '.join(f'{r:.2f}' for r in ratio)} times what its 1-sigma predicts (sqrt({n}/{n - left_out} - 1) of "
        "it), per axis (target: within 1.5 either way). Its warnings: " + ("; ".join(ours.warnings) or "none") + ".",
        "",
    ]
    return lines


def main(argv: list[str] | None = None) -> str:
    argv = sys.argv[1:] if argv is None else argv
    if "--datasets" in argv:
        root = Path(argv[argv.index("--datasets") + 1]).expanduser().resolve()
    else:
        root = Path(os.environ.get("VIDEOCAL_DATASETS", PROJECT.parent / "shared" / "datasets"))
    folder = root / "handeye"
    sets = sorted(p for p in folder.iterdir() if (p / "poses.json").exists()) if folder.is_dir() else []
    lines = [
        "# The camera's mounting from real robots' data",
        "",
        f"Measured {time.strftime('%Y-%m-%d')} on {platform.machine()}, {os.cpu_count()} cores "
        "(`python -m bench hand_eye_real`). Every figure here is from real robots and real images; no set has a "
        "true mounting, so answers are judged by how they explain the images and the poses, by their agreement "
        "and by whether the stated 1-sigma predicts how far an answer moves when a third of the views is left out.",
        "",
    ]
    if not sets:
        lines.append(f"**No hand-eye set was found** (looked in `{folder}`).")
    for s in sets:
        lines += run_set(s)
    if sets:
        lines += [
            "## Which is the better estimate",
            "",
            "On both sets the views disagree far beyond the corners' noise (13-15 times): the controllers' recorded "
            "poses, not the images, limit every answer. videocal's joint fit takes the poses as exact and minimises "
            "the corners' distances, so it explains the images best; the closed forms split each pose pair into a "
            "rotation and a translation equation, so they put the board's predicted places closest together. Neither "
            "models the robot's error, and where the poses are poor (franka: its views agree to 3-6 mm and 0.5-1 "
            "deg) they part by more than either's noise: 21 mm, along the axis the twelve poses fix least (the "
            "joint fit's largest 1-sigma, 9 mm, is on the same axis). videocal states that: its 1-sigma, taking each "
            "view as one measurement, covers the gap to the closed forms within 2.4 sigma, and leaving a third of the "
            "views out moves it 0.8-1.3 times as far as it predicts on both sets (three fixed folds, every third "
            "view out, had said 2.4 on kuka_2's depth: three moves are too few to judge a 1-sigma by). "
            "On kuka_2 (poses good to about a millimetre) all answers but Li's agree within "
            "2.6 mm and videocal's lies 0.4-0.6 mm from Tsai's, Park's and Horaud's. A fit that also estimates each "
            "view's pose error (its size from the data, as the warning states it) would weigh the two; until then "
            "the stated 1-sigma is what says how far to trust a mounting from poor poses.",
        ]
    OUT.write_text("\n".join(lines) + "\n")
    return str(OUT)


if __name__ == "__main__":
    print(main())
