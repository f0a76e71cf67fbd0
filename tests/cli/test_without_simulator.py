"""The simulator is a plug-in: with ``videocal_sim`` gone (blocked from importing, as if its folder were
deleted while its entry points are still registered), every other command works and those that need it
end with one ``error:`` line that says why, never a traceback."""

import os
import subprocess
import sys

import pytest

BLOCK_SIMULATOR = "import sys; sys.modules['videocal_sim'] = None; from app.cli.main import main; sys.exit(main())"


def _videocal_without_simulator(*args, cwd) -> subprocess.CompletedProcess:
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    return subprocess.run(
        [sys.executable, "-c", BLOCK_SIMULATOR, *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
        env=env,
    )


def test_the_commands_that_do_not_need_it_work(tmp_path):
    run = _videocal_without_simulator("--help", cwd=tmp_path)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
    assert "render" in run.stdout and "calibrate-intrinsics" in run.stdout
    assert "demo" in run.stdout and "cannot be loaded" in run.stdout  # the broken plug-in is named, not fatal
    out = tmp_path / "view.png"
    run = _videocal_without_simulator("render", "--out", out, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "args, expected",
    [
        (("demo", "--offscreen"), "the command 'demo' cannot be loaded"),
        (("calibrate-intrinsics", "sim", "--out", "intrinsics.yaml"), "the site plug-in 'sim' is registered"),
    ],
)
def test_the_commands_that_need_it_say_so(tmp_path, args, expected):
    run = _videocal_without_simulator(*args, cwd=tmp_path)
    assert "Traceback" not in run.stderr, run.stderr[-3000:]
    assert run.returncode == 2, (run.returncode, run.stderr[-2000:])
    errors = [line for line in run.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and expected in errors[0], run.stderr
    assert run.stderr.splitlines()[0].startswith("error: "), run.stderr  # nothing announced that cannot start
    assert not (tmp_path / "intrinsics.yaml").exists()
