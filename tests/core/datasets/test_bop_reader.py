"""The BOP-format reader on a data set written in the BOP toolkit's layout (its JSON as the toolkit writes it:
ids as strings, matrices row by row, mm), and ``locate`` on it: a smooth, creaseless object (a scanned mesh's
kind) on a textured background, rendered by videocal's renderer, started from the truth moved 10 mm / 3 deg.
(A render, not a photograph: real photographs are measured in bench/real_photos.py.)"""

from __future__ import annotations

import json

import cv2
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.datasets.bop import BopDataset
from calib_core.datasets.pose_errors import mspd
from calib_core.errors import FileFormatError
from calib_core.look.edge_samples import edge_points
from calib_core.look.locate import locate

K = Intrinsics(572.4, 573.6, 325.3, 242.0, 640, 480)


def scanned_blob() -> trimesh.Trimesh:
    """A smooth 10k-vertex object with no crease (as BOP's scanned models are), not symmetric."""
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=40.0)
    v = sphere.vertices * [1.2, 0.7, 1.6]
    v = v + 6.0 * np.sin(v[:, [1]] / 15.0)
    return trimesh.Trimesh(v, sphere.faces, process=False)


def _render(mesh, obj2cam, seed=0):
    from calib_core.render.renderer import RenderOptions, SceneRenderer
    from calib_core.scene import SceneItem

    renderer = SceneRenderer(K.width, K.height)
    try:
        renderer.set_items([SceneItem("obj", mesh, obj2cam, color=(0.8, 0.5, 0.3))])
        rgba = renderer.render_view(K, np.eye(4), RenderOptions(transparent_background=True, show_edges=False))
    finally:
        renderer.close()
    rng = np.random.default_rng(seed)
    background = cv2.resize(
        rng.uniform(0, 255, (12, 16, 3)).astype(np.uint8), (K.width, K.height), interpolation=cv2.INTER_CUBIC
    )
    alpha = rgba[:, :, 3:4] / 255.0
    image = rgba[:, :, :3] * alpha + background * (1 - alpha) + rng.normal(0, 3, background.shape)
    return np.clip(image, 0, 255).astype(np.uint8)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("bop") / "blob"
    (root / "models").mkdir(parents=True)
    mesh = scanned_blob()
    mesh.export(root / "models" / "obj_000003.ply")
    (root / "models" / "models_info.json").write_text(json.dumps({"3": {"diameter": 140.0, "min_x": -48.0}}))
    scene = root / "test" / "000007"
    (scene / "rgb").mkdir(parents=True)
    truths = {}
    for im_id, (euler, t) in enumerate([([20, -30, 10], [15, -10, 650]), ([-10, 40, 70], [-30, 20, 700])]):
        T = np.eye(4)
        T[:3, :3] = Rotation.from_euler("xyz", euler, degrees=True).as_matrix()
        T[:3, 3] = t
        truths[im_id] = T
        cv2.imwrite(str(scene / "rgb" / f"{im_id:06d}.png"), _render(mesh, T, im_id)[:, :, ::-1])
    K9 = [K.fu, 0.0, K.cx, 0.0, K.fv, K.cy, 0.0, 0.0, 1.0]
    (scene / "scene_camera.json").write_text(json.dumps({str(i): {"cam_K": K9, "depth_scale": 0.1} for i in truths}))
    (scene / "scene_gt.json").write_text(
        json.dumps(
            {
                str(i): [{"cam_R_m2c": T[:3, :3].reshape(-1).tolist(), "cam_t_m2c": T[:3, 3].tolist(), "obj_id": 3}]
                for i, T in truths.items()
            }
        )
    )
    (scene / "scene_gt_info.json").write_text(json.dumps({"0": [{"visib_fract": 0.93}], "1": [{"visib_fract": 0.31}]}))
    return root, mesh, truths


def test_the_reader_gives_each_annotated_object_with_its_camera_truth_and_visibility(dataset):
    root, _, truths = dataset
    data = BopDataset(root)
    views = list(data.views())
    assert [(v.scene_id, v.im_id, v.obj_id) for v in views] == [(7, 0, 3), (7, 1, 3)]
    assert views[0].visib_fract == pytest.approx(0.93)
    np.testing.assert_allclose(views[1].obj2cam, truths[1], atol=1e-12)
    assert (views[0].intrinsics.fu, views[0].intrinsics.cy, views[0].intrinsics.width, views[0].intrinsics.height) == (
        K.fu,
        K.cy,
        640,
        480,
    )
    assert [v.im_id for v in data.views(min_visible=0.5)] == [0]
    model = data.models()[3]
    assert model.diameter_mm == 140.0 and model.path.name == "obj_000003.ply" and len(model.symmetries) == 1


