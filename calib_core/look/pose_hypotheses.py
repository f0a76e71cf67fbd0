"""Where to start the edge refinement: camera poses within the robot's error of the modelled one,
ranked by how well the target's edges lie on the image's (truncated chamfer distance).

A robot's error moves the camera's centre (up to ``reach_mm``) and turns it (up to ``reach_deg``).
Far from the target both look alike, a shift of the image; close to it the move also shifts near and
far edges by different amounts (parallax): at the paper's task location, 177 mm from the fixture, a
shift that lays the plate's outline on the image leaves the pin 15 px off, and the edge refinement
settled from there with half its samples on the plate, 2.4 mm from the true pose. A 2D shift found
first also locks onto the wrong edges once the error reaches 100 px (twice the typical robot error,
that close), and a search around it inherits that. So the search is over the camera itself: its centre
on a grid over the reach (across and along the line of sight), a roll about the line of sight, and the
turn of its line of sight, which is nearly a shift of the image, scored as one (a grid of pixel
offsets over ``reach_deg``, added to each centre's projection). Every candidate is scored by the mean
distance of the target's edge samples from the image's edges (Canny, truncated at
:data:`TRUNCATE_PX`); the best few that differ in the image by more than a few pixels are where the
refinement starts.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import concat

TRUNCATE_PX = 40.0
"""The distance map's cap (px): wide enough that a pose 30 px from the target still sees its way down
(at 20 px the landscape was flat between the grid's points, 5 mm apart at 155 mm), and one far edge
costs no more than this."""
ROLL_DEG = 2.0
"""The largest roll about the line of sight searched: about three times a typical robot's orientation error."""
_LATERAL_STEPS = 9
_DEPTH_STEPS = 5
_ROLL_STEPS = 5
_TURN_STEPS = 7
_MAX_SAMPLES = 150
_DISTINCT_PX = 6.0
_RESCORED = 600


def turned_camera(obj2cam: np.ndarray, shift_px: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """``obj2cam`` (4, 4) with the camera turned about its centre so the image moves by ``shift_px`` (2,)
    (to first order: exact at the image's centre)."""
    turn = Rotation.from_rotvec([-shift_px[1] / intrinsics.fv, shift_px[0] / intrinsics.fu, 0.0]).as_matrix()
    out = obj2cam.copy()
    out[:3, :3] = turn @ obj2cam[:3, :3]
    out[:3, 3] = turn @ obj2cam[:3, 3]
    return out


def moved_cameras(obj2cam: np.ndarray, shifts_mm: np.ndarray, rolls_deg: np.ndarray) -> np.ndarray:
    """``obj2cam`` (4, 4) with the camera's centre moved by each of ``shifts_mm`` (H, 3) (camera axes)
    and the camera rolled by ``rolls_deg`` (H,) about its optical axis: (H, 4, 4)."""
    moved = np.tile(np.eye(4), (len(shifts_mm), 1, 1))
    moved[:, :3, :3] = Rotation.from_rotvec(np.radians(rolls_deg)[:, None] * np.array([0.0, 0.0, 1.0])).as_matrix()
    moved[:, :3, 3] = -np.einsum("hij,hj->hi", moved[:, :3, :3], shifts_mm)
    return concat(obj2cam, moved)


def turn_moves_px(samples_mm: np.ndarray, obj2cam: np.ndarray, intrinsics: Intrinsics, turn_deg: float) -> float:
    """How far (px) the farthest-moved of ``samples_mm`` (m, 3, the object's frame) moves in the image at ``obj2cam``
    when the object turns ``turn_deg`` each way about the camera's x and y axes through the samples' centre (as
    :func:`object_turned` turns it): a part seen face on and far off hardly moves, a long one pointing away swings."""
    turned, _ = object_turned(obj2cam[None], np.zeros((1, 0)), samples_mm.mean(axis=0), turn_deg)
    seen = projected(samples_mm, turned, intrinsics)  # (9, m, 2)
    moved = np.linalg.norm(seen[1:] - seen[0], axis=2)
    return float(np.nanmax(moved)) if np.isfinite(moved).any() else 0.0


def projected(samples_mm: np.ndarray, poses: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Where each of ``poses`` (H, 4, 4, obj2cam) puts ``samples_mm`` (m, 3, the object's frame) in the image: (H, m, 2)
    px, NaN behind the camera. A batched matmul (einsum's generic loop took 30 ms for a thousand poses of 400
    samples)."""
    pts = np.matmul(samples_mm, poses[:, :3, :3].transpose(0, 2, 1)) + poses[:, None, :3, 3]
    return project(pts.reshape(-1, 3), intrinsics).reshape(len(poses), -1, 2)


def object_turned(
    poses: np.ndarray, grid: np.ndarray, centre_mm: np.ndarray, turn_deg: float
) -> tuple[np.ndarray, np.ndarray]:
    """Each of ``poses`` (H, 4, 4, obj2cam) with the object turned by -``turn_deg``, 0 and +``turn_deg`` about the
    camera's x and y axes through ``centre_mm`` (3,, the object's frame), which stays where it was: (9 H, 4, 4), and
    ``grid`` (H, k) with the two turns (deg) as two more columns (9 H, k + 2), the unturned ones first."""
    centre = np.einsum("hij,j->hi", poses[:, :3, :3], centre_mm) + poses[:, :3, 3]  # (in the camera's frame)
    steps = (0.0, -turn_deg, turn_deg)
    out_poses, out_grid = [], []
    for a in steps:
        for b in steps:
            turn = Rotation.from_rotvec(np.radians([a, b, 0.0])).as_matrix()
            turned = poses.copy()
            turned[:, :3, :3] = np.matmul(turn, poses[:, :3, :3])
            turned[:, :3, 3] = centre - np.einsum("hij,j->hi", turned[:, :3, :3], centre_mm)
            out_poses.append(turned)
            out_grid.append(np.column_stack([grid, np.full(len(grid), a), np.full(len(grid), b)]))
    return np.concatenate(out_poses), np.concatenate(out_grid)


def _scores(padded_flat: np.ndarray, base: np.ndarray, offsets_flat: np.ndarray) -> np.ndarray:
    """Mean truncated distance (H, S) of the samples at the flat indices ``base`` (H, m) of the padded
    distance map, each moved by every flat offset ``offsets_flat`` (S,) (a move of (du, dv) whole
    pixels is du + dv times the padded width: the padding holds every move inside the map)."""
    return padded_flat[base[:, None, :] + offsets_flat[None, :, None]].mean(axis=2)


def rank_starts(
    distance: np.ndarray,
    intrinsics: Intrinsics,
    samples_mm: np.ndarray,
    obj2cam: np.ndarray,
    reach_mm: float,
    reach_deg: float,
    keep: int = 3,
    object_turn_deg: float = 0.0,
) -> list[np.ndarray]:
    """The ``keep`` best poses (4, 4) to start an edge refinement from, best first, near ``obj2cam``.

    ``distance`` (h, w): each pixel's distance to the nearest image edge, truncated at
    :data:`TRUNCATE_PX` (:func:`calib_core.look.edge_alignment.edge_distance_map`);
    ``samples_mm`` (m, 3): points on the target's edges that the camera sees (object frame);
    ``reach_mm``, ``reach_deg``: how far the camera's centre and its line of sight may be from
    ``obj2cam``'s. ``object_turn_deg``: every candidate also with the object turned this far each way about the two
    axes across the line of sight through its samples' centre (nine times the candidates), for a prior that is an
    error of the object itself (:func:`object_turned`), where such a turn moves its samples further in the image
    than candidates are told apart by (:func:`turn_moves_px`). Candidates whose edges lie within a few pixels of a
    better one's are left out.
    """
    if len(samples_mm) < 10:
        return [obj2cam]
    if len(samples_mm) > _MAX_SAMPLES:
        samples_mm = samples_mm[np.random.default_rng(0).choice(len(samples_mm), _MAX_SAMPLES, replace=False)]
    lateral = np.linspace(-reach_mm, reach_mm, _LATERAL_STEPS)
    depth = np.linspace(-reach_mm, reach_mm, _DEPTH_STEPS)
    rolls = np.linspace(-ROLL_DEG, ROLL_DEG, _ROLL_STEPS)
    grid = np.array([(x, y, z, r) for x in lateral for y in lateral for z in depth for r in rolls])
    poses = moved_cameras(obj2cam, grid[:, :3], grid[:, 3])
    centre = samples_mm.mean(axis=0)
    if object_turn_deg > 0.0 and turn_moves_px(samples_mm, obj2cam, intrinsics, object_turn_deg) > _DISTINCT_PX:
        # (a turn that moves no sample further than candidates are told apart by adds none: a small part far off)
        poses, grid = object_turned(poses, grid, centre, object_turn_deg)
    turn_px = max(intrinsics.fu, intrinsics.fv) * np.radians(reach_deg)
    t = np.linspace(-turn_px, turn_px, _TURN_STEPS)
    offsets = np.rint(
        np.stack(np.meshgrid(t, t, indexing="xy"), axis=-1).reshape(-1, 2)
    )  # whole pixels: a chamfer ranking needs no finer
    h, w = distance.shape
    pad = int(np.abs(offsets).max()) + 2
    padded = np.pad(np.asarray(distance, dtype=np.float32), pad, constant_values=TRUNCATE_PX)
    # Each candidate's samples as flat indices in the padded map (H, m): whole pixels, anything outside the image (or
    # behind the camera: NaN) clipped to just outside it, where the padding (wider than any offset) holds the cap. A
    # few thousand candidates at a time (with the object's turns, nine times as many: their points and pixels whole
    # took some 220 MB); only the indices kept, where the pixels were the candidates' largest array and the
    # distinctness check below reads a few hundred of them.
    base = np.empty((len(poses), len(samples_mm)), np.int64)
    for chunk in np.array_split(np.arange(len(poses)), max(1, len(poses) // 2048)):
        px = np.rint(np.nan_to_num(projected(samples_mm, poses[chunk], intrinsics), nan=-1e6).clip(-1e6, 1e6))
        px = px.astype(np.int64)
        base[chunk] = (np.clip(px[..., 1], -1, h) + pad) * padded.shape[1] + np.clip(px[..., 0], -1, w) + pad
    offsets_flat = (offsets[:, 1] * padded.shape[1] + offsets[:, 0]).astype(np.int64)
    flat = padded.ravel()
    # every candidate on a third of the samples, the best few hundred again on all of them (the coarse
    # score only has to keep the right one among those)
    coarse = base[:, : max(10, base.shape[1] // 3)]
    rough = np.concatenate(
        [_scores(flat, chunk, offsets_flat) for chunk in np.array_split(coarse, max(1, len(coarse) // 128))]
    )  # (H, S)
    best = np.argpartition(rough, min(_RESCORED, rough.size) - 1, axis=None)[:_RESCORED]
    rows, cols = np.unravel_index(best, rough.shape)
    cost = np.full(rough.shape, np.inf, dtype=np.float32)
    cost[rows, cols] = flat[base[rows] + offsets_flat[cols][:, None]].mean(axis=1)
    # the unmoved pose wins a tie
    cost[np.flatnonzero((np.abs(grid) < 1e-12).all(axis=1)), len(offsets) // 2] -= 1e-6
    chosen: list[tuple[int, int]] = []
    chosen_seen = np.empty((keep, len(samples_mm), 2))  # where each chosen one puts the samples (keep, m, 2)
    # the rescored ones, least cost first (ties by index, as a stable sort of the whole table: only they are finite)
    order = best[np.lexsort((best, cost.ravel()[best]))][: 50 * keep]
    top_rows, top_cols = np.unravel_index(order, cost.shape)
    top_seen = projected(samples_mm, poses[top_rows], intrinsics) + offsets[top_cols][:, None, :]
    for i, s, seen in zip(top_rows, top_cols, top_seen):
        apart = np.nanmean(np.linalg.norm(seen - chosen_seen[: len(chosen)], axis=2), axis=1)
        if (apart > _DISTINCT_PX).all():
            chosen_seen[len(chosen)] = seen
            chosen.append((int(i), int(s)))
        if len(chosen) == keep:
            break
    return [turned_camera(poses[i], offsets[s], intrinsics) for i, s in chosen]
