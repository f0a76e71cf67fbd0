"""Generated bad documents against one loader, in this process under resource limits:
``python -m tests.fuzz.run_loader LOADER EXAMPLES [SEED]`` prints one JSON line
``{loader, examples, accepted, refused, unexpected: [...], slowest_s, peak_rss_mb, baseline_rss_mb}``.

Each document is a good one (the bundled cell's own files) with hypothesis's mutations: a value
anywhere replaced by another type, a huge, non-finite or negative number, deep nesting or a long
string; keys deleted or added; the text cut, aliased or nested past the limits. A loader may accept
a document or refuse it with a ``VideocalError`` (what the command line turns into one ``error:``
line); anything else is a finding, recorded with its traceback. Every document has a time limit
(SIGALRM) and the process an address-space limit.
"""

from __future__ import annotations

import json
import os
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[2]
from tests.fuzz.mutations import byte_mutations, mutated, mutated_text

ADDRESS_SPACE = 4 * 1024**3
DOCUMENT_S = 10


class DocumentTimeout(Exception):
    pass


# --- the loaders ----------------------------------------------------------------------------------
def _cell_folder() -> Path:
    folder = Path(tempfile.mkdtemp(prefix="fuzz_cell_"))
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(ROOT / "resources" / sub, folder / sub)
    return folder


