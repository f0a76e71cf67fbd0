"""The flange's pose from transforms in time: each streamed edge interpolated at a stamp (known answers and
round trips), the chain composed from the flange up to the base, stillness judged on the flange."""

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.bags.tf_track import TfEdge, TfTrack, settled_flange
from calib_core.frames import concat, make_transform, pose_difference


def _edge(parent, child, stamps_s, xyz, rotvecs_deg):
    quats = Rotation.from_rotvec(np.radians(rotvecs_deg)).as_quat()
    return TfEdge(parent, child, (np.asarray(stamps_s) * 1e9).astype(np.int64), np.asarray(xyz, float), quats)


def test_a_streamed_edge_is_its_samples_at_their_stamps_and_halfway_between():
    e = _edge(
        "base", "arm", [0.0, 0.05, 0.1], [[0, 0, 0], [10, 0, 0], [10, 20, 0]], [[0, 0, 0], [0, 0, 90], [0, 0, 90]]
    )
    for k, t in enumerate(e.stamps_ns):  # round trip: a sample comes back as it went in
        d, r = pose_difference(
            e.at(int(t)), make_transform(Rotation.from_quat(e.quat_xyzw[k]).as_matrix(), e.xyz_mm[k])
        )
        assert np.linalg.norm(d) < 1e-9 and np.linalg.norm(r) < 1e-9
    mid = e.at(int(0.025e9))  # known answer: half the way, half the turn about z
    assert np.allclose(mid[:3, 3], [5, 0, 0]) and np.isclose(
        Rotation.from_matrix(mid[:3, :3]).as_rotvec(degrees=True)[2], 45.0
    )
    assert e.at(int(-0.01e9)) is None and e.at(int(0.2e9)) is None  # outside the stream: unknown
    gappy = _edge("base", "arm", [0.0, 0.5], [[0, 0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, 0]])
    assert gappy.at(int(0.25e9)) is None  # samples 0.5 s apart leave the pose between unknown


def test_the_chain_composes_from_the_flange_up_and_stillness_is_the_flange_s():
    stamps = np.arange(0, 2.0, 0.01)
    moving = [[0, 0, 0] if t < 1.0 else [0, 0, 30 * (t - 1.0)] for t in stamps]  # still for 1 s, then turning 30 deg/s
    arm = _edge("base", "forearm", stamps, [[0, 0, 500]] * len(stamps), moving)
    wrist = _edge("forearm", "flange", [0.0], [[0, 300, 0]], [[90, 0, 0]])
    track = TfTrack("base", "flange", (wrist, arm))
    expected = concat(
        make_transform(Rotation.from_rotvec([np.pi / 2, 0, 0]).as_matrix(), [0, 300, 0]),
        make_transform(np.eye(3), [0, 0, 500]),
    )
    pose, why = settled_flange(track, int(0.5e9))
    assert why is None and np.allclose(pose, expected)
    pose, why = settled_flange(track, int(1.5e9))
    assert pose is None and "the flange moved" in why and "not a still view" in why
    pose, why = settled_flange(track, int(0.1e9))  # the window reaches before the stream's start
    assert pose is None and "no transform from flange to base all round it" in why
