"""The compiled solve for four and five pairs: its P3P against OpenCV's, its quartic against
numpy's roots, its answers against OpenCV's SQPnP + LM, and an ambiguity it must hand to the full
search (two exact poses built on purpose)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from calib_core.solver import SolveStatus, solve_pose
from calib_core.solver.kernels.p3p import _real_quartic_roots, p3p

from tests.core.solver.scenes import PINHOLE_CAMERA, pixels, pose_error, random_points, random_pose


def _K():
    c = PINHOLE_CAMERA
    return np.array([[c.fu, 0.0, c.cx], [0.0, c.fv, c.cy], [0.0, 0.0, 1.0]])


def _rays(P, pose):
    X = P @ pose[:3, :3].T + pose[:3, 3]
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def test_p3p_finds_the_roots_opencv_finds():
    rng = np.random.default_rng(5)
    K = _K()
    compared = 0
    for _ in range(200):
        truth = random_pose(rng)
        P = random_points(rng, 3)
        Rs, ts = np.zeros((4, 3, 3)), np.zeros((4, 3))
        n = p3p(P, _rays(P, truth), Rs, ts)
        m, rvecs, tvecs = cv2.solveP3P(
            P.reshape(3, 1, 3),
            pixels(P, truth, intrinsics=PINHOLE_CAMERA).reshape(3, 1, 2),
            K,
            None,
            flags=cv2.SOLVEPNP_P3P,
        )
        assert n == m
        ours = [np.concatenate([Rs[k].ravel(), ts[k] / 500.0]) for k in range(n)]
        for rv, tv in zip(rvecs[:m], tvecs[:m]):
            theirs = np.concatenate([cv2.Rodrigues(rv)[0].ravel(), tv.ravel() / 500.0])
            assert min(np.max(np.abs(o - theirs)) for o in ours) < 1e-3  # both are seeds, each to its own round-off
            compared += 1
        # the truth is one of them (a seed, to a micrometre: near a double root, where two poses
        # merge, the quartic's root loses digits), and every root puts the three points on their rays
        assert (
            min(pose_error(np.vstack([np.column_stack([Rs[k], ts[k]]), [0, 0, 0, 1]]), truth)[0] for k in range(n))
            < 1e-3
        )
        rays = _rays(P, truth)
        for k in range(n):
            X = P @ Rs[k].T + ts[k]
            assert np.all(np.einsum("ij,ij->i", X / np.linalg.norm(X, axis=1, keepdims=True), rays) > 1 - 1e-12)
    assert compared > 250  # most triangles have two roots or more


def test_the_quartic_roots_are_numpys_real_roots():
    rng = np.random.default_rng(7)
    for _ in range(300):
        roots_true = np.sort(rng.uniform(-5, 5, rng.integers(0, 3) * 2))
        # a quartic with those real roots and, for the rest, a complex pair
        poly = np.poly(roots_true)
        for _ in range((4 - len(roots_true)) // 2):
            a, b = rng.uniform(-3, 3), rng.uniform(0.1, 3)
            poly = np.polymul(poly, [1.0, -2 * a, a * a + b * b])
        poly = poly * rng.uniform(0.5, 2.0)
        out = np.zeros(4)
        n = _real_quartic_roots(*poly, out)
        assert n == len(roots_true)
        np.testing.assert_allclose(np.sort(out[:n]), roots_true, atol=1e-8)


@pytest.mark.parametrize("n", [4, 5])
def test_few_pairs_solve_as_opencv_sqpnp_and_lm(n):
    rng = np.random.default_rng(40 + n)
    K = _K()
    agree = 0
    for _ in range(60):
        truth = random_pose(rng)
        P = random_points(rng, n)
        uv = pixels(P, truth, noise_px=0.5, rng=rng, intrinsics=PINHOLE_CAMERA)
        sol = solve_pose(P, uv, PINHOLE_CAMERA)
        assert sol.status in (SolveStatus.OK, SolveStatus.AMBIGUOUS), sol.reason
        ok, rv, tv = cv2.solvePnP(P, uv, K, None, flags=cv2.SOLVEPNP_SQPNP)
        rv, tv = cv2.solvePnPRefineLM(P, uv, K, None, rv, tv)
        cv_pose = np.vstack([np.column_stack([cv2.Rodrigues(rv)[0], tv.ravel()]), [0, 0, 0, 1]])
        cv_rms = np.sqrt(np.mean(np.sum((cv2.projectPoints(P, rv, tv, K, None)[0].reshape(-1, 2) - uv) ** 2, axis=1)))
        assert sol.rms_px <= cv_rms + 1e-9  # never a worse minimum than OpenCV's
        if pose_error(sol.obj2cam, cv_pose)[0] < 1e-6:
            agree += 1
    assert agree >= 55


def _ambiguous_fourth_point(P3, pose_a, pose_b):
    """A point that ``pose_a`` and ``pose_b`` image at the same pixel: on the conic p' F p = 0 of
    the pixels where the two cameras' rays meet, triangulated."""
    K = _K()
    R = pose_b[:3, :3] @ pose_a[:3, :3].T
    t = pose_b[:3, 3] - R @ pose_a[:3, 3]
    tx = np.array([[0, -t[2], t[1]], [t[2], 0, -t[0]], [-t[1], t[0], 0]])
    F = np.linalg.inv(K).T @ tx @ R @ np.linalg.inv(K)
    centre = P3.mean(axis=0)
    aim = pixels(centre[None], pose_a, intrinsics=PINHOLE_CAMERA)[0]
    for du in np.linspace(-300, 300, 61):
        u = aim[0] + du
        # p' F p = 0 with p = (u, v, 1): a quadratic in v
        a = F[1, 1]
        b = (F[0, 1] + F[1, 0]) * u + F[1, 2] + F[2, 1]
        c = F[0, 0] * u * u + (F[0, 2] + F[2, 0]) * u + F[2, 2]
        for v in np.roots([a, b, c]):
            if (
                abs(v.imag) > 1e-9
                or not 20 < v.real < PINHOLE_CAMERA.height - 20
                or not 20 < u < PINHOLE_CAMERA.width - 20
            ):
                continue
            p = np.array([u, v.real])
            Pa = K @ pose_a[:3]
            Pb = K @ pose_b[:3]
            X = cv2.triangulatePoints(Pa, Pb, p.reshape(2, 1), p.reshape(2, 1)).ravel()
            X = X[:3] / X[3]
            za = (pose_a[:3, :3] @ X + pose_a[:3, 3])[2]
            zb = (pose_b[:3, :3] @ X + pose_b[:3, 3])[2]
            if za > 100 and zb > 100 and np.linalg.norm(X - centre) < 150:
                return X
    return None


