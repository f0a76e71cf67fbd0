"""Rigid transforms, the one place where frames are composed.

Conventions (see docs/conventions.md):

* A transform is a 4x4 homogeneous matrix named ``a2b``: it maps coordinates in frame
  ``a`` to frame ``b`` (``p_b = a2b @ p_a``). ``concat(a2b, b2c)`` gives ``a2c``.
* Translations are in **millimetres** everywhere in videocal. Rotations are matrices;
  angles are **degrees** at every boundary a user sees and radians only inside,
  in names ending in ``_rad``.
* Survey-style placements are ``(x, y, z)`` mm and ``(roll, pitch, yaw)`` deg, fixed axes
  X then Y then Z (``R = Rz(yaw) Ry(pitch) Rx(roll)``), the convention of URDF ``rpy``.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "check_transform",
    "make_transform",
    "rotation_of",
    "translation_of",
    "invert",
    "concat",
    "apply",
    "transform_from_xyz_rpy",
    "xyz_rpy_from_transform",
    "transform_from_rotvec_deg",
    "rotation_angle_deg",
    "pose_difference",
    "skew",
]


def _rotation():
    """SciPy's ``Rotation``, imported when first needed: ``scipy.spatial`` costs a fifth of a second to import, and
    most commands never turn Euler angles or rotation vectors into matrices."""
    from scipy.spatial.transform import Rotation

    return Rotation


def check_transform(a2b: ArrayLike, *, name: str = "transform", tol: float = 1e-6) -> np.ndarray:
    """Validate a 4x4 rigid transform and return it as a float array.

    Raises ``ValueError`` naming ``name`` when the shape is wrong, a value is not finite,
    the rotation block is not orthonormal with determinant +1, or the last row is not
    ``[0, 0, 0, 1]``.
    """
    m = np.asarray(a2b, dtype=float)
    if m.shape != (4, 4):
        raise ValueError(f"{name}: expected a 4x4 matrix, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"{name}: contains NaN or infinite values")
    R = m[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=tol) or np.linalg.det(R) < 0:
        raise ValueError(f"{name}: rotation block is not a proper rotation matrix")
    if not np.allclose(m[3], [0.0, 0.0, 0.0, 1.0], atol=tol):
        raise ValueError(f"{name}: last row must be [0, 0, 0, 1]")
    return m


def make_transform(R: ArrayLike, t_mm: ArrayLike) -> np.ndarray:
    """Build ``a2b`` from a rotation matrix (3, 3) and a translation (3,) in mm."""
    m = np.eye(4)
    m[:3, :3] = np.asarray(R, dtype=float)
    m[:3, 3] = np.asarray(t_mm, dtype=float).reshape(3)
    return m


def rotation_of(a2b: np.ndarray) -> np.ndarray:
    """The rotation block (3, 3) of a transform."""
    return np.asarray(a2b, dtype=float)[:3, :3]


def translation_of(a2b: np.ndarray) -> np.ndarray:
    """The translation (3,) of a transform, mm: the origin of ``a`` expressed in ``b``."""
    return np.asarray(a2b, dtype=float)[:3, 3]


def invert(a2b: ArrayLike) -> np.ndarray:
    """Return ``b2a`` for a rigid ``a2b`` (exact, no general matrix inverse)."""
    m = np.asarray(a2b, dtype=float)
    R = m[:3, :3]
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ m[:3, 3]
    return out


def concat(*chain: ArrayLike) -> np.ndarray:
    """Compose transforms in reading order: ``concat(a2b, b2c, c2d)`` is ``a2d``."""
    if not chain:
        raise ValueError("concat needs at least one transform")
    out = np.asarray(chain[0], dtype=float)
    for nxt in chain[1:]:
        out = np.asarray(nxt, dtype=float) @ out
    return out


def apply(a2b: ArrayLike, points_a: ArrayLike) -> np.ndarray:
    """Map points (n, 3) or (3,) from frame ``a`` to frame ``b``; mm in, mm out."""
    m = np.asarray(a2b, dtype=float)
    p = np.asarray(points_a, dtype=float)
    return p @ m[:3, :3].T + m[:3, 3]


def transform_from_xyz_rpy(xyz_mm: ArrayLike, rpy_deg: ArrayLike) -> np.ndarray:
    """Placement from a survey: position (mm) and fixed-axis roll, pitch, yaw (deg)."""
    R = _rotation().from_euler("xyz", np.asarray(rpy_deg, dtype=float), degrees=True).as_matrix()
    return make_transform(R, xyz_mm)


def xyz_rpy_from_transform(a2b: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`transform_from_xyz_rpy`: ``(xyz_mm, rpy_deg)``."""
    m = np.asarray(a2b, dtype=float)
    with warnings.catch_warnings():
        # At +-90 deg pitch roll and yaw are not unique; scipy's choice still gives the same rotation.
        warnings.simplefilter("ignore", UserWarning)
        rpy = _rotation().from_matrix(m[:3, :3]).as_euler("xyz", degrees=True)
    return m[:3, 3].copy(), rpy


def transform_from_rotvec_deg(rotvec_deg: ArrayLike, t_mm: ArrayLike = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Transform from an axis-angle vector (deg; direction = axis, norm = angle) and mm."""
    R = _rotation().from_rotvec(np.asarray(rotvec_deg, dtype=float), degrees=True).as_matrix()
    return make_transform(R, t_mm)


def rotation_angle_deg(R: ArrayLike) -> float:
    """Angle of a rotation matrix, deg, in [0, 180]; robust near 0 and 180."""
    return float(np.degrees(np.linalg.norm(_rotation().from_matrix(np.asarray(R, dtype=float)).as_rotvec())))


def pose_difference(actual2base: ArrayLike, model2base: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Displacement of an actual pose from a modelled one, both ``x2base``.

    Returns ``(d_mm, rotvec_deg)``: the translation of the actual origin minus the
    modelled origin, in the base frame (mm), and the rotation vector (deg, base frame)
    of ``R_actual @ R_model.T``, so that ``actual = transform_from_rotvec_deg(rv, d) ∘ model``
    applied in the base frame about the modelled origin.
    """
    a = np.asarray(actual2base, dtype=float)
    m = np.asarray(model2base, dtype=float)
    d_mm = a[:3, 3] - m[:3, 3]
    rotvec_deg = _rotation().from_matrix(a[:3, :3] @ m[:3, :3].T).as_rotvec(degrees=True)
    return d_mm, rotvec_deg


def skew(v: ArrayLike) -> np.ndarray:
    """Cross-product matrix (3, 3) of a 3-vector: ``skew(a) @ b == cross(a, b)``."""
    x, y, z = np.asarray(v, dtype=float).reshape(3)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
