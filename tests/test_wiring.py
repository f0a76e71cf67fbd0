"""Who is given what: the operator's parts are given their dependencies, never the core; each pane is given one model
that the window composes; no widget reaches the core through the window or one part through another; a class of the
core with many members says why. By what the code touches, not by parameter names."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _classes_taking(source: str, names: tuple[str, ...]) -> list[str]:
    """Classes whose ``__init__`` takes a parameter of one of ``names``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if (
                    isinstance(item, ast.FunctionDef)
                    and item.name == "__init__"
                    and any(a.arg in names for a in item.args.args)
                ):
                    found.append(node.name)
    return found


def _parts_taking_the_core(source: str) -> list[str]:
    """Classes whose ``__init__`` takes a parameter named ``core`` (a part handed the whole program)."""
    return _classes_taking(source, ("core",))


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
    return _classes_taking(source, ("workbench", "core"))


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


def _frame_widget(call: ast.Call) -> bool:
    """A widget of the window's frame, given the window alone as its Qt parent (``MessageStatusBar(self)``): it shows
    nothing of the core, so it is no pane."""
    return not call.keywords and len(call.args) == 1 and getattr(call.args[0], "id", "") == "self"


def test_the_window_gives_each_pane_one_model():
    probe = ast.parse("CameraPane(wb.cell, wb.frames)\nReplayBar(wb.replay, lambda f: wb.frames.observe(f))\n")
    calls = [n for n in ast.walk(probe) if isinstance(n, ast.Call) and getattr(n.func, "id", "") in ("CameraPane",)]
    assert _core_objects_given(calls[0]) == ["wb.cell", "wb.frames"]
    source = (ROOT / "app" / "gui" / "main_window.py").read_text()
    views = [
        n
        for n in ast.walk(ast.parse(source))
        if isinstance(n, ast.Call) and getattr(n.func, "id", "").endswith(_VIEW_SUFFIXES) and not _frame_widget(n)
    ]
    names = {v.func.id for v in views}
    assert {"CameraPane", "VirtualPane", "OverviewPane", "PairsTable", "ResultsPanel", "CommandPanel"} <= names
    assert {"CellPanel", "RobotPanel", "VisionPanel", "ReplayBar", "StatusLine"} <= names
    given_more = {v.func.id: found for v in views if len(found := _core_objects_given(v)) != 1}
    assert not given_more, f"panes given other than one of the core's models: {given_more}"
