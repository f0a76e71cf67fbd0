"""Data sets in the BOP format (the Benchmark for 6D Object Pose estimation: T-LESS, ITODD, HOPE, YCB-V, LM, ...),
read as the BOP toolkit reads them.

A data set is a folder with ``models[_TYPE]/`` (``obj_NNNNNN.ply`` in mm and ``models_info.json``: each object's
diameter and symmetries) and one folder per split (``test``, ``test_primesense``, ``val``, ...) holding one folder
per scene: ``rgb/`` or ``gray/`` images named by image id (six digits), ``scene_camera.json`` (per image: ``cam_K``,
the 3 x 3 camera matrix row by row, px), ``scene_gt.json`` (per image: a list of ``obj_id`` with ``cam_R_m2c``,
row by row, and ``cam_t_m2c`` in mm: the model's frame to the camera's, OpenCV axes) and ``scene_gt_info.json``
(per annotation, in the same order: ``visib_fract``, the share of the object's silhouette not hidden by others).
BOP's images are undistorted: the camera is ``cam_K`` alone.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import FileFormatError

IMAGE_FOLDERS = ("rgb", "gray")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


@dataclass(frozen=True)
class ModelInfo:
    """One object of a data set: ``obj_id``, its mesh ``path`` (mm), ``diameter_mm`` (the largest distance between
    two of its points) and ``symmetries`` (k, 4, 4): every pose of the model that looks the same, the identity first,
    continuous symmetries sampled as the BOP toolkit samples them for scoring."""

    obj_id: int
    path: Path
    diameter_mm: float
    symmetries: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class ObjectView:
    """One annotated object in one image: where (``split``, ``scene_id``, ``im_id``, the annotation's index
    ``gt_index``), the image's file, the camera, the truth ``obj2cam`` (4, 4, mm) and ``visib_fract`` (0-1; None
    where the data set gives no scene_gt_info.json)."""

    dataset: str
    split: str
    scene_id: int
    im_id: int
    gt_index: int
    obj_id: int
    image_path: Path
    intrinsics: Intrinsics
    obj2cam: np.ndarray = field(repr=False)
    visib_fract: float | None

    @property
    def key(self) -> str:
        """``dataset/split/scene/image/annotation``, as the bench's rows name a view."""
        return f"{self.dataset}/{self.split}/{self.scene_id:06d}/{self.im_id:06d}/{self.gt_index}"


