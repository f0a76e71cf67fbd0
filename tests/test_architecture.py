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


def _parts_taking_the_core(source: str) -> list[str]:
    """Classes whose ``__init__`` takes a parameter named ``core`` (a part handed the whole program)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if (
                    isinstance(item, ast.FunctionDef)
                    and item.name == "__init__"
                    and any(a.arg == "core" for a in item.args.args)
                ):
                    found.append(node.name)
    return found


def test_the_operator_parts_are_given_what_they_need():
    # Each part of the operator core is handed its dependencies (the cell, the session, the arm...), never the
    # core itself: no part shares the program's state by convention. The recording tap alone listens to every part.
    assert _parts_taking_the_core("class Probe:\n    def __init__(self, core, log):\n        pass\n") == [
        "Probe"
    ]  # the check sees one
    offenders = {
        p.name: names
        for p in (ROOT / "calib_core" / "operator").glob("*.py")
        if p.name != "recording_tap.py" and (names := _parts_taking_the_core(p.read_text()))
    }
    assert offenders == {}
    bases = [
        n
        for n in ast.walk(ast.parse((ROOT / "calib_core" / "operator" / "core.py").read_text()))
        if isinstance(n, ast.ClassDef) and n.name == "OperatorCore"
    ]
    assert bases and bases[0].bases == []  # composed of its parts, not mixed from them


def _widgets_taking_the_core(source: str) -> list[str]:
    """Classes whose ``__init__`` takes the whole core (a parameter named ``workbench`` or ``core``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if (
                    isinstance(item, ast.FunctionDef)
                    and item.name == "__init__"
                    and any(a.arg in ("workbench", "core") for a in item.args.args)
                ):
                    found.append(node.name)
    return found


def _widget_modules_where(found) -> set[str]:
    """The window's modules but its assembly (main_window.py) in which ``found(source)`` finds something."""
    return {p.name for p in (ROOT / "app" / "gui").glob("*.py") if p.name != "main_window.py" and found(p.read_text())}


def test_the_panes_are_given_the_parts_they_show():
    assert _widgets_taking_the_core("class P:\n    def __init__(self, workbench, parent=None):\n        pass\n") == [
        "P"
    ]
    # the window (main_window.py) alone assembles the panes from the core
    taking = _widget_modules_where(_widgets_taking_the_core)
    assert not taking, f"given the whole core: {sorted(taking)}"
    # the camera pane shows the frames and the pairs being made, the vision panel the core's camera calibration,
    # the replay bar the core's replay, the pairs table the session, and so on: they exist and take no core
    given_parts = {"camera_pane.py", "virtual_pane.py", "vision_panel.py", "replay_bar.py", "pairs_table.py"}
    given_parts |= {
        "overview_pane.py",
        "results_panel.py",
        "tool_group.py",
        "robot_panel.py",
        "cell_panel.py",
        "command_panel.py",
    }
    assert given_parts <= {p.name for p in (ROOT / "app" / "gui").glob("*.py")} and given_parts.isdisjoint(taking)


def _touches_the_core(source: str) -> list[int]:
    """Lines where code touches a ``workbench`` attribute: the whole core, however the object holding it is named
    (``self.window.workbench``, ``wb = w.workbench``)."""
    return sorted(
        {n.lineno for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Attribute) and n.attr == "workbench"}
    )


def test_no_widget_reaches_the_core_through_the_window():
    # By what a widget's code touches, not by a parameter's name: Find points once took the window and reached
    # ``self.window.workbench.finder`` eight times; it is now given the finder and two callbacks.
    assert _touches_the_core("class F:\n    def run(self):\n        return self.window.workbench.finder\n") == [3]
    touching = _widget_modules_where(_touches_the_core)
    assert not touching, f"reach the core through the window: {sorted(touching)}"
    assert "found_points.py" not in touching


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


_CORE_PARTS = {
    "log",
    "cell",
    "session",
    "tasks",
    "observations",
    "frames",
    "refining",
    "arm",
    "picking",
    "finder",
    "moves",
    "robot_calibration",
    "recording",
    "tool",
    "desk",
    "vision",
    "replay",
    "files",
    "editor",
}


def _reaches_a_part_through_another(source: str) -> list[str]:
    """``self.<given>.<part>``: code reaching one of the core's parts through another part it was given (the vision
    panel once said its messages through ``self.vision.log``)."""
    return sorted(
        f"{n.lineno}: self.{n.value.attr}.{n.attr}"
        for n in ast.walk(ast.parse(source))
        if isinstance(n, ast.Attribute)
        and n.attr in _CORE_PARTS
        and isinstance(n.value, ast.Attribute)
        and isinstance(n.value.value, ast.Name)
        and n.value.value.id == "self"
    )


def test_no_widget_reaches_a_part_through_another():
    assert _reaches_a_part_through_another("class V:\n    def f(self):\n        self.vision.log.say('x')\n") == [
        "3: self.vision.log"
    ]
    reaching = {
        p.name: found
        for p in (ROOT / "app" / "gui").glob("*.py")
        if p.name != "main_window.py" and (found := _reaches_a_part_through_another(p.read_text()))
    }
    assert not reaching, f"given a part and reaching another through it: {reaching}"


_MANY_MEMBERS = 12
"""About ten: a class of the core with more public members says why in its docstring ("public members")."""


