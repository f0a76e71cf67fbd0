"""The real-photo page's pictures of what the truth is worth (``bench/real_photos.py``): the outline at the annotation
and at the look's answer drawn on the photo, for views where they part."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bench.real_views import view_prior

OVERLAID = ("lmo_dev/test/000002/000178/2", "lmo_dev/test/000002/000365/0")
"""Views whose truth and answer are drawn on the photo for the page (an ok answer scored 9 and 16 px off)."""


def truth_overlays(root: Path, images: Path) -> list[str]:
    """The outline at the truth (green) and at ``locate``'s answer from 10 mm / 3 deg off (red) on the photo, cropped
    and enlarged four times, for each of :data:`OVERLAID` found, written to the folder ``images``; the page's lines
    that show them."""
    import cv2

    from calib_core.camera.projection import project_points
    from calib_core.datasets.bop import BopDataset
    from calib_core.mesh_files import load_mesh
    from calib_core.look.locate import locate
    from calib_core.look.outline import outline_samples

    folder = root / "lmo_dev"
    if not (folder / "test").is_dir():
        return ["(lmo_dev not found: no overlay drawn)"]
    dataset = BopDataset(folder, "test")
    out = [
        "LM-O's truth comes from the Kinect's depth images, registered to its colour camera: in the colour photo it "
        "can lie several pixels off the object as seen. Green: the object's outline at the truth; red: at the answer "
        "`locate` called `ok` from 10 mm / 3 deg off. Where the red follows the object and the green does not, an "
        "answer scored 5-16 px off is the annotation's error as much as the look's: the within-5-px figures above are "
        "bounded by it.",
        "",
    ]
    wanted = {key: None for key in OVERLAID}
    for view in dataset.views(min_visible=0.5):
        if view.key in wanted:
            wanted[view.key] = view
    for key, view in wanted.items():
        if view is None:
            continue
        mesh = load_mesh(dataset.models()[view.obj_id].path)
        image = cv2.imread(str(view.image_path))
        prior = view_prior(view, 10.0, 3.0)
        located = locate(
            np.ascontiguousarray(image[:, :, ::-1]), view.intrinsics, mesh, prior, reach_mm=10, reach_deg=3, features={}
        )
        drawn = image.copy()
        for pose, colour in ((view.obj2cam, (0, 200, 0)), (located.obj2cam, (0, 0, 255))):
            if pose is None:
                continue
            outline = outline_samples(mesh, pose, view.intrinsics, 1.0)
            for u, v in project_points(outline.points_mm, pose, view.intrinsics):
                cv2.circle(drawn, (int(round(u)), int(round(v))), 0, colour, -1)
        uv = project_points(np.asarray(mesh.vertices), view.obj2cam, view.intrinsics)
        lo = np.maximum(uv.min(axis=0).astype(int) - 15, 0)
        hi = uv.max(axis=0).astype(int) + 15
        crop = cv2.resize(drawn[lo[1] : hi[1], lo[0] : hi[0]], None, fx=4, fy=4, interpolation=cv2.INTER_NEAREST)
        name = "real_photo_truth_" + key.replace("/", "_") + ".png"
        cv2.imwrite(str(images / name), crop)
        out += [f"![{key}, `{located.status}`](images/{name})", ""]
    return out
