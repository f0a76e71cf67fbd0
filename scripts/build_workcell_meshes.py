"""Build the bundled workcell's meshes from trimesh primitives and write them as binary STL, in mm.

Run from the project root: ``.venv/bin/python scripts/build_workcell_meshes.py``. The meshes are
committed; this script documents how they were made and re-makes them. Each mesh is in its
component's own frame, the frame the feature points of ``resources/workcell/workcell.yaml`` use.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

OUT = Path(__file__).resolve().parents[1] / "resources" / "workcell" / "meshes"


def box(size, centre):
    m = trimesh.creation.box(extents=size)
    m.apply_translation(centre)
    return m


def cylinder(radius, height, centre, axis="z", sections=32):
    m = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    if axis == "x":
        m.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    elif axis == "y":
        m.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
    m.apply_translation(centre)
    return m


def rack():
    """A storage rack: frame x 0..600 (width, y in the frame), origin at the front-left foot.

    Frame: x toward the back (depth 400), y to the left (width 600), z up (height 1700).
    Shelves at z = 520, 1238 (the one the grasp uses, top at 1258) and 1620."""
    parts = []
    for x in (15, 385):
        for y in (15, 585):
            parts.append(box((30, 30, 1700), (x, y, 850)))
    for z in (520, 1238, 1620):
        parts.append(box((400, 600, 20), (200, 300, z + 10)))
    parts.append(box((10, 600, 1700), (395, 300, 850)))  # back panel
    return trimesh.util.concatenate(parts)


def orbital_unit():
    """An orbital replacement unit's body (its grappling fixture is a separate component).

    Frame: origin at the centre of the front face's fixture plate surface; x out of the face
    (toward the robot), y to the right as seen from the robot, z up. The body lies behind
    (x < -6, under the 6 mm plate), 300 wide, 220 high, 280 deep, its bottom at z = -110."""
    return box((280, 300, 220), (-140 - 6, 0, 0))


def grappling_fixture():
    """The grappling fixture on an ORU's front face, in the ORU's frame: a 160 x 120 x 6 mm plate,
    a pin (radius 12, 40 long) with a knob, and four target bosses (radius 10, 4 high)."""
    plate = box((6, 160, 120), (-3, 0, 0))
    pin = cylinder(12, 40, (20, 0, 0), axis="x", sections=24)
    knob = cylinder(20, 10, (40, 0, 0), axis="x", sections=24)
    bosses = [
        cylinder(10, 4, (2, y, z), axis="x", sections=20) for y, z in ((-55, 40), (55, 40), (-55, -40), (55, -40))
    ]
    return trimesh.util.concatenate([plate, pin, knob, *bosses])


def drawer():
    """A drawer unit: frame at the front face centre, x out of the face, y to the right as seen from the robot, z up."""
    cabinet = box((400, 500, 300), (-200, 0, 0))
    front = box((10, 460, 240), (5, 0, 0))
    handle = box((20, 200, 20), (25, 0, 60))
    return trimesh.util.concatenate([cabinet, front, handle])


def tool_station():
    """A tool station table with a tool holder: frame at the floor centre, z up."""
    top = box((500, 500, 30), (0, 0, 885))
    legs = [box((40, 40, 870), (x, y, 435)) for x in (-220, 220) for y in (-220, 220)]
    holder = box((160, 160, 120), (0, 0, 960))
    return trimesh.util.concatenate([top, *legs, holder])


def gripper_tool():
    """A spare two-finger gripper standing in its holder: frame at its mounting face centre."""
    return trimesh.util.concatenate(
        [
            cylinder(45, 20, (0, 0, 10)),
            box((100, 120, 80), (0, 0, 60)),
            box((16, 40, 80), (35, 0, 140)),
            box((16, 40, 80), (-35, 0, 140)),
        ]
    )


def screwdriver_tool():
    """A screwdriver tool in its holder: frame at its mounting face centre."""
    return trimesh.util.concatenate(
        [cylinder(45, 20, (0, 0, 10)), cylinder(35, 160, (0, 0, 100)), cylinder(6, 90, (0, 0, 225), sections=16)]
    )


def floor():
    """The floor plate: 4 m x 4 m, top surface at z = 0."""
    return box((4000, 4000, 20), (500, 0, -10))


MESHES = {
    "rack.stl": rack,
    "orbital_unit.stl": orbital_unit,
    "grappling_fixture.stl": grappling_fixture,
    "drawer.stl": drawer,
    "tool_station.stl": tool_station,
    "gripper_tool.stl": gripper_tool,
    "screwdriver_tool.stl": screwdriver_tool,
    "floor.stl": floor,
}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    total = 0
    for name, build in MESHES.items():
        mesh = build()
        mesh.export(OUT / name)
        total += len(mesh.faces)
        print(f"{name}: {len(mesh.faces)} triangles")
    print(f"total {total} triangles (one instance each)")


if __name__ == "__main__":
    main()
