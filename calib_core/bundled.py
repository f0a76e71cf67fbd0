"""Where the bundled resources are: light enough for a command's --help to name them without loading anything."""

from pathlib import Path

RESOURCES = Path(__file__).resolve().parents[1] / "resources"
DEFAULT_WORKCELL = RESOURCES / "workcell" / "workcell.yaml"
"""The bundled cell (the paper's test bed)."""
