"""``calib_core.robot`` loads its model (Pinocchio, trimesh, SciPy) when a name needing it is first asked for: a
submodule needing none of them (the bounded xacro child, started once a document) starts without them."""

import subprocess
import sys

PROBE = (
    "import sys\n"
    "import calib_core.robot.errors\n"
    "print(sorted(m for m in ('pinocchio', 'trimesh', 'scipy') if m in sys.modules))\n"
    "from calib_core.robot import load_robot\n"
    "print(sorted(m for m in ('pinocchio', 'trimesh', 'scipy') if m in sys.modules), load_robot.__module__)\n"
)


def test_a_submodule_starts_without_the_model_and_a_public_name_loads_it():
    run = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    before, after = run.stdout.splitlines()
    assert before == "[]"
    assert "pinocchio" in after and after.endswith("calib_core.robot.model")