def loaders(folder: Path) -> dict:
    from app.cli.cmd_solve import read_solve_inputs
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.vision.board import parse_board
    from calib_core.vision.hand_eye_data import load_posed_images
    from calib_core.vision.hand_eye_io import load_cam2flange
    from calib_core.vision.target_detection import load_detector_settings
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import load_workspace

    workcell_doc = yaml.safe_load((folder / "workcell" / "workcell.yaml").read_text())
    ros_doc = yaml.safe_load((folder / "camera" / "gripper_camera_ros.yaml").read_text())
    opencv_text = (folder / "camera" / "gripper_camera.yaml").read_text()
    hand_eye_doc = {
        "cam2flange": {"xyz": [81.0, -1.0, 88.0], "rpy": [-100.0, 0.0, -90.0]},
        "units": {"length": "mm", "angle": "deg"},
        "std": {"xyz_mm": [0.1, 0.1, 0.1]},
    }
    solve_doc = json.loads((ROOT / "resources" / "examples" / "pairs.json").read_text())
    workspace_doc = _workspace_doc(folder)
    out = folder / "workcell"
    settings_doc = {
        "refine_markers": True,
        "aruco": {"adaptiveThreshWinSizeMax": 35, "cornerRefinementMethod": 1, "adaptiveThreshConstant": 7.0},
        "circle_blobs": {"minArea": 25.0, "filterByConvexity": True},
    }
    (out / "poses").mkdir(exist_ok=True)
    (out / "poses" / "0.yaml").write_text(
        "x: 0.11\ny: 0.59\nz: 0.65\nqx: -0.5186\nqy: 0.8156\nqz: 0.0932\nqw: 0.2390\n"
    )
    cal_data_doc = {
        "data": [{"image": "images/0.png", "pose": "poses/0.yaml"}, {"image": "images/1.png", "pose": "poses/0.yaml"}],
        "target_finder": {
            "type": "CharucoGridTargetFinder",
            "rows": 7,
            "cols": 5,
            "chessboard_dim": 0.036195,
            "aruco_marker_dim": 0.018256,
            "dictionary": 10,
        },
        "intrinsics": {"fx": 1352.0, "fy": 1356.1, "cx": 789.7, "cy": 627.3},
        "static_camera": True,
    }
    csv_text = (
        "image,x_mm,y_mm,z_mm,qx,qy,qz,qw\n"
        "images/0.png,110.0,590.0,650.0,-0.5186,0.8156,0.0932,0.2390\n"
        "images/1.png,120,600,640,0,0,0,1\n"
    )

    from app.cli.cmd_locate import read_features, read_prior
    from calib_core.mesh_files import load_mesh
    from calib_core.recording.reader import read_recording
    from calib_core.robot.model import load_robot

    urdf_text = (folder / "robot" / "videocal_arm.urdf").read_text()
    recording_bytes = (ROOT / "resources" / "recordings" / "sample_session.mcap").read_bytes()
    box_ply = (ROOT / "tests" / "data" / "third_party" / "opencv_samples" / "box.ply").read_text()
    prior_doc = {
        "R_obj2cam": [[0.7512, -0.6587, -0.0433], [-0.3824, -0.3808, -0.8419], [0.538, 0.649, -0.5379]],
        "t_obj2cam_mm": [-5.9, 110.7, 943.5],
    }
    features_doc = {"top_left": [0.0, 25.8, 7.5], "top_right": [18.9, 25.8, 7.5], "corner": [0, 0, 0]}

    def binary_file(name: str, data: bytes) -> Path:
        path = out / name
        path.write_bytes(data)
        return path

    def yaml_file(name: str, doc=None, text: str | None = None) -> Path:
        path = out / name
        path.write_text(text if text is not None else yaml.safe_dump(doc, sort_keys=False, allow_unicode=True))
        return path

    def json_file(name: str, doc) -> Path:
        path = out / name
        path.write_text(json.dumps(doc))
        return path

    bag_folder, bag_mcap = _small_bag(out)
    launch_xml = (
        '<launch>\n  <node pkg="tf2_ros" exec="static_transform_publisher" name="mounting" args="--x 0.081 --y -0.001 '
        "--z 0.088 "
        "--roll -1.745 --pitch 0.0 --yaw -1.571 --frame-id tool0 --child-frame-id "
        'camera_color_optical_frame"/>\n</launch>\n'
    )
    xacro_text = (
        '<robot name="fuzz" xmlns:xacro="http://www.ros.org/wiki/xacro">\n  <xacro:property name="l" value="0.3"/>\n'
        '  <xacro:macro name="link" params="n"><link name="${n}"/></xacro:macro>\n  <xacro:link n="base"/>\n  '
        '<xacro:link n="tip"/>\n'
        '  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/><origin xyz="0 0 ${l}"/><axis '
        'xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>\n</robot>\n'
    )
    url_texts = st.one_of(
        st.builds(
            lambda scheme, rest: scheme + rest,
            st.sampled_from(
                ["ros2://", "ros2:///", "socket://", "rfc2217://", "loop://", "ur-rtde://", "aravis://", ""]
            ),
            st.text(max_size=60),
        ),
        st.from_regex(
            r"ros2:///[a-z_/]{1,20}\?[a-z_]{1,12}=[-0-9.a-z\x00\n]{0,12}(&[a-z_]{1,12}=[-0-9.a-z]{0,8}){0,3}",
            fullmatch=True,
        ),
    )

    return {
        "ros2_bag": (byte_mutations(len(bag_mcap)), lambda m: _read_bag(bag_folder, m.of(bag_mcap))),
        "launch_file": (mutated_text(launch_xml), lambda t: _load_mounting(yaml_file("mounting.launch.xml", text=t))),
        "xacro": (mutated_text(xacro_text), lambda t: _expand(yaml_file("fuzz.urdf.xacro", text=t))),
        "connector_url": (url_texts, _open_url),
        "workcell": (
            st.one_of(
                mutated(workcell_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(workcell_doc, sort_keys=False)).map(lambda t: ("text", t)),
            ),
            lambda v: load_workcell(
                yaml_file("fuzz.yaml", v[1]) if v[0] == "doc" else yaml_file("fuzz.yaml", text=v[1])
            ),
        ),
        "intrinsics_ros": (
            st.one_of(
                mutated(ros_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(ros_doc)).map(lambda t: ("text", t)),
            ),
            lambda v: load_intrinsics(
                yaml_file("ros.yaml", v[1]) if v[0] == "doc" else yaml_file("ros.yaml", text=v[1])
            ),
        ),
        "intrinsics_opencv": (mutated_text(opencv_text), lambda t: load_intrinsics(yaml_file("opencv.yaml", text=t))),
        "hand_eye": (
            st.one_of(
                mutated(hand_eye_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(hand_eye_doc)).map(lambda t: ("text", t)),
            ),
            lambda v: load_cam2flange(yaml_file("he.yaml", v[1]) if v[0] == "doc" else yaml_file("he.yaml", text=v[1])),
        ),
        "workspace": (mutated(workspace_doc), lambda d: load_workspace(json_file("ws.json", d))),
        "solve_inputs": (mutated(solve_doc), lambda d: read_solve_inputs(json_file("solve.json", d))),
        "detector_settings": (
            st.one_of(
                mutated(settings_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(settings_doc)).map(lambda t: ("text", t)),
            ),
            lambda v: load_detector_settings(
                yaml_file("detector.yaml", v[1]) if v[0] == "doc" else yaml_file("detector.yaml", text=v[1])
            ),
        ),
        "cal_data": (
            st.one_of(
                mutated(cal_data_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(cal_data_doc)).map(lambda t: ("text", t)),
            ),
            lambda v: load_posed_images(
                yaml_file("cal_data.yaml", v[1]) if v[0] == "doc" else yaml_file("cal_data.yaml", text=v[1])
            ),
        ),
        "pose_csv": (mutated_text(csv_text), lambda t: load_posed_images(yaml_file("views.csv", text=t))),
        "robot_urdf": (mutated_text(urdf_text), lambda t: load_robot(yaml_file("../robot/fuzz.urdf", text=t))),
        "recording": (
            byte_mutations(len(recording_bytes)),
            lambda m: read_recording(binary_file("fuzz.mcap", m.of(recording_bytes))),
        ),
        "mesh_ply": (mutated_text(box_ply), lambda t: load_mesh(yaml_file("fuzz.ply", text=t), "cm")),
        "locate_prior": (mutated(prior_doc), lambda d: read_prior(json_file("prior.json", d))),
        "locate_features": (
            st.one_of(
                mutated(features_doc).map(lambda d: ("doc", d)),
                mutated_text(yaml.safe_dump(features_doc)).map(lambda t: ("text", t)),
            ),
            lambda v: read_features(
                yaml_file("features.yaml", v[1]) if v[0] == "doc" else yaml_file("features.yaml", text=v[1]), 10.0
            ),
        ),
        "board_spec": (
            st.one_of(
                st.text(max_size=60),
                st.from_regex(
                    r"(charuco|aruco):-?[0-9]{1,7}x-?[0-9]{1,7}:[-0-9.e]{1,8}:[-0-9.e]{1,8}:DICT_[0-9A-Z_]{1,12}(:legacy)?",
                    fullmatch=True,
                ),
                st.from_regex(
                    r"(chessboard|circles):-?[0-9]{1,7}x-?[0-9]{1,7}:[-0-9.e]{1,8}(:asymmetric)?", fullmatch=True
                ),
            ),
            parse_board,
        ),
    }


