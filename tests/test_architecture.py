"""The one direction of the architecture: app -> calib_core, never back; VTK only in render."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
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


def test_only_render_imports_vtk():
    render = ROOT / "calib_core" / "render"
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "calib_core").rglob("*.py")
        if render not in p.parents and _imports(p) & {"vtk", "vtkmodules", "pyvista", "pyvistaqt"}
    ]
    assert offenders == []


def test_cli_package_does_not_import_qt():
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "app" / "cli").rglob("*.py")
        if _imports(p) & {"PySide6", "shiboken6"}
    ]
    assert offenders == []
