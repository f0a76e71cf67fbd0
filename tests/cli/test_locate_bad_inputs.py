"""``videocal locate`` given inputs that are no use, as a user runs it: each one line naming the file, no traceback,
nothing half-written."""

from __future__ import annotations

import json
import resource
from pathlib import Path

from tests.cli.refused_runs import limits, refused, videocal


def _locate_inputs(folder: Path, photo) -> None:
    """``box.stl`` (100 x 80 x 60 mm), ``photo.png`` (``photo``, RGB), ``camera.yaml`` (640 x 480, 600 px focal) and
    ``ahead.json`` (the box 500 mm ahead) in ``folder``: what ``locate`` reads."""
    import cv2
    import trimesh

    from calib_core.camera.intrinsics import Intrinsics
    from calib_core.camera.intrinsics_io import save_intrinsics

    trimesh.creation.box([100.0, 80.0, 60.0]).export(folder / "box.stl")
    cv2.imwrite(str(folder / "photo.png"), photo[:, :, ::-1])
    save_intrinsics(folder / "camera.yaml", Intrinsics(600.0, 600.0, 320.0, 240.0, 640, 480))
    (folder / "ahead.json").write_text(
        json.dumps({"obj2cam": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 500], [0, 0, 0, 1]]})
    )


def _locate(folder: Path, mesh: str = "box.stl", prior: str = "ahead.json", *more, **run_options):
    """``videocal locate`` on ``folder``'s inputs (:func:`_locate_inputs`), with ``mesh`` and ``prior`` by name."""
    return videocal(
        "locate",
        folder / "photo.png",
        "--mesh",
        folder / mesh,
        "--intrinsics",
        folder / "camera.yaml",
        "--prior",
        folder / prior,
        *more,
        **run_options,
    )


def test_locate_names_a_mesh_with_a_non_finite_vertex_and_a_prior_behind_the_camera(tmp_path):
    """A NaN vertex was dropped by trimesh's processing without a word (and locate then said "give a prior nearer the
    object"); a prior behind the camera ended in "cannot convert float NaN to integer"."""
    import numpy as np
    import trimesh

    box = trimesh.creation.box([100.0, 80.0, 60.0])
    vertices = box.vertices.copy()
    vertices[3] = [np.nan, 0.0, 0.0]
    trimesh.Trimesh(vertices, box.faces, process=False).export(tmp_path / "nan.stl")
    _locate_inputs(tmp_path, np.zeros((480, 640, 3), np.uint8))
    (tmp_path / "behind.json").write_text(
        json.dumps({"obj2cam": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -500], [0, 0, 0, 1]]})
    )
    refused(
        _locate(tmp_path, mesh="nan.stl"),
        "nan.stl",
        "not finite",
    )
    refused(
        _locate(tmp_path, prior="behind.json"),
        "behind.json",
        "behind it",
    )


def test_locate_overlay_on_a_full_disk_is_one_line_and_leaves_no_file(tmp_path):
    """libpng, writing the overlay to a full disk, printed its own "libpng error" line before videocal's error."""
    import numpy as np

    def small_files() -> None:
        import signal

        limits()
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG, as on a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))  # the noisy photo's overlay is larger

    _locate_inputs(tmp_path, np.random.default_rng(1).integers(0, 255, (480, 640, 3), dtype=np.uint8))
    run = _locate(tmp_path, "box.stl", "ahead.json", "--overlay", tmp_path / "out" / "overlay.png", preexec=small_files)
    assert "libpng" not in run.stderr, run.stderr
    refused(run, "overlay.png", "not written")
    assert list((tmp_path / "out").iterdir()) == []
