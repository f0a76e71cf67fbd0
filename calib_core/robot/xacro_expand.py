"""A xacro file to URDF text, within limits: a child process (:mod:`calib_core.robot.xacro_child`) with at most
``memory_mb`` of memory and ``timeout_s`` of time, so an expression such as ``${9**9**9}`` or ``'a'*10**10``
is an error naming the file, not a hang or a machine out of memory."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from calib_core.child_process import die_with_parent
from calib_core.errors import FileFormatError

TIMEOUT_S = 30.0
"""A vendor's xacro (a UR, FANUC or KUKA support package) expands in 1-5 s here, under load in 10."""
MEMORY_MB = 2048
MAX_OUTPUT_BYTES = 200 * 1024 * 1024


def expand_xacro(
    path: Path,
    roots: list[Path],
    args: dict[str, str] | None = None,
    *,
    timeout_s: float = TIMEOUT_S,
    memory_mb: int = MEMORY_MB,
) -> str:
    """The URDF text of xacro ``path`` with ``$(find pkg)`` from ``roots`` and ``$(arg name)`` from ``args``."""
    # Absolute: the child runs in the project's folder, not the caller's.
    request = json.dumps(
        {
            "path": str(Path(path).resolve()),
            "roots": [str(Path(r).resolve()) for r in roots],
            "args": dict(args or {}),
            "memory_mb": memory_mb,
            "cpu_s": int(timeout_s) + 1,
        }
    )
    try:
        done = subprocess.run(
            [sys.executable, "-m", "calib_core.robot.xacro_child"],
            input=request,
            capture_output=True,
            text=True,
            timeout=timeout_s,
            cwd=str(Path(__file__).resolve().parents[2]),
            preexec_fn=die_with_parent,
        )
    except subprocess.TimeoutExpired:
        raise FileFormatError(
            path, f"cannot expand xacro: it took longer than {timeout_s:g} s (a runaway expression?)"
        ) from None
    if done.returncode != 0:
        why = done.stderr.strip().splitlines()
        raise FileFormatError(path, f"cannot expand xacro: {why[-1] if why else f'exit code {done.returncode}'}")
    if len(done.stdout) > MAX_OUTPUT_BYTES:
        raise FileFormatError(path, f"cannot expand xacro: the URDF it makes is over {MAX_OUTPUT_BYTES // 2**20} MB")
    return done.stdout
