"""What a recording made through the core holds for Foxglove's panels, checked against the model it
came from: the camera calibration is the intrinsics, the frame tree composes to the modelled camera
pose, the annotations sit on the picks and on an independent reprojection of the solved pose, the
meshes are the cell's and the robot's."""

import io
import time

import numpy as np
import pytest
import trimesh
from foxglove_schemas_protobuf.CameraCalibration_pb2 import CameraCalibration
from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from scipy.spatial.transform import Rotation

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.operator.core import OperatorCore
from calib_core.recording.reader import read_recording
from calib_core.recording.schemas import (
    ANNOTATIONS_TOPIC,
    CALIBRATION_TOPIC,
    JOINTS_TOPIC,
    SCENE_TOPIC,
    TRANSFORMS_TOPIC,
    VIDEO_TOPIC,
)
from tests.core.operator.perfect_operator import pick_all, task_joints
from tests.core.operator.still_robot import frame_now, still_for
from videocal_sim.sim_site import simulated_cell


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A session recorded through the core: the robot drives a little, stands at the task's approach,
    six pairs are picked on a frame of that pose and solved."""
    cell, site = simulated_cell(image_scale=0.5)
    core = OperatorCore(cell, site)
    path = tmp_path_factory.mktemp("tap") / "session.mcap"
    core.recording.start(path)
    q = task_joints(core)
    # still elsewhere, then a move, then still at q; stamped after the recording's start, as a live session is
    t = still_for(core, 0.4, joints_deg=q - 2.0, start_s=time.monotonic() + 1.0)
    for k in range(1, 11):
        still_for(core, 0.0, joints_deg=q - 2.0 + 0.2 * k, start_s=t + 0.02 * k)
    still_for(core, 2.5, joints_deg=q, start_s=t + 0.24)
    frame_now(core, image=np.full((cell.intrinsics.height, cell.intrinsics.width, 3), 90, np.uint8))
    pick_all(core, site.bed, q)
    core.picking.calibrate()
    solution = core.session.result.estimate.solution
    points_obj, _, numbers = core.session.pairs.arrays()
    obj2world = core.workcell.component(core.session.target).item2world
    core.recording.stop()
    return core, read_recording(path), q, solution, apply(invert(obj2world), points_obj), numbers


def _tree(message: FrameTransforms) -> dict:
    tree = {}
    for ft in message.transforms:
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat([ft.rotation.x, ft.rotation.y, ft.rotation.z, ft.rotation.w]).as_matrix()
        T[:3, 3] = np.array([ft.translation.x, ft.translation.y, ft.translation.z]) * 1000.0
        tree[ft.child_frame_id] = (ft.parent_frame_id, T)
    return tree


def _to_world(tree: dict, frame: str) -> np.ndarray:
    T = np.eye(4)
    while frame != "world":
        parent, child2parent = tree[frame]
        T, frame = child2parent @ T, parent
    return T


def test_the_camera_calibration_is_the_intrinsics_in_use(recorded):
    core, contents, *_ = recorded
    (m,) = contents.topic(CALIBRATION_TOPIC)
    cal = CameraCalibration.FromString(m.raw)
    i = core.intrinsics
    assert (cal.width, cal.height, cal.frame_id) == (i.width, i.height, core.robot.roles["camera"])
    assert np.allclose(np.reshape(cal.K, (3, 3)), [[i.fu, 0, i.cx], [0, i.fv, i.cy], [0, 0, 1]])
    assert (
        np.allclose(np.reshape(cal.P, (3, 4))[:, :3], np.reshape(cal.K, (3, 3))) and cal.distortion_model == "plumb_bob"
    )
    assert np.allclose(cal.D[: len(i.distortion)], i.distortion)


def test_the_frame_tree_composes_to_the_modelled_camera_and_tool(recorded):
    core, contents, q, *_ = recorded
    last = FrameTransforms.FromString(contents.topic(TRANSFORMS_TOPIC)[-1].raw)
    tree = _tree(last)
    assert np.allclose(_to_world(tree, core.robot.roles["camera"]), core.robot.fk(q, "camera"), atol=1e-6)
    assert np.allclose(_to_world(tree, core.robot.roles["tcp"]), core.robot.fk(q, "tcp"), atol=1e-6)
    video = CompressedVideo.FromString(contents.topic(VIDEO_TOPIC)[0].raw)
    assert video.frame_id in tree  # the 3D panel can place the image


def test_transforms_follow_a_move_and_repeat_once_a_second_while_the_robot_stands(recorded):
    _, contents, *_ = recorded
    joints = contents.topic(JOINTS_TOPIC)
    tf = contents.topic(TRANSFORMS_TOPIC)[1:]  # the first is the start's
    t_move = joints[0].payload["t_host_s"] + 0.4
    moving = [m for m in joints if t_move < m.payload["t_host_s"] < t_move + 0.21]
    tf_times = [m.log_time_ns for m in tf]
    assert len(moving) == 10 and all(m.log_time_ns in tf_times for m in moving)  # every sample of the move
    standing = [t for t in tf_times if t > moving[-1].log_time_ns + 30_000_000]
    assert 2 <= len(standing) <= 4  # 2.5 s standing: about one a second, not 125


def test_the_annotations_sit_on_the_picks_and_on_an_independent_reprojection(recorded):
    core, contents, _, solution, points_obj, numbers = recorded
    last = ImageAnnotations.FromString(contents.topic(ANNOTATIONS_TOPIC)[-1].raw)
    pairs = {p.number: p.pixel for p in core.session.pairs}
    assert sorted(t.text for t in last.texts) == sorted(f"#{n}" for n in pairs)
    # Foxglove's image coordinates start at the top-left pixel's corner, videocal's (OpenCV's) at its centre
    circles = {(round(c.position.x - 0.5, 6), round(c.position.y - 0.5, 6)) for c in last.circles}
    assert circles == {(round(float(u), 6), round(float(v), 6)) for u, v in pairs.values()}
    crosses, residuals = last.points
    centres = np.array([[p.x, p.y] for p in crosses.points]).reshape(-1, 4, 2).mean(axis=1) - 0.5
    expected = project(apply(solution.obj2cam, points_obj), core.intrinsics)
    assert np.allclose(centres, expected, atol=1e-6)
    lines = np.array([[p.x, p.y] for p in residuals.points]).reshape(-1, 2, 2) - 0.5
    assert np.allclose(lines[:, 0], [pairs[n] for n in numbers]) and np.allclose(lines[:, 1], expected, atol=1e-6)


def test_the_scene_has_the_robot_on_its_links_and_the_cell_in_the_world(recorded):
    core, contents, q, *_ = recorded
    (m,) = contents.topic(SCENE_TOPIC)
    entities = {e.id: e for e in SceneUpdate.FromString(m.raw).entities}
    tree = _tree(FrameTransforms.FromString(contents.topic(TRANSFORMS_TOPIC)[0].raw))
    robot = [e for e in entities.values() if e.id.startswith("robot/")]
    assert robot and all(e.frame_id in tree and e.frame_locked for e in robot)
    for item in core.workcell.components:
        entity = entities[f"cell/{item.name}"]
        model = entity.models[0]
        assert entity.frame_id == "world" and model.media_type == "model/gltf-binary"
        mesh = trimesh.load(io.BytesIO(model.data), file_type="glb", force="mesh")
        # glTF is y-up: turned back +90 deg about x (what Foxglove does), the vertices are the cell's, in m
        z_up = mesh.vertices @ Rotation.from_euler("x", 90, degrees=True).as_matrix().T
        assert len(mesh.vertices) == len(item.mesh.vertices)
        assert np.allclose(np.sort(z_up * 1000.0, axis=0), np.sort(item.mesh.vertices, axis=0), atol=1e-3)
    assert [a[0] for a in contents.attachments] == ["robot.urdf"] and contents.attachments[0][
        2
    ].decode() == core.robot.urdf_xml
