"""Plug-ins found by Python entry points, so a user's site, command or connector is a package of
theirs, not a fork of videocal.

Groups:

- ``videocal.sites``: a *site kind* by name (``sim``: the simulated cell of ``videocal_sim``), an
  object with ``open_cell(workcell_path, **options) -> (Cell, Site)``;
- ``videocal.commands``: extra subcommands of ``videocal``, each a module with ``HELP`` (one line),
  ``add_arguments(parser)`` and ``run(args) -> int``, imported only when the command runs.

Nothing here imports a plug-in until it is asked for by name.
"""

from __future__ import annotations

from importlib.metadata import EntryPoint, entry_points

from calib_core.errors import VideocalError

SITES = "videocal.sites"
COMMANDS = "videocal.commands"


class PluginNotFoundError(VideocalError, LookupError):
    """No installed package registers a plug-in of that name in that group."""


def plugin_names(group: str) -> list[str]:
    """The names registered in ``group``, sorted (none imported)."""
    return sorted({ep.name for ep in entry_points(group=group)})


def plugin_entry(group: str, name: str) -> EntryPoint:
    """The entry point ``name`` of ``group``; :class:`PluginNotFoundError` names the installed ones."""
    for ep in entry_points(group=group):
        if ep.name == name:
            return ep
    installed = ", ".join(plugin_names(group)) or "none"
    raise PluginNotFoundError(
        f"no {group.split('.')[-1][:-1]} plug-in named {name!r} is installed (installed: {installed})"
    )


def load_plugin(group: str, name: str):
    """The object the entry point ``name`` of ``group`` names, imported now. A plug-in still registered
    but no longer importable (its package deleted or broken) is a :class:`PluginNotFoundError` that
    says so, not a traceback."""
    ep = plugin_entry(group, name)
    try:
        return ep.load()
    except ImportError as exc:
        raise PluginNotFoundError(
            f"the {group.split('.')[-1][:-1]} plug-in {name!r} is registered ({ep.value}) but cannot be loaded: {exc}"
        ) from None