def test_a_broken_annotation_names_its_file_and_field(dataset, tmp_path):
    root, _, _ = dataset
    import shutil

    copy = tmp_path / "blob"
    shutil.copytree(root, copy)
    gt = copy / "test" / "000007" / "scene_gt.json"
    data = json.loads(gt.read_text())
    data["1"][0]["cam_t_m2c"] = [1.0, "x"]
    gt.write_text(json.dumps(data))
    with pytest.raises(FileFormatError) as e:
        list(BopDataset(copy).views())
    assert "scene_gt.json" in str(e.value) and "1[0].cam_t_m2c" in str(e.value)
    with pytest.raises(FileFormatError, match="no split 'val'"):
        BopDataset(copy, "val")


def test_a_creaseless_mesh_gives_edge_samples_along_its_outline():
    mesh = scanned_blob()
    assert not (mesh.face_adjacency_angles > np.radians(30)).any()
    pose = np.eye(4)
    pose[:3, 3] = [0, 0, 650]
    samples = edge_points(mesh, pose, K)[0]
    # the blob's outline is about 380 px round at 650 mm: a sample every 4 px or so
    assert len(samples) > 60
    from calib_core.camera.projection import project_points
    from calib_core.look.outline import silhouette_mask

    mask, (u0, v0) = silhouette_mask(mesh, pose, K)
    uv = project_points(samples, pose, K)
    boundary = cv2.morphologyEx(mask, cv2.MORPH_GRADIENT, np.ones((3, 3), np.uint8))
    distance = cv2.distanceTransform(255 - boundary, cv2.DIST_L2, 3)
    at = distance[
        np.clip(np.rint(uv[:, 1] - v0).astype(int), 0, mask.shape[0] - 1),
        np.clip(np.rint(uv[:, 0] - u0).astype(int), 0, mask.shape[1] - 1),
    ]
    assert np.all(at <= 1.5)  # every sample on the silhouette's boundary


def test_locate_finds_the_creaseless_object_from_a_prior_10_mm_and_3_deg_off(dataset):
    root, mesh, _ = dataset
    view = next(BopDataset(root).views(min_visible=0.5))
    image = cv2.imread(str(view.image_path))[:, :, ::-1]
    prior = view.obj2cam.copy()
    prior[:3, 3] += [6.0, -8.0, 0.0]
    prior[:3, :3] = Rotation.from_rotvec(np.radians(3.0) * np.array([0.6, 0.0, 0.8])).as_matrix() @ prior[:3, :3]
    located = locate(
        np.ascontiguousarray(image), view.intrinsics, mesh, prior, reach_mm=10.0, reach_deg=3.0, features={}
    )
    assert located.obj2cam is not None, located.message
    points = np.asarray(mesh.vertices)[::10]
    prior_error = mspd(prior, view.obj2cam, points, np.eye(4)[None], view.intrinsics)
    error = mspd(located.obj2cam, view.obj2cam, points, np.eye(4)[None], view.intrinsics)
    assert prior_error > 8.0 and error < 5.0, (prior_error, error, located.message)
    assert located.status == "ok", located.message  # an unprinted object on its background: one answer


def test_a_rounded_rotation_is_read_as_the_nearest_one_and_a_matrix_that_is_none_is_named(dataset, tmp_path):
    """LM-O's annotated rotations are off orthonormal by up to 0.0096: read, they are the nearest rotation; a matrix
    that is no rotation at all names its file and field."""
    root, _, _ = dataset
    import shutil

    copy = tmp_path / "blob"
    shutil.copytree(root, copy)
    gt = copy / "test" / "000007" / "scene_gt.json"
    data = json.loads(gt.read_text())
    R = np.array(data["1"][0]["cam_R_m2c"]).reshape(3, 3)
    data["1"][0]["cam_R_m2c"] = (R * 1.004).reshape(-1).tolist()  # as rounded annotations are
    gt.write_text(json.dumps(data))
    view = next(v for v in BopDataset(copy).views() if v.im_id == 1)
    read = view.obj2cam[:3, :3]
    np.testing.assert_allclose(read @ read.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(read, R, atol=1e-9)
    data["1"][0]["cam_R_m2c"] = (R * 1.2).reshape(-1).tolist()
    gt.write_text(json.dumps(data))
    with pytest.raises(FileFormatError) as e:
        list(BopDataset(copy).views())
    assert "1[0].cam_R_m2c" in str(e.value) and "not a rotation" in str(e.value)
