"""The look on a real photograph with its truth: one LM-O image (a Kinect's, clutter and occlusion) and two of its
scanned objects. Fails when the look gets worse on it; the whole data set is measured by bench/real_photos.py."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from bench.photo_priors import moved_prior
from bench.real_views import view_prior  # the bench's priors, drawn the same way
from calib_core.datasets.bop import BopDataset
from calib_core.datasets.pose_errors import mspd
from calib_core.mesh_files import load_mesh
from calib_core.look.locate import locate

LMO = Path(__file__).resolve().parents[2] / "data" / "third_party" / "lmo"


@pytest.mark.parametrize("obj_id", [1, 6])
def test_a_real_photo_gives_the_object_within_5_px_from_a_robots_error(obj_id):
    """From 10 mm and 3 deg off (a robot model's error), the ape and the cat of LM-O's photo 415 are `ok` and within
    MSPD 5 px of their truth (2.5 and 4.2 px when this was written; the truth itself is good to a few pixels), and
    their stated points' 1-sigma says so."""
    dataset = BopDataset(LMO, "test")
    (view,) = [v for v in dataset.views() if v.obj_id == obj_id]
    info = dataset.models()[obj_id]
    mesh = load_mesh(info.path)
    image = np.ascontiguousarray(cv2.imread(str(view.image_path), cv2.IMREAD_COLOR)[:, :, ::-1])
    prior = view_prior(view, 10.0, 3.0)
    located = locate(image, view.intrinsics, mesh, prior, reach_mm=10.0, reach_deg=3.0, features={})
    points = np.asarray(mesh.vertices)[:: max(1, len(mesh.vertices) // 2000)]
    error_px = mspd(located.obj2cam, view.obj2cam, points, info.symmetries, view.intrinsics)
    assert located.status == "ok", located.message
    assert error_px < 5.0
    assert 0.3 < located.points_sigma_px < 5.0
    assert located.to_dict()["points_sigma_px"] == pytest.approx(located.points_sigma_px, abs=1e-3)


def _ape_at_half_size():
    """LM-O's ape in the slice's photo at half size: ``(view, model info, mesh, half-size intrinsics, RGB image)``."""
    dataset = BopDataset(LMO, "test")
    (view,) = [v for v in dataset.views() if v.obj_id == 1]
    info = dataset.models()[1]
    half = view.intrinsics.scaled(0.5)
    image = cv2.imread(str(view.image_path), cv2.IMREAD_COLOR)[:, :, ::-1]
    image = np.ascontiguousarray(cv2.resize(image, (half.width, half.height), interpolation=cv2.INTER_AREA))
    return view, info, load_mesh(info.path), half, image


def test_a_small_object_on_a_photo_is_looked_for_however_few_edges_show():
    """The photo at half size: the ape's outline is 23 samples (3 px apart), fewer than the window takes to say a target
    is not in view in the model's view of the cell (hidden by other parts). A photograph has no such view: the ape is
    looked for, and found, not sent back with "Go to task" (LM-O's view 126 of the ape, 96 % in sight, was so)."""
    from calib_core.look.edge_samples import edge_points
    from calib_core.look.in_view import MIN_SHOWN_SAMPLES

    view, info, mesh, half, image = _ape_at_half_size()
    assert len(edge_points(mesh, view.obj2cam, half)[0]) < MIN_SHOWN_SAMPLES
    located = locate(image, half, mesh, view_prior(view, 10.0, 3.0), reach_mm=10.0, reach_deg=3.0, features={})
    assert located.status == "ok", located.message
    points = np.asarray(mesh.vertices)[:: max(1, len(mesh.vertices) // 2000)]
    assert mspd(located.obj2cam, view.obj2cam, points, info.symmetries, half) < 5.0


def test_videocal_locate_looks_for_a_small_object_too(tmp_path):
    """The same half-size photo through ``videocal locate``, which renders the object alone to see which of its edges
    show: nothing hides it there, so however few samples show it is looked for (it said "not in the camera's view")."""
    import json
    import subprocess
    import sys

    from calib_core.camera.intrinsics_io import save_intrinsics

    view, info, _, half, image = _ape_at_half_size()
    cv2.imwrite(str(tmp_path / "half.png"), image[:, :, ::-1])
    save_intrinsics(tmp_path / "half.yaml", half)
    prior = view_prior(view, 10.0, 3.0)
    (tmp_path / "prior.json").write_text(
        json.dumps({"R_obj2cam": prior[:3, :3].tolist(), "t_obj2cam_mm": prior[:3, 3].tolist()})
    )
    args = ["locate", tmp_path / "half.png", "--mesh", info.path, "--intrinsics", tmp_path / "half.yaml"]
    args += ["--prior", tmp_path / "prior.json", "--reach-mm", "10", "--reach-deg", "3"]
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", *map(str, args)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-2000:]
    answer = json.loads(run.stdout)
    assert answer["status"] == "ok", answer["message"]


def test_a_look_reads_the_photo_once(monkeypatch):
    """Every start of a look (the prior, starts round it and nearer and further, at full and at half size) shares one
    image evidence: one Canny pass and one gradient a pyramid level, where each start made its own (ten Canny and
    five gradient passes a photo)."""
    from calib_core.look import colour_contrast

    calls = {"edges": 0, "gradient": 0}
    edges, gradient = colour_contrast.edges, colour_contrast.gradient_magnitude

    def counted(name, fn):
        def wrapper(*args, **kwargs):
            calls[name] += 1
            return fn(*args, **kwargs)

        return wrapper

    monkeypatch.setattr(colour_contrast, "edges", counted("edges", edges))
    monkeypatch.setattr(colour_contrast, "gradient_magnitude", counted("gradient", gradient))
    dataset = BopDataset(LMO, "test")
    (view,) = [v for v in dataset.views() if v.obj_id == 6]
    mesh = load_mesh(dataset.models()[6].path)
    image = np.ascontiguousarray(cv2.imread(str(view.image_path), cv2.IMREAD_COLOR)[:, :, ::-1])
    prior = moved_prior(view.obj2cam, 30.0, 10.0, np.random.default_rng(7))
    located = locate(image, view.intrinsics, mesh, prior, reach_mm=30.0, reach_deg=10.0, features={})
    assert located.edge_samples > 0, located.message  # the fits ran
    assert calls["edges"] == 1 and calls["gradient"] <= 2, calls


def test_a_white_bottle_before_a_white_drill_is_not_called_ok_where_it_is_not():
    """LM-O's glue (a white bottle, symmetric) in photo 571, 81 % in sight in front of the white drill, from 30 mm /
    10 deg off (the real-photo bench's prior for this view, drawn the same way): from a ranked start the fine fit
    settled on the drill's edges 28 px off the bottle, every start that settled agreed with it, and the look said `ok`.
    From the ranked starts coarse to fine, one reaches the bottle and the look says it cannot choose. An `ok` must be
    right: within 10 px (MSPD, up to the bottle's symmetry)."""
    import zlib

    dataset = BopDataset(LMO, "test")
    (view,) = [v for v in dataset.views() if v.obj_id == 11]
    info = dataset.models()[11]
    mesh = load_mesh(info.path)
    image = np.ascontiguousarray(cv2.imread(str(view.image_path), cv2.IMREAD_COLOR)[:, :, ::-1])
    seed = zlib.crc32(b"lmo_dev/test/000002/000571/6/30")  # the bench's key for this view and distance
    prior = moved_prior(view.obj2cam, 30.0, 10.0, np.random.default_rng(seed))
    located = locate(image, view.intrinsics, mesh, prior, reach_mm=30.0, reach_deg=10.0, features={})
    assert located.obj2cam is not None, located.message  # it settled somewhere: the verdict is what is tested
    points = np.asarray(mesh.vertices)[:: max(1, len(mesh.vertices) // 2000)]
    error_px = mspd(located.obj2cam, view.obj2cam, points, info.symmetries, view.intrinsics)
    assert located.status != "ok" or error_px <= 10.0, (located.status, error_px, located.message)