def _small_bag(out: Path) -> tuple[Path, bytes]:
    """A ROS 2 bag of two images, a CameraInfo and a JointState written by rosbags; its folder and its MCAP's bytes."""
    import shutil as _shutil

    from tests.core.bags.bag_writing import write_bag

    folder = out / "fuzz_bag"
    _shutil.rmtree(folder, ignore_errors=True)
    image = np.tile(np.arange(640, dtype=np.uint16).astype(np.uint8), (480, 1))  # the size its CameraInfo says
    write_bag(folder, "mcap", {"/camera/image_raw": [image, image[::-1].copy()]})
    mcap = next(folder.glob("*.mcap"))
    return folder, mcap.read_bytes()


def _read_bag(folder: Path, data: bytes):
    from calib_core.bags.bag_source import bag_intrinsics, bag_stamped_images

    next(folder.glob("*.mcap")).write_bytes(data)
    images = list(bag_stamped_images(folder))
    if images:
        bag_intrinsics(folder, (images[0][2].shape[1], images[0][2].shape[0]))
    return images


def _load_mounting(path: Path):
    from calib_core.vision.hand_eye_io import load_mounting

    return load_mounting(path)


def _expand(path: Path):
    from calib_core.robot.xacro_expand import expand_xacro

    return expand_xacro(path, [], timeout_s=5.0, memory_mb=512)


