"""Intrinsics files: OpenCV FileStorage YAML, ROS ``camera_info`` YAML, a ``sensor_msgs/CameraInfo`` message, and the
plain matrices a script dumps as JSON or YAML (``K`` as rows, ``dist``, ``image_size``).

``load_intrinsics(path)`` tells them apart by their keys; ``save_intrinsics(path,
intrinsics, fmt=...)`` writes either, atomically. Every problem is a
:class:`~calib_core.errors.FileFormatError` naming the file and the field.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

from calib_core.atomic_file import atomic_path, atomic_write_text
from calib_core.camera.intrinsics import DISTORTION_MODELS, MAX_IMAGE_SIDE_PX, Intrinsics
from calib_core.documents import parse_yaml, read_text
from calib_core.errors import FileFormatError

FORMATS = ("opencv", "ros")


def load_intrinsics(path: str | Path, image_size: tuple[int, int] | None = None) -> Intrinsics:
    """Read intrinsics from an OpenCV FileStorage YAML or a ROS camera_info YAML file.

    ``image_size`` (width, height) px: the size of the images they are used with, known from the
    images themselves. A file without ``image_width``/``image_height`` (many OpenCV tools write none)
    takes this size; a file with a size that differs is refused (it is another camera mode)."""
    path = Path(path)
    if path.exists() and not path.is_file():
        raise FileFormatError(path, "not a regular file")
    text = read_text(path, "intrinsics file", max_bytes=1024 * 1024)
    if text.lstrip().startswith("%YAML") or "!!opencv-matrix" in text:
        return _load_opencv(path, image_size)
    # `ros2 topic echo --once` ends its message with a "---" line: the first document is the message.
    lines = text.splitlines()
    while lines and lines[-1].strip() in ("---", "...", ""):
        lines.pop()
    data = parse_yaml("\n".join(lines) + "\n", path)
    if isinstance(data, dict) and "camera_matrix" in data and isinstance(data["camera_matrix"], dict):
        return _load_ros(path, data, image_size)
    if isinstance(data, dict) and ("k" in data or "K" in data) and ("width" in data or "height" in data):
        return _load_camera_info_message(path, data, image_size)
    if isinstance(data, dict) and any(k in data for k in PLAIN_MATRIX_KEYS):
        return _load_plain(path, data, image_size)
    raise FileFormatError(
        path,
        "not an intrinsics file: expected OpenCV FileStorage YAML (camera_matrix as "
        "!!opencv-matrix), ROS camera_info YAML (camera_matrix: {rows, cols, data}), a "
        "sensor_msgs/CameraInfo message as `ros2 topic echo` prints it (k, d, width, height), or plain matrices as "
        "JSON or YAML (K: [[fu, 0, cx], [0, fv, cy], [0, 0, 1]], dist: [k1, k2, p1, p2, k3], image_size: [w, h])",
    )


def save_intrinsics(
    path: str | Path, intrinsics: Intrinsics, fmt: str = "opencv", camera_name: str = "videocal_camera"
) -> None:
    """Write ``intrinsics`` as ``fmt`` ("opencv" or "ros") to ``path``, atomically."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown intrinsics format {fmt!r}; expected one of {', '.join(FORMATS)}")
    path = Path(path)
    if fmt == "opencv":

        def same(tmp: Path) -> None:  # cv2.FileStorage reports no write error: read it back
            back = _load_opencv(tmp)
            if not np.allclose(back.K, intrinsics.K) or (back.width, back.height) != (
                intrinsics.width,
                intrinsics.height,
            ):
                raise ValueError("the written camera matrix or image size differs")

        with atomic_path(path, same) as tmp:
            fs = cv2.FileStorage(str(tmp), cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_FORMAT_YAML)
            fs.write("image_width", intrinsics.width)
            fs.write("image_height", intrinsics.height)
            fs.write("camera_matrix", intrinsics.K)
            fs.write("distortion_coefficients", intrinsics.dist_coeffs.reshape(1, -1))
            if intrinsics.model != "plumb_bob":
                fs.write("distortion_model", intrinsics.model)
            fs.release()
    else:
        atomic_write_text(path, yaml.safe_dump(_ros_dict(intrinsics, camera_name), sort_keys=False))