def _public_members(cls: ast.ClassDef) -> set[str]:
    """A class's public methods and properties, its psygnal signals, and the public attributes its ``__init__`` sets."""
    names = set()
    for node in cls.body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            names.add(node.name)
        elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
            if getattr(node.value.func, "id", None) == "Signal":
                names |= {t.id for t in node.targets if isinstance(t, ast.Name) and not t.id.startswith("_")}
        elif isinstance(node, ast.FunctionDef) and node.name == "__init__":
            for assign in ast.walk(node):
                targets = assign.targets if isinstance(assign, ast.Assign) else [getattr(assign, "target", None)]
                for target in targets:
                    for t in target.elts if isinstance(target, ast.Tuple) else [target]:
                        if (
                            isinstance(t, ast.Attribute)
                            and isinstance(t.value, ast.Name)
                            and t.value.id == "self"
                            and not t.attr.startswith("_")
                        ):
                            names.add(t.attr)
    return names


def _crowded_without_reason(source: str) -> list[str]:
    return [
        f"{node.name} ({len(members)})"
        for node in ast.parse(source).body
        if isinstance(node, ast.ClassDef)
        and len(members := _public_members(node)) > _MANY_MEMBERS
        and "public members" not in (ast.get_docstring(node) or "")
    ]


def test_no_class_of_the_core_holds_many_members_without_saying_why():
    probe = "class C:\n    def __init__(self):\n" + "".join(f"        self.a{k} = {k}\n" for k in range(13))
    assert _crowded_without_reason(probe) == ["C (13)"]
    assert _crowded_without_reason('class C:\n    """Its public members: ..."""\n' + probe.split("\n", 1)[1]) == []
    crowded = {
        str(p.relative_to(ROOT)): found
        for p in (ROOT / "calib_core").rglob("*.py")
        if (found := _crowded_without_reason(p.read_text()))
    }
    assert not crowded, crowded


_ASSEMBLY = {"main_window.py", "workbench.py", "cell_launcher.py"}
"""The window's assembly: it builds the core (workbench, cell_launcher) and composes each pane's model from the
core's parts (main_window); every other module of the window is a view."""


def _core_models_imported(source: str) -> list[str]:
    """The classes of the core's state a module imports (the operator's parts and the pane models in
    ``calib_core.operator``, the calibration session): its arrows into the core's models. Exceptions and constants
    are not models."""
    import importlib

    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.ImportFrom) or not node.module:
            continue
        if not (node.module.startswith("calib_core.operator") or node.module == "calib_core.calibration.session"):
            continue
        module = importlib.import_module(node.module)
        for alias in node.names:
            thing = getattr(module, alias.name, None)
            if isinstance(thing, type) and not issubclass(thing, BaseException):
                found.append(f"{node.module}.{alias.name}")
    return sorted(set(found))


def test_every_view_has_one_arrow_into_the_core_s_models():
    # What a view can touch is what it imports: the camera pane once took six parts (the cell, the frames, the
    # picking, the session, the arm, Find points); it now takes its CameraPaneModel, and a second part imported to
    # be given it would show here, whatever the parameter is called.
    probe = (
        "from calib_core.operator.arm import Arm\n"
        "from calib_core.operator.move_preview import MoveNeedsConfirmation\n"  # an exception: no model
        "from calib_core.operator.calibration_run import VIA\n"  # a constant
        "def f():\n    from calib_core.calibration.session import CalibrationSession\n"
    )
    assert _core_models_imported(probe) == [
        "calib_core.calibration.session.CalibrationSession",
        "calib_core.operator.arm.Arm",
    ]
    crowded = {
        p.name: found
        for p in (ROOT / "app" / "gui").glob("*.py")
        if p.name not in _ASSEMBLY and len(found := _core_models_imported(p.read_text())) > 1
    }
    assert not crowded, f"views importing more than one of the core's models: {crowded}"


_VIEW_SUFFIXES = ("Pane", "Panel", "Table", "Bar", "Line")


def _core_objects_given(call: ast.Call) -> list[str]:
    """The arguments of ``call`` that hand over an object of the core: a part reached from the workbench
    (``workbench.session``, ``wb.cell``) or a model composed of parts (``CameraPaneModel(...)``). A bound method
    (``workbench.log.say``) or a lambda hands over one capability, not a model."""
    given = []
    for arg in list(call.args) + [k.value for k in call.keywords]:
        if isinstance(arg, ast.Call) and getattr(arg.func, "id", "").endswith("Model"):
            given.append(arg.func.id)
        elif isinstance(arg, ast.Attribute) and arg.attr in _CORE_PARTS and isinstance(arg.value, ast.Name):
            given.append(f"{arg.value.id}.{arg.attr}")
    return given


def test_the_window_gives_each_pane_one_model():
    probe = ast.parse("CameraPane(wb.cell, wb.frames)\nReplayBar(wb.replay, lambda f: wb.frames.observe(f))\n")
    calls = [n for n in ast.walk(probe) if isinstance(n, ast.Call) and getattr(n.func, "id", "") in ("CameraPane",)]
    assert _core_objects_given(calls[0]) == ["wb.cell", "wb.frames"]
    source = (ROOT / "app" / "gui" / "main_window.py").read_text()
    views = [
        n
        for n in ast.walk(ast.parse(source))
        if isinstance(n, ast.Call) and getattr(n.func, "id", "").endswith(_VIEW_SUFFIXES)
    ]
    names = {v.func.id for v in views}
    assert {"CameraPane", "VirtualPane", "OverviewPane", "PairsTable", "ResultsPanel", "CommandPanel"} <= names
    assert {"CellPanel", "RobotPanel", "VisionPanel", "ReplayBar", "StatusLine"} <= names
    given_more = {v.func.id: found for v in views if len(found := _core_objects_given(v)) != 1}
    assert not given_more, f"panes given other than one of the core's models: {given_more}"
