"""The look as ``videocal locate`` calls it: for a mesh whose edge samples are its creases rather than its outline (a
CAD-like mesh: HANDAL's tools, OpenCV's box; not LM-O's scans), the command renders the model's view so that the
look leaves out creases without contrast (``app/cli/cmd_locate.py``). The bench's own rows call ``locate`` without
it; these rows say what the command gives from the same priors."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from bench.photo_runs import PRIORS, Row, Tally


@contextmanager
def model_view_of(mesh, view):
    """The model's view as the command makes it (``obj2cam -> image``: the object alone in the view's camera), or
    ``None`` for a mesh whose samples are its outline (the command starts no renderer for it)."""
    from calib_core.look.edge_samples import edge_model

    if edge_model(mesh, view.obj2cam, view.intrinsics).from_outline:
        yield None
        return
    from calib_core.render.model_view import ModelView
    from calib_core.scene import SceneItem

    renderer = ModelView(view.intrinsics)
    try:
        yield renderer.of([SceneItem("object", mesh, np.eye(4), color=(0.75, 0.75, 0.75))], np.eye(4))
    finally:
        renderer.close()


def command_section(rows: list[Row], commanded: list[Row]) -> list[str]:
    """Per data set and prior, the command's way (with the model's view) beside the bench's own rows on the same views
    from the same priors: within MSPD 5 px, ``ok``, wrong ``ok``, uncertain, not found, median seconds."""
    if not commanded:
        return ["No mesh measured here is one the command renders a model's view of: the rows above are its own."]
    out = [
        "For the meshes whose edge samples are creases (a CAD-like mesh) `videocal locate` renders the model's view "
        "and "
        "the look leaves out creases without contrast; the rows above call `locate` without it. The same views from "
        "the same priors both ways:",
        "",
        "| data set | prior | way | views | within MSPD 5 px | ok | wrong ok (> 10 px) | uncertain | not found | "
        "s a view (median) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in sorted({r.dataset for r in commanded}):
        for prior in PRIORS:
            ours = [r for r in commanded if r.dataset == name and r.prior == prior]
            keys = {r.key for r in ours}
            theirs = [r for r in rows if r.dataset == name and r.run == (prior, prior) and r.key in keys]
            for way, rs in (("without the model's view (above)", theirs), ("as the command: with it", ours)):
                if not rs:
                    continue
                t = Tally.of(rs)
                out.append(
                    f"| {name} | {prior[0]:g} mm / {prior[1]:g} deg | {way} | {t.views} | {t.within_5} | {t.ok} | "
                    f"{t.wrong_ok} | {t.uncertain} | {t.not_found} | {np.median([r.seconds for r in rs]):.1f} |"
                )
    return out
