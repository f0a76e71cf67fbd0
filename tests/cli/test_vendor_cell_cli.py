"""A ROS-Industrial support package as shipped becomes a cell with no edit, from any folder, with relative paths."""

import os
import subprocess
import sys
from pathlib import Path

import yaml

KUKA = Path(__file__).parents[1] / "data" / "third_party" / "ros_industrial" / "kuka_experimental"


def _videocal(*args, cwd):
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH")}
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
        env={**env, "PYTHONPATH": str(Path(__file__).parents[2]), "QT_QPA_PLATFORM": "offscreen"},
    )


def test_new_cell_from_the_kr6_xacro_then_render_from_another_folder(tmp_path):
    work = tmp_path / "work"
    work.mkdir()
    xacro = os.path.relpath(KUKA / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", work)
    made = _videocal(
        "new-cell",
        "kr6",
        "--urdf",
        xacro,
        "--package-path",
        os.path.relpath(KUKA, work),
        "--xacro-arg",
        "unused:=1",
        cwd=work,
    )
    assert made.returncode == 0, made.stderr
    assert "flange tool0" in made.stdout
    cell = yaml.safe_load((work / "kr6" / "workcell.yaml").read_text())
    assert cell["robot"]["xacro_args"] == {"unused": "1"}
    shot = _videocal(
        "render",
        "--workcell",
        "kr6/workcell.yaml",
        "--location",
        "target_grasp",
        "--view",
        "overview",
        "--out",
        "kr6.png",
        cwd=work,
    )
    assert shot.returncode == 0, shot.stderr
    assert (work / "kr6.png").stat().st_size > 10_000
    # the overview frames this cell as the window does (it looked at the bundled cell's spot: the KR6 was 1 % of
    # the image, in a corner); the robot's orange now covers several per cent, around the image's middle
    import cv2
    import numpy as np

    image = cv2.imread(str(work / "kr6.png"))[..., ::-1].astype(int)
    orange = (image[..., 0] > 150) & (image[..., 2] < 90) & (image[..., 0] - image[..., 2] > 100)
    assert orange.mean() > 0.025
    rows, cols = np.nonzero(orange)
    assert (
        0.25 * image.shape[1] < cols.mean() < 0.75 * image.shape[1]
        and 0.2 * image.shape[0] < rows.mean() < 0.8 * image.shape[0]
    )
    bad = _videocal(
        "new-cell",
        "kr6b",
        "--urdf",
        xacro,
        "--package-path",
        os.path.relpath(KUKA, work),
        "--xacro-arg",
        "ur_type=ur10e",
        cwd=work,
    )
    assert bad.returncode == 2 and "write it as NAME:=VALUE" in bad.stderr and not (work / "kr6b").exists()
    lost = _videocal("new-cell", "kr6c", "--urdf", xacro, cwd=work)
    assert lost.returncode == 2 and "$(find kuka_kr6_support)" in lost.stderr and "Traceback" not in lost.stderr
