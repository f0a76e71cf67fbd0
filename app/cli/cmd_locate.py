"""``videocal locate PHOTO --mesh MESH --intrinsics FILE --prior POSE.json``: a known object's pose in a photo.

Runs Find points and the edge fit (:mod:`calib_core.look.locate`) on one photo of one object and prints the
object's pose in the camera's frame with its 1-sigma as JSON (``R_obj2cam``, ``t_obj2cam_mm``, ``std``,
``status``, the features found; for an ``uncertain`` answer the ``rival`` pose that made it so). ``--overlay OUT.png``
draws the located outline (green), the prior's (red) and the rival's (amber) on the photo. The prior is JSON:
``R_obj2cam`` (3 x 3) and ``t_obj2cam_mm`` (3), as this command prints them, or ``obj2cam`` (4 x 4, mm).
``--features`` is YAML: ``name: [x, y, z]`` in the mesh's units, corners of the object (default: the vertices of a
mesh of at most 64, a box's eight).

Several photos (frames of a recording, one look's photos) are located in one process, from the same prior: the
libraries are loaded once (about 2 s), then each photo takes its own time. The output is then JSON Lines, one object
per photo in the order given, each with its ``photo``, written as soon as it is located; a photo that cannot be read
or does not fit the camera file is a line with its ``error`` (and an ``error:`` line on stderr) and the others go on.
``--overlay`` then names a folder, one ``<photo name>.png`` each.

Exit codes: 0 located (``ok``; every photo), 2 bad input (one ``error:`` line; any photo), 3 not located or
``uncertain`` (another start settled elsewhere on the image; the JSON says why and still gives the pose).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from calib_core.documents import read_json, read_text, parse_yaml
from calib_core.errors import FileFormatError
from calib_core.mesh_units import MESH_SCALE

EXIT_NOT_LOCATED = 3
MAX_FEATURES = 1000


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from calib_core.look.search_reach import REACH_DEG, REACH_MM

    parser.add_argument(
        "photo",
        type=Path,
        nargs="+",
        help="the photo (PNG, JPEG, ...) of the object; several: one JSON line each, from the same prior",
    )
    parser.add_argument("--mesh", type=Path, required=True, help="the object's mesh (STL, OBJ, PLY, DAE, glTF)")
    parser.add_argument(
        "--intrinsics", type=Path, required=True, help="the camera's intrinsics (OpenCV YAML or ROS camera_info YAML)"
    )
    parser.add_argument(
        "--prior",
        type=Path,
        required=True,
        help="JSON: the object's rough pose in the camera frame (R_obj2cam, t_obj2cam_mm)",
    )
    parser.add_argument(
        "--features",
        type=Path,
        help="YAML: name: [x, y, z] corner points in the mesh's units (default: a small mesh's vertices)",
    )
    parser.add_argument(
        "--units",
        choices=sorted(MESH_SCALE, key=MESH_SCALE.get),
        default="mm",
        help="the mesh's and the features' units (default mm)",
    )
    parser.add_argument(
        "--reach-mm",
        type=float,
        default=REACH_MM,
        help=f"how far the prior's position may be off, mm (default {REACH_MM:g})",
    )
    parser.add_argument(
        "--reach-deg",
        type=float,
        default=REACH_DEG,
        help=f"how far the prior may be turned, degrees (default {REACH_DEG:g})",
    )
    parser.add_argument(
        "--overlay",
        type=Path,
        help="write the photo with the located outline (green), the prior's (red) and an uncertain answer's rival "
        "(amber) to this PNG (several photos: a folder of them)",
    )
    parser.add_argument("--indent", type=int, default=2, help="JSON indentation (0 for one line)")


def read_prior(path: Path) -> np.ndarray:
    """The prior pose (4, 4) mm from JSON: ``R_obj2cam`` + ``t_obj2cam_mm``, or ``obj2cam``; the error names the
    field."""
    from calib_core.frames import check_transform, make_transform  # scipy: loaded for a run, not for --help

    data = read_json(path, "prior pose file")
    if not isinstance(data, dict):
        raise FileFormatError(path, "the top level must be a JSON object with R_obj2cam and t_obj2cam_mm (or obj2cam)")
    try:
        if "obj2cam" in data:
            pose = np.asarray(data["obj2cam"], dtype=float).reshape(4, 4)
        else:
            for key in ("R_obj2cam", "t_obj2cam_mm"):
                if data.get(key) is None:
                    raise FileFormatError(path, "required field is missing (or give obj2cam, 4 x 4)", key)
            pose = make_transform(
                np.asarray(data["R_obj2cam"], dtype=float).reshape(3, 3),
                np.asarray(data["t_obj2cam_mm"], dtype=float).reshape(3),
            )
    except (TypeError, ValueError) as exc:
        raise FileFormatError(
            path, f"R_obj2cam must be 3 x 3 and t_obj2cam_mm 3 numbers (or obj2cam 4 x 4): {exc}"
        ) from None
    # a rough prior written by hand (four decimals) is a rotation to a few 1e-4: the nearest rotation is meant
    u, singular, vt = np.linalg.svd(pose[:3, :3]) if np.all(np.isfinite(pose)) else (None, None, None)
    if singular is not None and np.max(np.abs(singular - 1.0)) < 0.01 and np.linalg.det(u @ vt) > 0:
        pose[:3, :3] = u @ vt
    try:
        return check_transform(pose, name="prior")
    except ValueError as exc:
        raise FileFormatError(path, str(exc)) from None


def read_features(path: Path, scale: float) -> dict[str, np.ndarray]:
    """``name: [x, y, z]`` (the mesh's units) -> mm; the error names the feature."""
    data = parse_yaml(read_text(path, "features file", max_bytes=1024 * 1024), path)
    if not isinstance(data, dict) or not data:
        raise FileFormatError(path, "must be a mapping of feature names to [x, y, z]")
    if len(data) > MAX_FEATURES:
        raise FileFormatError(path, f"{len(data)} features; at most {MAX_FEATURES}")
    out = {}
    for name, value in data.items():
        if not (
            isinstance(value, list)
            and len(value) == 3
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        ):
            raise FileFormatError(path, f"must be [x, y, z] numbers, got {value!r}", str(name))
        point = np.asarray(value, dtype=float) * scale
        if not np.all(np.isfinite(point)):
            raise FileFormatError(path, "must be finite numbers", str(name))
        out[str(name)] = point
    return out


def run(args: argparse.Namespace) -> int:
    for name in ("reach_mm", "reach_deg"):
        value = getattr(args, name)
        if not (np.isfinite(value) and 0.0 < value <= (500.0 if name == "reach_mm" else 30.0)):
            raise ValueError(
                f"--{name.replace('_', '-')} must be above 0 and at most {500 if name == 'reach_mm' else 30}, got "
                f"{value:g}"
            )
    several = len(args.photo) > 1
    if several and args.overlay is not None:
        _check_overlay_folder(args.overlay, args.photo)
    locator = _Locator(args)
    try:
        if not several:
            image, result = locator.locate(args.photo[0])
            if args.overlay:
                locator.draw(args.overlay, image, result)
            json.dump(result.to_dict(), sys.stdout, indent=args.indent or None)
            sys.stdout.write("\n")
            return 0 if result.status == "ok" else EXIT_NOT_LOCATED
        worst = 0
        for photo in args.photo:
            try:
                image, result = locator.locate(photo)
            except (FileFormatError, FileNotFoundError, IsADirectoryError, PermissionError) as exc:
                print(f"error: {exc}", file=sys.stderr)
                _write_line({"photo": str(photo), "status": "error", "error": str(exc)})
                worst = 2
                continue
            if args.overlay:
                overlay = args.overlay / f"{photo.stem}.png"
                locator.draw(overlay, image, result)
            _write_line({"photo": str(photo), **result.to_dict()})
            if result.status != "ok" and worst == 0:
                worst = EXIT_NOT_LOCATED
        return worst
    finally:
        locator.close()


class _Locator:
    """The mesh, features and prior read once (a bad one ends the command), then :meth:`locate` photo by photo; the
    camera file is read with the first photo (a file without a size takes that photo's)."""

    def __init__(self, args: argparse.Namespace) -> None:
        from calib_core.mesh_files import load_mesh  # trimesh: loaded for a run, not for --help

        self.args = args
        self.intrinsics = None
        self._view = None
        self._expected = None
        self.mesh = load_mesh(args.mesh, args.units)
        self.features = read_features(args.features, MESH_SCALE[args.units]) if args.features else None
        self.prior = read_prior(args.prior)
        centre = self.prior[:3, :3] @ np.asarray(self.mesh.bounding_box.centroid, dtype=float) + self.prior[:3, 3]
        if not centre[2] > 0.0:
            raise FileFormatError(
                args.prior,
                f"the prior puts the object's centre {centre[2]:.1f} mm in front of the camera: behind it, or in its "
                "plane; the camera looks along +z (OpenCV's axes)",
            )

    def locate(self, photo: Path):
        """(image (h, w[, 3]) uint8, :class:`~calib_core.look.located.Located`) of one photo; a photo that cannot
        be read or is not the camera file's size raises :class:`FileFormatError` naming it."""
        from calib_core.image_files import read_image
        from calib_core.look.locate import locate

        image = read_image(photo)
        if self.intrinsics is None:
            self._open_camera(image)
        if (self.intrinsics.width, self.intrinsics.height) != (image.shape[1], image.shape[0]):
            raise FileFormatError(
                photo,
                f"the photo is {image.shape[1]} x {image.shape[0]} px but {self.args.intrinsics} is for "
                f"{self.intrinsics.width} x {self.intrinsics.height} px",
            )
        result = locate(
            image,
            self.intrinsics,
            self.mesh,
            self.prior,
            features=self.features,
            expected=self._expected,
            reach_mm=self.args.reach_mm,
            reach_deg=self.args.reach_deg,
            name=self.args.mesh.stem,
        )
        return image, result

    def _open_camera(self, image: np.ndarray) -> None:
        from calib_core.camera.intrinsics_io import load_intrinsics
        from calib_core.look.edge_samples import edge_model
        from calib_core.scene import SceneItem

        self.intrinsics = load_intrinsics(self.args.intrinsics, image_size=(image.shape[1], image.shape[0]))
        if edge_model(self.mesh, self.prior, self.intrinsics).from_outline:
            # a scanned mesh: its samples come from its outline, which the model's view always shows (its facets'
            # own edges hold none), so the renderer (a third of the command's memory) is not started
            return
        from calib_core.render.model_view import ModelView

        self._view = ModelView(self.intrinsics)
        # the model's view only says which edges show: the object alone, light on the renderer's black, its faces
        # shaded apart by the light
        item = SceneItem(self.args.mesh.stem, self.mesh, np.eye(4), color=(0.75, 0.75, 0.75))
        self._expected = self._view.of([item], np.eye(4))

    def draw(self, path: Path, image: np.ndarray, result) -> None:
        """The overlay of ``result`` on ``image`` written to ``path`` (:func:`_write_overlay`), a CAD part's creases
        drawn (the part whose model's view was rendered), a scanned mesh's not."""
        _write_overlay(path, image, self.intrinsics, self.mesh, self.prior, result, creases=self._expected is not None)

    def close(self) -> None:
        if self._view is not None:
            self._view.close()


def _check_overlay_folder(folder: Path, photos: list[Path]) -> None:
    """Several photos' overlays go to a folder, one ``<photo name>.png`` each: refused before any work when the name
    is a file's or two photos share a name."""
    if folder.suffix.lower() in (".png", ".jpg", ".jpeg") or folder.is_file():
        raise FileFormatError(folder, "with several photos --overlay names a folder, one <photo name>.png each")
    stems: dict[str, Path] = {}
    for photo in photos:
        if photo.stem in stems and stems[photo.stem] != photo:
            raise FileFormatError(
                photo, f"its overlay would overwrite that of {stems[photo.stem]} (both {photo.stem}.png)"
            )
        stems[photo.stem] = photo


def _write_line(document: dict) -> None:
    sys.stdout.write(json.dumps(document) + "\n")
    sys.stdout.flush()  # a line as each photo is done: progress for whoever reads the stream


def _write_overlay(
    path: Path, image: np.ndarray, intrinsics, mesh, prior: np.ndarray, result, *, creases: bool = True
) -> None:
    """The photo with the object's outline drawn at the prior (red), at the answer (green) and, for an ``uncertain``
    answer, at the rival that made it so (amber), each with its creases when ``creases`` (a CAD part's: a scanned mesh's
    facets meet at every angle, and its creases would be noise), and the features found (blue crosses)."""
    import cv2

    from calib_core.atomic_file import atomic_write_bytes
    from calib_core.camera.projection import project_points
    from calib_core.look.outline import silhouette_mask

    out = cv2.cvtColor(image, cv2.COLOR_RGB2BGR) if image.ndim == 3 else cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    edges = mesh.face_adjacency_edges[mesh.face_adjacency_angles > np.radians(20)] if creases else np.zeros((0, 2), int)
    vertices = np.asarray(mesh.vertices, dtype=float)
    drawn = [("prior", prior, (0, 0, 255)), ("answer", result.obj2cam, (0, 200, 0))]
    if result.rival_obj2cam is not None:
        drawn.append(("rival", result.rival_obj2cam, (0, 170, 255)))
    for _, pose, colour in drawn:
        if pose is None:
            continue
        mask, corner = silhouette_mask(mesh, pose, intrinsics)
        if mask.size:
            outline, _ = cv2.findContours(mask, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE, offset=corner)
            cv2.polylines(out, outline, True, colour, 1, cv2.LINE_AA)
        for a, b in project_points(vertices[edges.reshape(-1)], pose, intrinsics).reshape(-1, 2, 2):
            cv2.line(
                out,
                (int(round(a[0] * 4)), int(round(a[1] * 4))),
                (int(round(b[0] * 4)), int(round(b[1] * 4))),
                colour,
                1,
                cv2.LINE_AA,
                shift=2,
            )
    # which colour is which, in the corner (white under black, readable on any photo)
    for row, (name, pose, colour) in enumerate(d for d in drawn if d[1] is not None):
        at = (8, 18 + 18 * row)
        cv2.putText(out, name, at, cv2.FONT_HERSHEY_SIMPLEX, 0.5, (0, 0, 0), 3, cv2.LINE_AA)
        cv2.putText(out, name, at, cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
    for f in result.features:
        cv2.drawMarker(out, (int(round(f.uv_px[0])), int(round(f.uv_px[1]))), (255, 200, 0), cv2.MARKER_CROSS, 9, 1)
    if path.suffix.lower() not in (".png", ".jpg", ".jpeg"):
        raise FileFormatError(path, "the overlay is written as PNG or JPEG: name it .png or .jpg")
    path.parent.mkdir(parents=True, exist_ok=True)
    # encoded in memory and written by Python: libpng writing to a full disk printed its own line before the error
    encoded, data = cv2.imencode(path.suffix.lower(), out)
    if not encoded:
        raise FileFormatError(path, "could not encode the overlay image")
    atomic_write_bytes(path, data.tobytes())