def test_four_pairs_that_two_poses_fit_exactly_are_reported_ambiguous():
    """The fast path must not answer when a second pose fits as well: it leaves the ambiguity to the
    full search, which reports both."""
    rng = np.random.default_rng(12)
    for _ in range(50):
        truth = random_pose(rng)
        P3 = random_points(rng, 3)
        Rs, ts = np.zeros((4, 3, 3)), np.zeros((4, 3))
        n = p3p(P3, _rays(P3, truth), Rs, ts)
        others = [np.vstack([np.column_stack([Rs[k], ts[k]]), [0, 0, 0, 1]]) for k in range(n)]
        others = [T for T in others if pose_error(T, truth)[1] > 5.0]
        if not others:
            continue
        X = _ambiguous_fourth_point(P3, truth, others[0])
        if X is None:
            continue
        P = np.vstack([P3, X])
        uv = pixels(P, truth, intrinsics=PINHOLE_CAMERA)
        sol = solve_pose(P, uv, PINHOLE_CAMERA, prior=truth)
        assert sol.status is SolveStatus.AMBIGUOUS, (sol.status, sol.reason)
        assert len(sol.candidates) >= 2 and pose_error(sol.obj2cam, truth)[0] < 1e-6
        return
    pytest.fail("no two-pose configuration built in 50 tries")
