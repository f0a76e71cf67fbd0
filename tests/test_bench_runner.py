"""`make bench`'s runner, asked for a bench it does not have: one line naming it and the benches there are."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_an_unknown_bench_is_one_line_naming_the_benches():
    run = subprocess.run(
        [sys.executable, "-m", "bench", "cli", "real_photos"], capture_output=True, text=True, cwd=ROOT, timeout=60
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    (line,) = run.stderr.strip().splitlines()
    assert line.startswith("error: no bench named cli;") and "cli_bench" in line and "real_photos" in line