def read_json(path: Path) -> dict:
    """A JSON object from ``path``; a missing or malformed file is a :class:`FileFormatError` naming it."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except FileNotFoundError as e:
        raise FileFormatError(path, "not found") from e
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise FileFormatError(path, f"not readable as JSON ({e})") from e
    if not isinstance(data, dict):
        raise FileFormatError(path, "expected a JSON object keyed by id")
    return data


def _numbers(path: Path, where: str, value, count: int) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError) as e:
        raise FileFormatError(path, f"expected {count} numbers", where) from e
    if a.size != count or not np.all(np.isfinite(a)):
        raise FileFormatError(path, f"expected {count} finite numbers, got {a.size}", where)
    return a


def symmetry_transforms(
    info: dict, *, path: Path | None = None, where: str = "", max_step_rad: float = 0.01
) -> np.ndarray:
    """The poses (k, 4, 4) under which an object of BOP's ``models_info`` entry ``info`` looks the same: the
    identity, each of ``symmetries_discrete`` (4 x 4 row by row, mm), and each of those composed with turns about
    each of ``symmetries_continuous`` (``axis``, ``offset`` mm) in ``ceil(pi / max_step_rad)`` equal steps (the
    toolkit's sampling: a point at the object's diameter moves at most ``max_step_rad`` x diameter a step)."""
    src = path or Path("models_info.json")
    discrete = [np.eye(4)]
    for k, sym in enumerate(info.get("symmetries_discrete", []) or []):
        discrete.append(_numbers(src, f"{where}.symmetries_discrete[{k}]", sym, 16).reshape(4, 4))
    turns = [np.eye(4)]
    for k, sym in enumerate(info.get("symmetries_continuous", []) or []):
        if not isinstance(sym, dict):
            raise FileFormatError(src, "expected an object with axis and offset", f"{where}.symmetries_continuous[{k}]")
        axis = _numbers(src, f"{where}.symmetries_continuous[{k}].axis", sym.get("axis"), 3)
        offset = _numbers(src, f"{where}.symmetries_continuous[{k}].offset", sym.get("offset", [0, 0, 0]), 3)
        norm = float(np.linalg.norm(axis))
        if norm == 0:
            raise FileFormatError(src, "the axis is zero", f"{where}.symmetries_continuous[{k}].axis")
        steps = int(np.ceil(np.pi / max_step_rad))
        from scipy.spatial.transform import Rotation

        for i in range(1, steps):
            T = np.eye(4)
            T[:3, :3] = Rotation.from_rotvec(axis / norm * (2.0 * np.pi * i / steps)).as_matrix()
            T[:3, 3] = offset - T[:3, :3] @ offset  # a turn about the axis through ``offset``
            turns.append(T)
    return np.array([t @ d for d in discrete for t in turns])


class BopDataset:
    """A BOP data set at ``root`` (its folder name is the data set's name unless ``name`` is given), the models in
    ``models_folder`` (``models``; T-LESS also has ``models_cad``), the images of ``split``."""

    def __init__(
        self, root: str | Path, split: str = "test", *, models_folder: str = "models", name: str | None = None
    ):
        self.root = Path(root)
        self.split = split
        self.name = name or self.root.name
        self.models_dir = self.root / models_folder
        if not (self.root / split).is_dir():
            raise FileFormatError(
                self.root / split,
                f"no split {split!r} in the data set (folders: "
                f"{', '.join(sorted(p.name for p in self.root.iterdir() if p.is_dir())) or 'none'})",
            )
        self._models: dict[int, ModelInfo] | None = None

    def models(self) -> dict[int, ModelInfo]:
        """Every object by id, from ``models_info.json``."""
        if self._models is None:
            path = self.models_dir / "models_info.json"
            info = read_json(path)
            models = {}
            for key, entry in info.items():
                where = f"{key}"
                try:
                    obj_id = int(key)
                except ValueError as e:
                    raise FileFormatError(path, "an object id must be a whole number", where) from e
                if not isinstance(entry, dict) or "diameter" not in entry:
                    raise FileFormatError(path, "expected an object with a diameter", where)
                diameter = float(_numbers(path, f"{where}.diameter", entry["diameter"], 1)[0])
                models[obj_id] = ModelInfo(
                    obj_id,
                    self.models_dir / f"obj_{obj_id:06d}.ply",
                    diameter,
                    symmetry_transforms(entry, path=path, where=where),
                )
            self._models = models
        return self._models

    def scene_ids(self) -> list[int]:
        """The split's scenes, by id."""
        return sorted(int(p.name) for p in (self.root / self.split).iterdir() if p.is_dir() and p.name.isdigit())

    def views(
        self, *, min_visible: float = 0.0, scene_ids: list[int] | None = None, obj_ids: set[int] | None = None
    ) -> Iterator[ObjectView]:
        """Every annotated object of the split with at least ``min_visible`` of it in sight, scene by scene and
        image by image in id order."""
        for scene_id in scene_ids if scene_ids is not None else self.scene_ids():
            folder = self.root / self.split / f"{scene_id:06d}"
            cameras = read_json(folder / "scene_camera.json")
            truth = read_json(folder / "scene_gt.json")
            info_path = folder / "scene_gt_info.json"
            infos = read_json(info_path) if info_path.exists() else {}
            for key in sorted(truth, key=lambda k: int(k)):
                im_id = int(key)
                camera = cameras.get(key)
                if camera is None:
                    raise FileFormatError(folder / "scene_camera.json", "no camera for this image", key)
                K = _numbers(folder / "scene_camera.json", f"{key}.cam_K", camera.get("cam_K"), 9).reshape(3, 3)
                image = _image_file(folder, im_id)
                intrinsics = None
                for index, gt in enumerate(truth[key]):
                    obj_id = int(gt["obj_id"])
                    if obj_ids is not None and obj_id not in obj_ids:
                        continue
                    visible = None
                    if key in infos and index < len(infos[key]):
                        visible = float(infos[key][index].get("visib_fract", 0.0))
                    if visible is not None and visible < min_visible:
                        continue
                    if intrinsics is None:
                        intrinsics = _intrinsics(K, image)
                    where = f"{key}[{index}]"
                    T = np.eye(4)
                    T[:3, :3] = _rotation(
                        folder / "scene_gt.json",
                        f"{where}.cam_R_m2c",
                        _numbers(folder / "scene_gt.json", f"{where}.cam_R_m2c", gt.get("cam_R_m2c"), 9),
                    )
                    T[:3, 3] = _numbers(folder / "scene_gt.json", f"{where}.cam_t_m2c", gt.get("cam_t_m2c"), 3)
                    yield ObjectView(
                        self.name, self.split, scene_id, im_id, index, obj_id, image, intrinsics, T, visible
                    )


ROTATION_TOLERANCE = 0.02
"""How far from orthonormal (the largest element of R R^T - I) a stored rotation may be before it is no rotation:
LM-O's annotations are off by up to 0.0096 (a median 0.0002), and are scored at the nearest rotation."""


def _rotation(path: Path, where: str, numbers: np.ndarray) -> np.ndarray:
    """The nearest rotation (3, 3) to ``numbers`` (9,) row by row, rounded as files round them; a matrix that is not
    a rotation is a :class:`FileFormatError` naming the field."""
    R = numbers.reshape(3, 3)
    if np.abs(R @ R.T - np.eye(3)).max() > ROTATION_TOLERANCE or np.linalg.det(R) <= 0:
        raise FileFormatError(path, "not a rotation (its rows are not orthonormal, or it mirrors)", where)
    u, _, vt = np.linalg.svd(R)
    return u @ vt


def _image_file(scene: Path, im_id: int) -> Path:
    for folder in IMAGE_FOLDERS:
        for suffix in IMAGE_SUFFIXES:
            path = scene / folder / f"{im_id:06d}{suffix}"
            if path.exists():
                return path
    raise FileFormatError(scene / "rgb" / f"{im_id:06d}.png", "no image of this id in rgb/ or gray/")


def _intrinsics(K: np.ndarray, image: Path) -> Intrinsics:
    """A pinhole camera from ``cam_K`` at the image's own size (read from its header)."""
    import cv2

    size = _image_size(image)
    if size is None:
        picture = cv2.imread(str(image), cv2.IMREAD_UNCHANGED)
        if picture is None:
            raise FileFormatError(image, "not a readable image")
        size = (picture.shape[1], picture.shape[0])
    return Intrinsics(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(size[0]), int(size[1]))


def _image_size(path: Path) -> tuple[int, int] | None:
    """(width, height) of a PNG from its header, without decoding it; None for other kinds."""
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] == b"\x89PNG\r\n\x1a\n":
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    return None
