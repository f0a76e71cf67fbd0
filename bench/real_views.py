"""Which real photographs the benches measure on, and from where: the BOP-format data sets found, the seeded sample
of each set's views with half or more in sight, and each view's seeded prior. Shared by videocal's rows and the
peers' (``bench/real_photos.py``, ``bench/real_photos_peers.py``), so that both see the same views from the same
priors."""

from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np

from bench.photo_priors import moved_prior

PROJECT = Path(__file__).resolve().parent.parent
HELD_BACK = {"lmo"}
HELD_BACK_SCENES = {("lm", 2)}
SPLITS = ("test", "test_primesense", "val", "test_primesense_bop19")


def datasets_root(given: str | None = None) -> Path:
    """Where the data sets are: ``given``, ``$VIDEOCAL_DATASETS``, the shared folder beside the project, the cache."""
    if given:
        return Path(given).expanduser().resolve()
    if os.environ.get("VIDEOCAL_DATASETS"):
        return Path(os.environ["VIDEOCAL_DATASETS"]).expanduser()
    shared = PROJECT.parent / "shared" / "datasets"
    if shared.is_dir():
        return shared
    return Path.home() / ".cache" / "videocal" / "datasets"


def found_datasets(root: Path):
    from calib_core.datasets.bop import BopDataset

    if not root.is_dir():
        return []
    out = []
    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        if folder.name.lower() in HELD_BACK:
            continue
        for split in SPLITS:
            if (folder / split).is_dir() and (folder / "models" / "models_info.json").exists():
                out.append(BopDataset(folder, split))
                break
    return out


def chosen_views(dataset, views_per_set: int) -> list:
    """A seeded sample of at most ``views_per_set`` of ``dataset``'s views with half or more in sight, held-back
    scenes left out; the same on every run."""
    chosen = [v for v in dataset.views(min_visible=0.5) if (dataset.name, v.scene_id) not in HELD_BACK_SCENES]
    rng = np.random.default_rng(48)
    if len(chosen) > views_per_set:
        chosen = [chosen[i] for i in sorted(rng.choice(len(chosen), views_per_set, replace=False))]
    return chosen


def view_prior(view, mm: float, deg: float, seed: str = "") -> np.ndarray:
    """The prior (4, 4) of ``view``: its truth moved ``mm`` in a random direction and turned ``deg`` about a random
    axis, seeded by the view, the distance and ``seed`` (empty: the bench's own priors; another word, another draw
    of them, as :mod:`bench.photo_seeds` takes)."""
    salt = f"{view.key}/{mm:g}" + (f"/{seed}" if seed else "")
    return moved_prior(view.obj2cam, mm, deg, np.random.default_rng(zlib.crc32(salt.encode())))
