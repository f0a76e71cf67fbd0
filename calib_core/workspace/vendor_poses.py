"""One Cartesian pose (4, 4, mm, the cell's ``base`` frame) as each vendor's language writes a target:

- Universal Robots URScript: ``p[x, y, z, rx, ry, rz]``, metres and a rotation vector in radians;
- ABB RAPID: ``pose`` ``[[x, y, z], [q1, q2, q3, q4]]``, mm and a unit quaternion, scalar first (in a ``robtarget``
  with its ``confdata``, and a held tool's ``tooldata``);
- KUKA KRL: ``FRAME {X, Y, Z, A, B, C}``, mm and degrees, ``R = Rz(A) Ry(B) Rx(C)`` (a ``POS`` with ``S`` and ``T``);
- FANUC TP: a position ``(X, Y, Z, W, P, R)``, mm and degrees, ``R = Rz(R) Ry(P) Rx(W)``;
- COMAU PDL2: ``POS(x, y, z, e1, e2, e3, '')``, mm and Euler ZYZ degrees.

The listings that carry them are :mod:`calib_core.workspace.controller_formats`'.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation


def urscript_pose(T: np.ndarray) -> str:
    x, y, z = T[:3, 3] / 1000.0
    rx, ry, rz = Rotation.from_matrix(T[:3, :3]).as_rotvec()
    return f"p[{x:.6f}, {y:.6f}, {z:.6f}, {rx:.6f}, {ry:.6f}, {rz:.6f}]"


def rapid_pose(T: np.ndarray) -> str:
    """RAPID's ``pose``: ``[[x, y, z], [q1, q2, q3, q4]]``, mm and a unit quaternion, scalar first."""
    x, y, z = T[:3, 3]
    qx, qy, qz, qw = Rotation.from_matrix(T[:3, :3]).as_quat()
    if qw < 0:  # the same rotation; RAPID's examples keep q1 >= 0
        qw, qx, qy, qz = -qw, -qx, -qy, -qz
    return f"[[{x:.3f},{y:.3f},{z:.3f}],[{qw:.8f},{qx:.8f},{qy:.8f},{qz:.8f}]]"


def rapid_robtarget(T: np.ndarray, confdata: tuple[int, int, int, int] = (0, 0, 0, 0)) -> str:
    return f"[{rapid_pose(T)[1:-1]},[{','.join(str(int(v)) for v in confdata)}],[9E9,9E9,9E9,9E9,9E9,9E9]]"


def rapid_tooldata(tcp2flange: np.ndarray) -> str:
    """RAPID's ``tooldata`` held by the robot (``robhold`` TRUE): the TCP frame on the flange, and tool0's own load
    (0.001 kg at [0, 0, 0.001]): the tool's mass is not something a camera measures."""
    return f"[TRUE,{rapid_pose(tcp2flange)},[0.001,[0,0,0.001],[1,0,0,0],0,0,0]]"


def krl_frame(T: np.ndarray, status_turn: tuple[int, int] | None = None) -> str:
    """KRL's ``FRAME`` ``{X, Y, Z, A, B, C}``; with ``status_turn`` a ``POS`` (``..., S s, T t}``)."""
    x, y, z = T[:3, 3]
    with warnings.catch_warnings():
        # B = +-90 deg (a tool turned square): A and C are not unique; scipy's choice gives the same rotation
        warnings.simplefilter("ignore", UserWarning)
        a, b, c = Rotation.from_matrix(T[:3, :3]).as_euler("ZYX", degrees=True)
    st = "" if status_turn is None else f",S {status_turn[0]},T {status_turn[1]}"
    return f"{{X {x:.3f},Y {y:.3f},Z {z:.3f},A {a:.4f},B {b:.4f},C {c:.4f}{st}}}"


def fanuc_position(T: np.ndarray) -> tuple[float, ...]:
    """(X, Y, Z, W, P, R): mm and degrees."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # P = +-90 deg: W and R not unique, the rotation is
        w, p, r = Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)
    x, y, z = T[:3, 3]
    return float(x), float(y), float(z), float(w), float(p), float(r)


def pdl2_pos(T: np.ndarray) -> str:
    x, y, z = T[:3, 3]
    with warnings.catch_warnings():
        # e2 = 0 or 180 deg: e1 and e3 are not unique; scipy's choice gives the same rotation
        warnings.simplefilter("ignore", UserWarning)
        e = Rotation.from_matrix(T[:3, :3]).as_euler("ZYZ", degrees=True)
    return f"POS({x:.3f}, {y:.3f}, {z:.3f}, {e[0]:.4f}, {e[1]:.4f}, {e[2]:.4f}, '')"
