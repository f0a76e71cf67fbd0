"""The names the camera's frame goes by in everything videocal gives a ROS system: the live ``/tf_static``, the
mounting's launch file and URDF, and an exported bag. One pair for all of them, from the workcell's ``site:``
section (``camera_frame``: the camera driver's own optical frame, so the mounting attaches to the frame its images
are stamped with; ``camera_parent_frame``: the link it hangs from), else videocal's defaults.
"""

from __future__ import annotations

DEFAULT_CAMERA_FRAME = "videocal_camera_optical_frame"
"""z along the optical axis, x right, y down: ROS's optical-frame convention (REP 103), as videocal's camera frame."""


def camera_frames(workcell, *, static_camera: bool = False, flange_frame: str | None = None) -> tuple[str, str]:
    """``(parent, child)``: the frame the camera hangs from (the site's ``camera_parent_frame``, else the robot's
    flange link: the workcell's, else ``flange_frame`` (the loaded robot's), else ``tool0``; its base link for a
    camera standing in the cell) and the camera's own (the site's ``camera_frame``, else
    :data:`DEFAULT_CAMERA_FRAME`). ``workcell`` may be None (the defaults)."""
    site = getattr(workcell, "site", None)
    frames = (workcell.robot_spec.frames or {}) if workcell is not None else {}
    if static_camera:
        fallback = str(frames.get("base") or "base_link")
    else:
        fallback = str(frames.get("flange") or flange_frame or "tool0")
    parent = getattr(site, "camera_parent_frame", None) or fallback
    child = getattr(site, "camera_frame", None) or DEFAULT_CAMERA_FRAME
    return parent, child
