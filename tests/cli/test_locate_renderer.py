"""``videocal locate`` starts the renderer only for a mesh whose own edges it must judge: a CAD part's creases (two
faces of one shade meeting show none); a scanned mesh's samples come from its outline, which always shows, and the
renderer (VTK, a third of the command's memory) stays unloaded. Likewise the solver's compiled kernels (numba, about
half a second to load) only for a look that found features to solve from. Run as a user runs it, in a subprocess of
its own."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from bench.real_views import view_prior
from calib_core.camera.intrinsics_io import save_intrinsics
from calib_core.datasets.bop import BopDataset
from calib_core.datasets.pose_errors import mspd
from calib_core.mesh_files import load_mesh
from tests.core.look.box_photo import BOX, HAND_PRIOR, PHOTO, TUTORIAL_CAMERA

ROOT = Path(__file__).resolve().parents[2]
LMO = ROOT / "tests" / "data" / "third_party" / "lmo"
_RUN = (
    "import contextlib, io, sys\n"
    "from app.cli.main import main\n"
    "sys.argv = ['videocal', 'locate', *sys.argv[1:]]\n"
    "out = io.StringIO()\n"
    "with contextlib.redirect_stdout(out):\n"
    "    code = main()\n"
    "print(out.getvalue().strip())\n"
    "print('loaded:' + ','.join(m for m in ('vtkmodules', 'numba') if m in sys.modules))\n"
    "sys.exit(code)\n"
)


def _locate(*args: str) -> tuple[dict, set[str]]:
    """The command's JSON answer and which of VTK (``vtkmodules``) and ``numba`` it loaded."""
    done = subprocess.run([sys.executable, "-c", _RUN, *args], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    answer, loaded = done.stdout.strip().rsplit("\nloaded:", 1)
    return json.loads(answer), set(filter(None, loaded.split(",")))


def _prior_file(folder: Path, pose: np.ndarray) -> Path:
    path = folder / "prior.json"
    path.write_text(json.dumps({"R_obj2cam": pose[:3, :3].tolist(), "t_obj2cam_mm": pose[:3, 3].tolist()}))
    return path


def test_a_scanned_mesh_is_located_without_the_renderer(tmp_path):
    dataset = BopDataset(LMO, "test")
    (view,) = [v for v in dataset.views() if v.obj_id == 6]
    info = dataset.models()[6]
    save_intrinsics(tmp_path / "kinect.yaml", view.intrinsics)
    prior = _prior_file(tmp_path, view_prior(view, 10.0, 3.0))
    answer, loaded = _locate(
        str(view.image_path), "--mesh", str(info.path), "--intrinsics", str(tmp_path / "kinect.yaml"),
        "--prior", str(prior), "--reach-mm", "10", "--reach-deg", "3",
    )  # fmt: skip
    assert loaded == set()  # no renderer, and no solver: a scan has no features to solve from
    assert answer["status"] == "ok", answer["message"]
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = answer["R_obj2cam"], answer["t_obj2cam_mm"]
    mesh = load_mesh(info.path)
    points = np.asarray(mesh.vertices)[:: max(1, len(mesh.vertices) // 2000)]
    assert mspd(pose, view.obj2cam, points, info.symmetries, view.intrinsics) < 5.0


def test_a_cad_part_is_located_with_its_creases_judged_by_the_renderer(tmp_path):
    save_intrinsics(tmp_path / "camera.yaml", TUTORIAL_CAMERA)
    prior = tmp_path / "prior.json"
    prior.write_text(json.dumps(HAND_PRIOR))
    answer, loaded = _locate(
        str(PHOTO), "--mesh", str(BOX), "--units", "cm", "--intrinsics", str(tmp_path / "camera.yaml"),
        "--prior", str(prior),
    )  # fmt: skip
    assert loaded == {"vtkmodules", "numba"}  # the box's corners found are solved for a pose of their own
    assert answer["status"] == "ok", answer["message"]
