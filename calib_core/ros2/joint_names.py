"""Joint states that name other joints than the cell's robot: what to tell the user, and the renaming that would
match them when there is one (a prefix the driver adds, say)."""

from __future__ import annotations


def foreign_joints_text(topic: str, received: list[str], wanted: list[str]) -> str:
    """What to tell a user whose joint states name other joints than the cell's robot: which names came, which are
    missing, and the renaming that would match them when one does (a prefix the driver adds, say)."""
    missing = [n for n in wanted if n not in received]
    text = (
        f"{topic} arrives without this cell's joints: it names {', '.join(received[:8]) or 'no joint'}"
        f"{' ...' if len(received) > 8 else ''}; missing {', '.join(missing[:6])}{' ...' if len(missing) > 6 else ''}"
    )
    mapping = suggest_joint_names(wanted, received)
    if mapping:
        pairs = ", ".join(f"{a} -> {b}" for a, b in list(mapping.items())[:3])
        text += (
            f"; they look like this robot's with other names ({pairs}{' ...' if len(mapping) > 3 else ''}): use "
            "the driver's URDF for the cell"
        )
    else:
        text += ": is this the cell's robot (another arm, a gripper's group)?"
    return text


def suggest_joint_names(wanted: list[str], received: list[str]) -> dict[str, str] | None:
    """Each wanted joint's received name when every one is found by a name that ends with it or that it ends with
    (``ur10e_shoulder_pan_joint`` for ``shoulder_pan_joint``), one to one; else None."""
    found = {}
    for name in wanted:
        matches = [r for r in received if r != name and (r.endswith(name) or name.endswith(r))]
        if len(matches) != 1:
            return None
        found[name] = matches[0]
    return found if len(set(found.values())) == len(found) else None
