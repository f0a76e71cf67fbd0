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


_POSE_CALLS = {
    "invert",
    "fk",
    "frame_placement",
    "make_transform",
    "delta_transform",
    "transform_from_xyz_rpy",
    "concat",
}


def _is_pose(node: ast.AST, known: frozenset[str] = frozenset()) -> bool:
    """A 4 x 4 pose by its name (``a2b``, ``item.item2world``), by the function that makes one, or by a name
    assigned one in the same function (``known``: ``T = make_transform(...)`` makes ``T`` a pose)."""
    import re

    if isinstance(node, ast.Name | ast.Attribute):
        name = node.id if isinstance(node, ast.Name) else node.attr
        return (isinstance(node, ast.Name) and name in known) or re.fullmatch(
            r"[a-z_]*[a-z]2[a-z][a-z_]*", name
        ) is not None
    if isinstance(node, ast.Call):
        f = node.func
        return (f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else "") in _POSE_CALLS
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
        return _is_pose(node.left, known) or _is_pose(node.right, known)
    return False


def _poses_by_call(scope: ast.AST) -> frozenset[str]:
    """Names a function assigns a pose to (by a pose call or another pose), followed to a fixed point."""
    known: set[str] = set()
    while True:
        found = {
            t.id
            for node in ast.walk(scope)
            if isinstance(node, ast.Assign) and _is_pose(node.value, frozenset(known))
            for t in node.targets
            if isinstance(t, ast.Name)
        }
        if found <= known:
            return frozenset(known)
        known |= found


def _is_inverse_by_hand(node: ast.AST, known: frozenset[str]) -> bool:
    """``np.linalg.inv(pose)``: a rigid pose is inverted by ``invert`` (its transpose, exact), not a general inverse."""
    return (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "inv"
        and len(node.args) == 1
        and _is_pose(node.args[0], known)
    )


def _bare_compositions(source: str, filename: str) -> list[str]:
    tree = ast.parse(source, filename=filename)
    hits = set()
    for scope in [tree] + [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]:
        known = _poses_by_call(scope) if scope is not tree else frozenset()
        for node in ast.walk(scope):
            if (
                isinstance(node, ast.BinOp)
                and isinstance(node.op, ast.MatMult)
                and _is_pose(node.left, known)
                and _is_pose(node.right, known)
            ):
                hits.add((node.lineno, ast.unparse(node)))
            elif _is_inverse_by_hand(node, known):
                hits.add((node.lineno, ast.unparse(node)))
    return [f"{filename}:{line}: {text}" for line, text in sorted(hits)]


def test_poses_are_composed_with_concat_and_invert():
    # concat(a2b, b2c) reads in the order the frames chain; ``b2c @ a2b`` reads backwards, and a wrong order still runs.
    assert (
        len(
            _bare_compositions(
                "x = invert(cam2world) @ obj2world\ny = concat(obj2world, invert(cam2world)) @ p", "probe"
            )
        )
        == 1
    )
    # by call: a name given a pose in the function, and a pose inverted by hand
    assert (
        len(
            _bare_compositions(
                "def f(q):\n    T = robot.fk(q, 'tcp')\n    S = T\n    return S @ make_transform(R, t)", "probe"
            )
        )
        == 1
    )
    assert len(_bare_compositions("r = np.linalg.inv(base2root)\nc = np.linalg.inv(J.T @ J)", "probe")) == 1
    offenders = [
        hit
        for package in ("calib_core", "app", "videocal_sim")
        for p in sorted((ROOT / package).rglob("*.py"))
        for hit in _bare_compositions(p.read_text(), str(p.relative_to(ROOT)))
    ]
    assert offenders == [], "\n".join(offenders)


def _test_modules_imported(source: str) -> list[str]:
    """The test modules (``tests....test_*``) that ``source`` imports, at any depth."""
    found = []
    for node in ast.walk(ast.parse(source)):
        modules = (
            [node.module]
            if isinstance(node, ast.ImportFrom) and node.module
            else [a.name for a in node.names]
            if isinstance(node, ast.Import)
            else []
        )
        found += [m for m in modules if m.startswith("tests.") and m.rsplit(".", 1)[-1].startswith("test_")]
    return found


def test_no_test_module_imports_another():
    # a test module's helpers shared by importing it run its module-level set-up twice and tie the two files together:
    # shared helpers live in plain modules (tests/app/windows.py, tests/core/solver/scenes.py, conftest fixtures)
    assert _test_modules_imported("def f():\n    from tests.app.test_x import _go\n") == ["tests.app.test_x"]
    importing = {
        str(p.relative_to(ROOT)): found
        for p in (ROOT / "tests").rglob("*.py")
        if (found := _test_modules_imported(p.read_text()))
    }
    assert not importing, importing