def _load_opencv(path: Path, image_size: tuple[int, int] | None = None) -> Intrinsics:
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except (cv2.error, SystemError) as exc:  # the binding wraps parse errors in SystemError
        cause = exc.__cause__ or exc
        raise FileFormatError(path, f"OpenCV cannot parse it ({_first_line(cause)})") from None
    try:
        if not fs.isOpened():
            raise FileFormatError(path, "OpenCV cannot open it as FileStorage")
        K = _fs_matrix(fs, path, "camera_matrix", (3, 3))
        dist_node = fs.getNode("distortion_coefficients")
        if dist_node.empty() or dist_node.isNone():
            dist = np.zeros(5)
        else:
            dist = _fs_matrix(fs, path, "distortion_coefficients", None).ravel()
        width = _fs_int(fs, path, "image_width", image_size[0] if image_size else None)
        height = _fs_int(fs, path, "image_height", image_size[1] if image_size else None)
        model_node = fs.getNode("distortion_model")
        model = model_node.string() if not model_node.empty() and model_node.isString() else None
    except cv2.error as exc:  # a node of another shape than the file's kind says (OpenCV asserts)
        raise FileFormatError(
            path, f"not an OpenCV intrinsics file ({_first_line(exc).split('error: ')[-1]})"
        ) from None
    finally:
        fs.release()
    return _build(path, K, dist, width, height, "camera_matrix", "distortion_coefficients", model)


def _fs_matrix(fs: cv2.FileStorage, path: Path, key: str, shape: tuple[int, int] | None) -> np.ndarray:
    node = fs.getNode(key)
    if node.empty() or node.isNone():
        raise FileFormatError(path, "missing", key)
    try:
        m = node.mat()
    except cv2.error:  # rows x cols disagrees with the data: OpenCV asserts
        raise FileFormatError(path, "its rows and cols do not match the number of values in data", key) from None
    if m is None:
        raise FileFormatError(path, "expected an !!opencv-matrix", key)
    m = np.asarray(m, dtype=float)
    if shape is not None and m.shape != shape:
        raise FileFormatError(path, f"expected a {shape[0]}x{shape[1]} matrix, got {m.shape}", key)
    return m


def _image_side(path: Path, key: str, value, from_images: int | None) -> int:
    """The file's ``value`` for an image side (``None``: absent), checked against the images' side."""
    if value is None:
        if from_images is None:
            raise FileFormatError(
                path, "missing (the image size is needed; give the images it is used with, whose size then counts)", key
            )
        return int(from_images)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 < value <= MAX_IMAGE_SIDE_PX:
        raise FileFormatError(
            path, f"expected a whole number of pixels from 1 to {MAX_IMAGE_SIDE_PX}, got {value!r}", key
        )
    if from_images is not None and value != from_images:
        raise FileFormatError(
            path, f"says {value} px, the images are {from_images} px: the file is for another camera mode", key
        )
    return value


def _fs_int(fs: cv2.FileStorage, path: Path, key: str, from_images: int | None = None) -> int:
    node = fs.getNode(key)
    if node.empty() or node.isNone():
        return _image_side(path, key, None, from_images)
    if not node.isInt() or not 0 < node.real() <= MAX_IMAGE_SIDE_PX:
        raise FileFormatError(path, f"expected a whole number of pixels from 1 to {MAX_IMAGE_SIDE_PX}", key)
    return _image_side(path, key, int(node.real()), from_images)


def _load_ros(path: Path, data: dict, image_size: tuple[int, int] | None = None) -> Intrinsics:
    known = {
        "image_width",
        "image_height",
        "camera_name",
        "camera_matrix",
        "distortion_model",
        "distortion_coefficients",
        "rectification_matrix",
        "projection_matrix",
    }
    unknown = sorted(set(data) - known)
    if unknown:
        raise FileFormatError(path, f"unknown key(s) for a ROS camera_info file: {', '.join(unknown)}")
    width = _image_side(path, "image_width", data.get("image_width"), image_size[0] if image_size else None)
    height = _image_side(path, "image_height", data.get("image_height"), image_size[1] if image_size else None)
    model = _model_field(path, data.get("distortion_model") or "plumb_bob")
    K = _ros_matrix(path, data, "camera_matrix", 9).reshape(3, 3)
    dist = (
        _ros_matrix(path, data, "distortion_coefficients", None) if "distortion_coefficients" in data else np.zeros(0)
    )
    return _build(path, K, dist, width, height, "camera_matrix", "distortion_coefficients", model)


