"""The length units a mesh file may be in."""

MESH_SCALE = {"mm": 1.0, "cm": 10.0, "m": 1000.0}
"""A mesh's units -> mm."""
