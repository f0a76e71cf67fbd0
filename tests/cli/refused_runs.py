"""Runs of the command line that must be refused: a child process under memory and time limits, and the check
that it said why without a traceback."""

import os
import resource
import subprocess
import sys

ADDRESS_SPACE = 6 * 1024**3  # far above any good run of these commands, far below a runaway allocation


def limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


def videocal(*args, cwd=None, preexec=limits, timeout=120) -> subprocess.CompletedProcess:
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env=env,
        preexec_fn=preexec,
    )


def refused(run: subprocess.CompletedProcess, *expected: str) -> str:
    assert "Traceback" not in run.stderr, run.stderr[-3000:]
    assert run.returncode == 2, (run.returncode, run.stderr[-2000:])
    errors = [line for line in run.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1, run.stderr
    for text in expected:
        assert text in errors[0], errors[0]
    return errors[0]