def _open_url(url: str):
    """A controller connector made (not started) and a camera spec checked, as a workcell's site: section is taken."""
    from calib_core.connectors.controller import ControllerContext
    from calib_core.connectors.registry import check_camera_spec, open_controller
    from calib_core.connectors.joint_map import JointMap

    scheme = url.split(":", 1)[0].lower()
    if scheme in ("ros2", "socket", "rfc2217", "loop"):  # made without a connection (ur-rtde connects when made)
        open_controller(url, ControllerContext(("a", "b"), ("deg", "deg"), JointMap.identity(2), 50.0, {}))
    check_camera_spec(url)


def _workspace_doc(folder: Path) -> dict:
    from calib_core.calibration.corrections import Correction, CorrectionTable
    from calib_core.calibration.correspondences import Correspondence
    from calib_core.calibration.view_stamp import ViewStamp
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import Workspace, save_workspace

    cell = load_workcell(folder / "workcell" / "workcell.yaml")
    table = CorrectionTable()
    measured = np.eye(4)
    measured[:3, 3] = [1.0, -2.0, 0.5]
    table.add(
        Correction(
            "oru_1_grasp",
            np.eye(4),
            measured,
            np.array([1.0, -2.0, 0.5]),
            np.zeros(3),
            np.full(3, 0.1),
            np.full(3, 0.01),
            np.zeros(6),
            0.3,
            6,
        )
    )
    view = ViewStamp(3, 12.5, (0.0,) * 6, 0.01, "2026-12-01 12:00:00", "camera")
    pairs = [Correspondence(1, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), (100.0, 200.0), True, view)]
    path = folder / "workcell" / "seed_workspace.json"
    save_workspace(
        path,
        Workspace(
            str(cell.path),
            load_intrinsics(cell.intrinsics_path),
            dict(cell.task_locations),
            "oru_1_fixture",
            pairs,
            table,
        ),
    )
    return json.loads(path.read_text())


# --- the run --------------------------------------------------------------------------------------
def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main(name: str, examples: int, seed: int = 0) -> dict:
    from calib_core.errors import VideocalError

    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))
    folder = _cell_folder()
    strategy, load = loaders(folder)[name]
    baseline = _rss_mb()
    stats = {
        "loader": name,
        "examples": 0,
        "accepted": 0,
        "refused": 0,
        "unexpected": [],
        "slowest_s": 0.0,
        "baseline_rss_mb": baseline,
    }

    def alarm(*_):
        raise DocumentTimeout(f"no answer within {DOCUMENT_S} s")

    signal.signal(signal.SIGALRM, alarm)

    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        derandomize=True,
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(strategy)
    def fuzz(value):
        stats["examples"] += 1
        started = time.perf_counter()
        signal.alarm(DOCUMENT_S)
        try:
            load(value)
            stats["accepted"] += 1
        except VideocalError:
            stats["refused"] += 1
        except BaseException as exc:  # a finding: anything but a clear refusal
            if isinstance(exc, KeyboardInterrupt):
                raise
            if len(stats["unexpected"]) < 10:
                stats["unexpected"].append(
                    {
                        "error": f"{type(exc).__name__}: {exc}"[:500],
                        "traceback": traceback.format_exc()[-1500:],
                        "input": repr(value)[:400],
                    }
                )
            else:
                stats["unexpected"].append({"error": f"{type(exc).__name__}"})
        finally:
            signal.alarm(0)
            stats["slowest_s"] = max(stats["slowest_s"], time.perf_counter() - started)

    fuzz()
    stats["peak_rss_mb"] = _rss_mb()
    shutil.rmtree(folder, ignore_errors=True)
    return stats


if __name__ == "__main__":
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
    print(json.dumps(main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]) if len(sys.argv) > 3 else 0)))