def _load_camera_info_message(path: Path, data: dict, image_size: tuple[int, int] | None = None) -> Intrinsics:
    """A ``sensor_msgs/CameraInfo`` message as YAML: ROS 2's lower-case fields (``k``, ``d``) or ROS 1's (``K``,
    ``D``)."""

    def field(name: str):
        return data.get(name, data.get(name.upper()))

    known = {
        "header",
        "height",
        "width",
        "distortion_model",
        "d",
        "k",
        "r",
        "p",
        "binning_x",
        "binning_y",
        "roi",
        "D",
        "K",
        "R",
        "P",
    }
    unknown = sorted(set(map(str, data)) - known)
    if unknown:
        raise FileFormatError(path, f"unknown key(s) for a CameraInfo message: {', '.join(unknown)}")
    width = _image_side(path, "width", data.get("width") or None, image_size[0] if image_size else None)
    height = _image_side(path, "height", data.get("height") or None, image_size[1] if image_size else None)
    model = _model_field(path, data.get("distortion_model") or "plumb_bob")
    values = {}
    for name, size in (("k", 9), ("d", None)):
        v = field(name)
        if v is None and name == "d":
            v = []
        if (
            not isinstance(v, list)
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
            or (size and len(v) != size)
        ):
            raise FileFormatError(path, f"must be a list of {size or 'the distortion'} numbers, got {v!r}", name)
        values[name] = np.asarray(v, dtype=float)
    return _build(path, values["k"].reshape(3, 3), values["d"], width, height, "k", "d", model)


PLAIN_MATRIX_KEYS = ("K", "camera_matrix", "cameraMatrix", "mtx")
"""The names scripts give the camera matrix when they dump it as plain rows (``json.dump(K.tolist())``)."""
PLAIN_DISTORTION_KEYS = ("dist", "D", "dist_coeffs", "distCoeffs", "distortion", "distortion_coefficients")


def _load_plain(path: Path, data: dict, image_size: tuple[int, int] | None = None) -> Intrinsics:
    """Plain matrices as a calibration script dumps them (JSON or YAML): the camera matrix as three rows or nine
    numbers under one of :data:`PLAIN_MATRIX_KEYS`, the distortion (a flat or nested list, absent: none) under one of
    :data:`PLAIN_DISTORTION_KEYS`, the size as ``image_size: [width, height]`` or ``width``/``height`` (absent: the
    images' own). Other keys (a script's RMS, a note) are left alone."""

    def numbers(key: str, value) -> np.ndarray:
        flat = np.asarray(value, dtype=object).ravel() if isinstance(value, list) else None
        if flat is None or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in flat):
            raise FileFormatError(path, f"must be a list of numbers (or of rows of numbers), got {value!r}", key)
        return flat.astype(float)

    k_key = next(k for k in PLAIN_MATRIX_KEYS if k in data)
    K = numbers(k_key, data[k_key])
    if K.size != 9:
        raise FileFormatError(path, f"a camera matrix has 9 numbers (3 rows of 3), got {K.size}", k_key)
    d_key = next((k for k in PLAIN_DISTORTION_KEYS if k in data), None)
    dist = numbers(d_key, data[d_key]) if d_key is not None else np.zeros(0)
    size = data.get("image_size")
    if size is not None:
        if not isinstance(size, list) or len(size) != 2:
            raise FileFormatError(path, f"must be [width, height], got {size!r}", "image_size")
        w_value, h_value, w_key, h_key = size[0], size[1], "image_size[0]", "image_size[1]"
    elif any(k in data for k in ("width", "height", "image_width", "image_height")):
        w_key = "width" if "width" in data else "image_width"
        h_key = "height" if "height" in data else "image_height"
        w_value, h_value = data.get(w_key), data.get(h_key)
    else:
        w_value = h_value = None
        w_key = h_key = "image_size"
    width = _image_side(path, w_key, w_value, image_size[0] if image_size else None)
    height = _image_side(path, h_key, h_value, image_size[1] if image_size else None)
    model = _model_field(path, data["distortion_model"]) if "distortion_model" in data else None
    return _build(path, K.reshape(3, 3), dist, width, height, k_key, d_key or "dist", model)


