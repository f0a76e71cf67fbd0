"""The one direction of the architecture: videocal_sim -> app -> calib_core, never back; VTK only in render."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _imports(path: Path, *, module_level_only: bool = False) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: set[str] = set()
    for node in tree.body if module_level_only else ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
    return names


def test_calib_core_never_imports_qt_or_app():
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "calib_core").rglob("*.py")
        if _imports(p) & {"PySide6", "PyQt5", "PyQt6", "shiboken6", "app"}
    ]
    assert offenders == []


def test_core_and_app_never_import_the_simulator():
    # The simulator is a plug-in (entry points): deleting videocal_sim must leave calib_core and app whole.
    offenders = [
        str(p.relative_to(ROOT))
        for package in ("calib_core", "app")
        for p in (ROOT / package).rglob("*.py")
        if "videocal_sim" in _imports(p)
    ]
    assert offenders == []


def test_only_render_imports_vtk():
    render = ROOT / "calib_core" / "render"
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "calib_core").rglob("*.py")
        if render not in p.parents and _imports(p) & {"vtk", "vtkmodules", "pyvista", "pyvistaqt"}
    ]
    assert offenders == []


def test_cli_package_does_not_import_qt_at_load():
    # Headless commands must never load Qt: command modules may import it only inside the
    # function that runs the window (``videocal gui``, ``videocal demo``).
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "app" / "cli").rglob("*.py")
        if _imports(p, module_level_only=True) & {"PySide6", "shiboken6", "app.gui"}
        or any(m.startswith("app.gui") for m in _from_imports(p))
    ]
    assert offenders == []


def _from_imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    return {n.module for n in tree.body if isinstance(n, ast.ImportFrom) and n.module}


def test_headless_commands_do_not_load_qt():
    import subprocess
    import sys

    code = "import sys, app.cli.main as m; m.main(['table1', '--json']); print('PySide6' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert out.stdout.strip().endswith("False")
