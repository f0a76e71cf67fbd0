"""The fuzz suite: every loader of user files fed generated bad documents (tests/fuzz/run_loader.py)
in its own process under an address-space limit. Each document is accepted or refused with a
VideocalError (one ``error:`` line on the command line); any other exception, a hang past the
per-document limit or a crash of the process is a failure. ``VIDEOCAL_FUZZ_EXAMPLES`` sets how
many documents per loader (default 150 here; bench/reliability_bench.py runs 10 000)."""

import json
import os
import subprocess
import sys

import pytest

from tests.fuzz.run_loader import ROOT

LOADERS = [
    "workcell",
    "intrinsics_ros",
    "intrinsics_opencv",
    "hand_eye",
    "workspace",
    "solve_inputs",
    "board_spec",
    "detector_settings",
    "cal_data",
    "pose_csv",
    "robot_urdf",
    "recording",
    "mesh_ply",
    "locate_prior",
    "locate_features",
    "ros2_bag",
    "launch_file",
    "xacro",
    "connector_url",
]
EXAMPLES = int(os.environ.get("VIDEOCAL_FUZZ_EXAMPLES", "150"))


def run_fuzz(loader: str, examples: int, seed: int = 0, timeout: float = 1200) -> dict:
    run = subprocess.run(
        [sys.executable, "-m", "tests.fuzz.run_loader", loader, str(examples), str(seed)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=timeout,
    )
    assert run.returncode == 0, f"the fuzzed process died ({run.returncode}): {run.stderr[-3000:]}"
    return json.loads(run.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("loader", LOADERS)
def test_every_generated_document_is_accepted_or_refused_clearly(loader):
    stats = run_fuzz(loader, EXAMPLES)
    assert stats["examples"] >= min(EXAMPLES, 50)
    assert stats["unexpected"] == [], json.dumps(stats["unexpected"][:3], indent=1)
    assert stats["refused"] > 0  # the mutations do reach the checks


def test_the_fuzzer_finds_a_loader_that_fails_unclearly(tmp_path):
    """The suite can fail: a loader that lets a TypeError out is reported with its input."""
    probe = tmp_path / "probe.py"
    probe.write_text(
        "import json, sys\n"
        "import tests.fuzz.run_loader as r\n"
        "real = r.loaders\n"
        "def broken(folder):\n"
        "    table = real(folder)\n"
        "    strategy, _ = table['hand_eye']\n"
        "    def load(v):\n"
        "        raise TypeError('an unclear failure')\n"
        "    table['hand_eye'] = (strategy, load)\n"
        "    return table\n"
        "r.loaders = broken\n"
        "print(json.dumps(r.main('hand_eye', 5)))\n"
    )
    run = subprocess.run(
        [sys.executable, str(probe)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    stats = json.loads(run.stdout.strip().splitlines()[-1])
    assert stats["unexpected"] and "TypeError: an unclear failure" in stats["unexpected"][0]["error"]
