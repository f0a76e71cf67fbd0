"""The edge fit's noise model: samples of one edge chain share its error (a cluster-robust covariance)."""

import numpy as np
import trimesh

from calib_core.look.edge_alignment import crease_segments
from calib_core.solver.clustered_covariance import clustered_scatter
from calib_core.look.edge_samples import edge_chains


def test_a_box_has_twelve_chains_and_a_cylinder_s_rims_one_each():
    box_segments, _ = crease_segments(trimesh.creation.box((40.0, 30.0, 10.0)))
    assert len(np.unique(edge_chains(box_segments))) == 12  # its edges meet at right angles: none join
    cylinder = trimesh.creation.cylinder(radius=5.0, height=8.0, sections=32)
    segments, _ = crease_segments(cylinder)
    chains = edge_chains(segments)
    rims = [np.flatnonzero(np.isclose(segments[:, :, 2], z).all(axis=1)) for z in (-4.0, 4.0)]
    for rim in rims:
        assert len(rim) == 32 and len(np.unique(chains[rim])) == 1  # 11 deg a facet: one chain round
    assert chains[rims[0][0]] != chains[rims[1][0]]


def test_an_open_box_s_rim_is_among_its_creases():
    """Known answer: a box with its top's two triangles taken away has the top's four edges as its rim, each with its
    one face left (a side); the top's diagonal, which the two missing triangles shared, belongs to no face and is
    not an edge at all."""
    box = trimesh.creation.box((40.0, 30.0, 10.0))
    top = np.flatnonzero(np.isclose(box.face_normals[:, 2], 1.0))
    assert len(top) == 2
    open_box = trimesh.Trimesh(box.vertices, np.delete(box.faces, top, axis=0), process=False)
    segments, normals = crease_segments(open_box)
    on_top = np.isclose(segments[:, :, 2], 5.0).all(axis=1)
    assert on_top.sum() == 4  # the rim, each edge once; no diagonal (it belongs to no face now)
    lengths = np.sort(np.linalg.norm(segments[on_top, 1] - segments[on_top, 0], axis=1))
    np.testing.assert_allclose(lengths, [30.0, 30.0, 40.0, 40.0])
    # a rim edge repeats its one face's normal: a side's, turned out of the box
    np.testing.assert_allclose(normals[on_top, 0], normals[on_top, 1])
    assert np.allclose(normals[on_top, :, 2], 0.0)


def test_the_chained_scatter_grows_with_a_shared_error_and_never_falls_below_the_independent():
    rng = np.random.default_rng(0)
    m, sigma = 2000, 0.1
    chain = np.repeat(np.arange(20), m // 20)
    J = rng.normal(size=(20, 6))[chain] + 0.3 * rng.normal(size=(m, 6))  # the samples of one edge move alike
    H = J.T @ J
    independent = sigma**2 * H
    # independent offsets, each sample its own chain: the scatter is sigma^2 H (the sandwich is consistent)
    alone = clustered_scatter(J, rng.normal(0, sigma, m), np.arange(m), independent)
    assert np.allclose(alone, independent, rtol=0.25, atol=0.25 * sigma**2 * np.abs(H).max())
    # the same noise plus an offset shared by each chain's samples: the scatter grows, in every direction no less
    shared = rng.normal(0, sigma, m) + np.repeat(rng.normal(0, sigma, 20), m // 20)
    grown = clustered_scatter(J, shared, chain, independent)
    assert np.trace(grown) > 5 * np.trace(independent)
    assert np.linalg.eigvalsh(grown - independent).min() > -1e-9 * np.trace(grown)


def test_a_part_metres_across_chains_as_the_same_part_small():
    # (points within 2 m are told apart by one packed integer, beyond by their rows: the same chains either way)
    for scale in (1.0, 100.0):  # a 4 m box and a 10 m cylinder at 100 x
        box_segments, _ = crease_segments(trimesh.creation.box((40.0 * scale, 30.0 * scale, 10.0 * scale)))
        assert len(np.unique(edge_chains(box_segments))) == 12
        cylinder = trimesh.creation.cylinder(radius=5.0 * scale, height=8.0 * scale, sections=32)
        segments, _ = crease_segments(cylinder)
        chains = edge_chains(segments)
        for z in (-4.0 * scale, 4.0 * scale):
            rim = np.flatnonzero(np.isclose(segments[:, :, 2], z).all(axis=1))
            assert len(rim) == 32 and len(np.unique(chains[rim])) == 1
