"""Entry point of the ``videocal`` console script.

Each subcommand lives in its own module of ``app.cli`` exposing ``add_arguments(parser)``
and ``run(args) -> int``; modules are imported only when their command runs, so
``videocal --help`` is fast and headless commands never load Qt or VTK.

Exit codes shared by every command: 0 success, 2 bad input (one ``error: ...`` line on
stderr, no traceback); commands document their own further codes.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from calib_core import __version__
from calib_core.errors import VideocalError

# name -> (module, one-line help). Add a line here when a command lands.
COMMANDS: dict[str, tuple[str, str]] = {}


def _register(name: str, module: str, help_text: str) -> None:
    COMMANDS[name] = (module, help_text)


_register(
    "gui",
    "app.cli.cmd_gui",
    "open the operator's window (the bundled workcell with simulated robot and camera by default)",
)
_register("solve", "app.cli.cmd_solve", "solve a camera pose from point pairs in a JSON file")
_register("table1", "app.cli.cmd_table1", "reproduce the paper's Table 1 (Newton convergence)")
_register("link-key", "app.cli.cmd_link_key", "name, show or renew the controller link's pre-shared key")
_register("monitor", "app.cli.cmd_monitor", "print the joint samples of any controller connector")
_register("grab", "app.cli.cmd_grab", "save N frames of any camera connector as PNG files and frames.csv")
_register(
    "replay", "app.cli.cmd_replay", "re-solve every calibration in a recording and compare with the recorded results"
)
_register(
    "recover", "app.cli.cmd_recover", "rewrite a recording cut off by a crash, keeping every message before the cut"
)
_register("export", "app.cli.cmd_export", "export a workspace's corrections as JSON, CSV or a PDL2 listing")
_register(
    "calibrate-intrinsics",
    "app.cli.cmd_calibrate_intrinsics",
    "calibrate the camera's intrinsics from ChArUco board views (folder, video or 'sim')",
)
_register(
    "calibrate-hand-eye",
    "app.cli.cmd_calibrate_hand_eye",
    "calibrate the camera's mounting from robot poses viewing a board (sim, cal_data.yaml, CSV)",
)
_register(
    "calibrate-robot",
    "app.cli.cmd_calibrate_robot",
    "identify the robot's geometric parameters and camera mounting from board views at many poses",
)
_register(
    "new-cell",
    "app.cli.cmd_new_cell",
    "write a starting cell for a robot description (URDF or xacro): loads and renders at once",
)
_register(
    "locate",
    "app.cli.cmd_locate",
    "a known object's pose in a photo (mesh, intrinsics, rough pose): Find points and the edge fit, as JSON",
)
_register(
    "render", "app.cli.cmd_render", "render the workcell to a PNG (virtual camera, overview, or simulated true camera)"
)


def _register_plugins() -> None:
    """Subcommands that installed packages register (``videocal.commands``; the simulator's ``demo``):
    imported only when they run, like ours; one of ours is never replaced."""
    from calib_core.plugins import COMMANDS as GROUP
    from importlib.metadata import entry_points

    for ep in entry_points(group=GROUP):
        if ep.name not in COMMANDS:
            COMMANDS[ep.name] = (ep.value, None)


_register_plugins()


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit 2, as for every bad input
        self.print_usage(sys.stderr)
        if message.endswith("expected one argument"):
            # "--joints -20,10,..." reads "-20,..." as an option: say how a value that starts with "-" is given
            option = message.removeprefix("argument ").split(":")[0].split("/")[-1]
            message += f" (a value that starts with '-' is given as {option}=VALUE, e.g. {option}=-20,10,30)"
        print(f"error: {message}", file=sys.stderr)
        raise SystemExit(2)


def _plugin_help(module: str) -> str:
    """A plug-in command's one line (its module's ``HELP``); one that cannot be imported says so
    instead of taking every other command down with it."""
    try:
        return getattr(importlib.import_module(module), "HELP", f"(from {module})")
    except ImportError as exc:
        return f"(cannot be loaded: {exc})"


def build_parser(*, plugin_help: bool = True) -> argparse.ArgumentParser:
    """``plugin_help``: import the plug-in commands' modules for their one-line help (only when the
    list of commands may be shown)."""
    parser = _Parser(prog="videocal", description="Remote video calibration of a robot workcell.")
    parser.add_argument("--version", action="version", version=f"videocal {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, (module, help_text) in COMMANDS.items():
        if help_text is None:  # a plug-in's: its one line is the module's HELP
            help_text = _plugin_help(module) if plugin_help else f"(from {module})"
        sp = sub.add_parser(name, help=help_text, description=help_text)
        sp.set_defaults(_module=module)
        # Arguments are declared by the module itself, imported lazily only for this parser.
        sp.set_defaults(_add_arguments=None)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    first = next((a for a in argv if not a.startswith("-")), None)
    parser = build_parser(plugin_help=first not in COMMANDS)  # a command's run imports no other plug-in
    # Let the chosen command's module declare its arguments before the full parse.
    if first in COMMANDS:
        try:
            module = importlib.import_module(COMMANDS[first][0])
        except ImportError as exc:  # a registered plug-in whose package is gone or broken
            print(f"error: the command {first!r} cannot be loaded: {exc}", file=sys.stderr)
            return 2
        module.add_arguments(parser._subparsers._group_actions[0].choices[first])  # type: ignore[union-attr]
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    module = importlib.import_module(args._module)
    try:
        return int(module.run(args) or 0)
    except (VideocalError, ValueError, FileNotFoundError, IsADirectoryError, PermissionError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # The reader went away (``videocal ... | head``): not an error of ours, and nothing more to say.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