def _ros_matrix(path: Path, data: dict, key: str, size: int | None) -> np.ndarray:
    node = data.get(key)
    if not isinstance(node, dict) or "data" not in node:
        raise FileFormatError(path, "expected {rows, cols, data}", key)
    values = node["data"]
    if not isinstance(values, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise FileFormatError(path, "data must be a list of numbers", f"{key}.data")
    if size is not None and len(values) != size:
        raise FileFormatError(path, f"expected {size} numbers, got {len(values)}", f"{key}.data")
    rows, cols = node.get("rows"), node.get("cols")
    for name, v in (("rows", rows), ("cols", cols)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v <= 0):
            raise FileFormatError(path, f"must be a positive whole number, got {v!r}", f"{key}.{name}")
    if rows is not None and cols is not None and rows * cols != len(values):
        raise FileFormatError(path, f"rows x cols = {rows} x {cols} does not match {len(values)} numbers", key)
    return np.asarray(values, dtype=float)


def _model_field(path: Path, model) -> str:
    if not isinstance(model, str) or model not in DISTORTION_MODELS:  # a list or a mapping is not a model's name
        raise FileFormatError(
            path,
            f"unsupported distortion model {model!r}; videocal reads {', '.join(DISTORTION_MODELS)}",
            "distortion_model",
        )
    return str(model)


def _coefficients(path: Path, dist: np.ndarray, model: str | None, d_field: str) -> tuple[str, tuple[float, ...]]:
    """``(model, coefficients)`` of a file's distortion: as its ``model`` says (``plumb_bob`` takes 4 or 5 values, and
    an all-zero list of any length; ``rational_polynomial`` 8; ``equidistant`` 4); a file naming no model (OpenCV's)
    is ``plumb_bob`` with 4 or 5 values, ``rational_polynomial`` with 8 (``plumb_bob`` when k4..k6 are zero)."""
    n = dist.size
    if not np.all(np.isfinite(dist)):
        raise FileFormatError(path, "the distortion contains NaN or infinite values", d_field)
    if model is None:
        model = "rational_polynomial" if n == 8 and np.any(dist[5:] != 0) else "plumb_bob"
    if not np.any(dist) and model != "equidistant":  # no distortion, however many zeros were written
        return model, (0.0,) * len(DISTORTION_MODELS[model])
    names = DISTORTION_MODELS[model]
    if model == "plumb_bob" and n in (4, 5, 8) and not np.any(dist[5:]):
        return model, tuple(np.r_[dist[:5], np.zeros(5 - min(n, 5))])
    if n != len(names):
        raise FileFormatError(
            path, f"a {model} lens has {len(names)} coefficients ({' '.join(names)}), the file gives {n}", d_field
        )
    return model, tuple(float(v) for v in dist)


def _build(
    path: Path,
    K: np.ndarray,
    dist: np.ndarray,
    width: int,
    height: int,
    k_field: str,
    d_field: str,
    model: str | None = None,
) -> Intrinsics:
    if not np.all(np.isfinite(K)):
        raise FileFormatError(path, "contains NaN or infinite values", k_field)
    if abs(K[0, 1]) > 1e-9 or np.any(np.abs(K[2] - [0, 0, 1]) > 1e-9) or abs(K[1, 0]) > 1e-9:
        raise FileFormatError(
            path, "not a pinhole camera matrix [[fu,0,cx],[0,fv,cy],[0,0,1]] (skew is not supported)", k_field
        )
    model, coefficients = _coefficients(path, np.asarray(dist, dtype=float).ravel(), model, d_field)
    try:
        return Intrinsics(K[0, 0], K[1, 1], K[0, 2], K[1, 2], width, height, coefficients, model)
    except ValueError as exc:
        raise FileFormatError(path, str(exc).removeprefix("intrinsics: "), k_field) from None


def _ros_dict(intr: Intrinsics, camera_name: str) -> dict:
    P = np.zeros((3, 4))
    P[:, :3] = intr.K
    return {
        "image_width": intr.width,
        "image_height": intr.height,
        "camera_name": camera_name,
        "camera_matrix": {"rows": 3, "cols": 3, "data": [float(v) for v in intr.K.ravel()]},
        "distortion_model": intr.model,
        "distortion_coefficients": {
            "rows": 1,
            "cols": len(intr.distortion),
            "data": [float(v) for v in intr.distortion],
        },
        "rectification_matrix": {"rows": 3, "cols": 3, "data": [float(v) for v in np.eye(3).ravel()]},
        "projection_matrix": {"rows": 3, "cols": 4, "data": [float(v) for v in P.ravel()]},
    }


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
