"""A package's public names loaded from their submodules on first use (PEP 562), so importing one submodule of a
heavy package (the solver's numba kernels, the robot's Pinocchio model) does not load the rest."""

from __future__ import annotations

import importlib
from collections.abc import Callable


def lazy_exports(package: str, where: dict[str, str]) -> Callable[[str], object]:
    """The module ``__getattr__`` of ``package`` that imports ``package.<where[name]>`` when ``name`` is first asked
    for; any other name is an :class:`AttributeError` as for a plain module."""

    def __getattr__(name: str) -> object:
        if name in where:
            return getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
