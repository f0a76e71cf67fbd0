"""Finding ROS packages without ROS: where ``$(find pkg)`` and ``package://pkg/...`` point.

The places looked in, in order: the cell's package paths (``robot.package_paths``, ``--package-path``), each entry
of ``ROS_PACKAGE_PATH``, and ``<prefix>/share`` of each entry of ``AMENT_PREFIX_PATH`` (an installed ROS 2
workspace). A place is a package itself (its ``package.xml`` names it), a folder holding packages, or a checkout
of a repository holding them a few levels down (a ROS-Industrial support repository): packages are found by the
name in their ``package.xml``, as ``rospack`` and ``ament_index`` do, searched at most ``MAX_DEPTH`` folders deep.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path

MAX_DEPTH = 4
MAX_FOLDERS = 5000  # a search root that is a whole disk must not hang the load
_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_SKIP = {".git", "node_modules", "build", "install", "log", "__pycache__", ".venv"}


def search_roots(package_paths: Iterable[str | Path] = ()) -> list[Path]:
    """The folders looked in for packages, in order (see the module)."""
    roots = [Path(p) for p in package_paths]
    roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    roots += [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return roots


def _declared_name(folder: Path) -> str | None:
    try:
        text = (folder / "package.xml").read_text(encoding="utf-8", errors="replace")[:20000]
    except OSError:
        return None
    m = _NAME.search(text)
    return m.group(1) if m else None


def find_package(name: str, roots: list[Path]) -> Path | None:
    """The folder of package ``name`` (the one holding its ``package.xml``), or None."""
    for root in roots:
        for candidate in (root, root / name):
            if _declared_name(candidate) == name:
                return candidate.resolve()
    seen = 0
    for root in roots:
        level = [root]
        for _ in range(MAX_DEPTH):
            deeper = []
            for folder in level:
                try:
                    children = sorted(
                        p for p in folder.iterdir() if p.is_dir() and p.name not in _SKIP and not p.name.startswith(".")
                    )
                except OSError:
                    continue
                for child in children:
                    seen += 1
                    if seen > MAX_FOLDERS:
                        return None
                    if _declared_name(child) == name:
                        return child.resolve()
                    deeper.append(child)
            level = deeper
    return None
