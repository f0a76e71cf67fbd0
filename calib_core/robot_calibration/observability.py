"""Which parameters a set of views determines: the identification Jacobian's rank, the subset
chosen by QR with column pivoting (Khalil and Dombre's "base parameters"), the directions left
undetermined, the condition number and strong correlations.

The nuisance parameters (the board's placement) are projected out first: a direction the board's
unknown pose can absorb is not determined by the views, whatever its column looks like.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

RANK_TOLERANCE = 1e-6
"""A singular value below this share of the largest is a redundancy (exact up to round-off and the
finite differences' error): those directions change no pixel."""
WEAK_SIGMA = 20.0
"""A chosen parameter whose 1-sigma would exceed this (mm or mrad, per pixel of noise) is left at its
nominal value: the views barely see it. Kept loose on purpose: at the 0.1 px of refined board corners a
direction at 0.5 mm per px is still found to 0.05 mm, and leaving it out costs more (measured: held-out
camera poses 0.31 mm off with a limit of 0.5, 0.045 mm without)."""
CORRELATION_LIMIT = 0.9


@dataclass(frozen=True)
class Observability:
    """``identified`` indices into the parameter names, chosen by QR pivoting; ``unidentified`` the
    rest; ``condition`` of the identified columns (scaled); ``directions`` undetermined combinations,
    each a list of (name, weight) of its largest components; ``correlations`` (a, b, r) above
    :data:`CORRELATION_LIMIT` among the identified."""

    identified: list[int]
    unidentified: list[int]
    condition: float
    rank: int
    directions: list[list[tuple[str, float]]] = field(default_factory=list)
    correlations: list[tuple[str, str, float]] = field(default_factory=list)
    singular_values: np.ndarray = field(default_factory=lambda: np.zeros(0))


def project_out(J: np.ndarray, nuisance: np.ndarray) -> np.ndarray:
    """``J`` with its components along the columns of ``nuisance`` removed."""
    if nuisance.size == 0:
        return J
    Q, _ = np.linalg.qr(nuisance)
    return J - Q @ (Q.T @ J)


def analyse(J: np.ndarray, names: list[str], scale: np.ndarray, nuisance: np.ndarray | None = None) -> Observability:
    """``J`` (residuals, parameters) the identification Jacobian (px per parameter unit), ``scale``
    each parameter's typical size, ``nuisance`` (residuals, k) the columns of nuisance parameters."""
    Js = project_out(J * scale[None, :], nuisance if nuisance is not None else np.zeros((J.shape[0], 0)))
    s = np.linalg.svd(Js, compute_uv=False)
    rank = int(np.sum(s > RANK_TOLERANCE * s[0])) if s.size and s[0] > 0 else 0
    _, R, order = scipy.linalg.qr(Js, mode="economic", pivoting=True)
    chosen = sorted(order[:rank].tolist())
    # Drop chosen parameters the views barely see (1-sigma per pixel of noise above WEAK_SIGMA).
    while chosen:
        Jc = Js[:, chosen]
        cov = np.linalg.pinv(Jc.T @ Jc)
        sig = np.sqrt(np.clip(np.diag(cov), 0, None))
        worst = int(np.argmax(sig))
        if sig[worst] <= WEAK_SIGMA:
            break
        chosen.pop(worst)
    unidentified = [k for k in range(len(names)) if k not in chosen]
    # Undetermined directions: the null space of the full scaled Jacobian, named by its largest parts.
    _, sv, Vt = np.linalg.svd(Js, full_matrices=True)
    null = Vt[rank:] if rank < Vt.shape[0] else np.zeros((0, len(names)))
    directions = []
    for v in null[: min(len(null), 40)]:
        top = np.argsort(-np.abs(v))[:4]
        directions.append([(names[k], round(float(v[k]), 3)) for k in top if abs(v[k]) > 0.05])
    condition = float(np.linalg.cond(Js[:, chosen])) if chosen else float("inf")
    correlations = []
    if chosen:
        cov = np.linalg.pinv(Js[:, chosen].T @ Js[:, chosen])
        d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
        corr = cov / np.outer(d, d)
        for a in range(len(chosen)):
            for b in range(a + 1, len(chosen)):
                if abs(corr[a, b]) > CORRELATION_LIMIT:
                    correlations.append((names[chosen[a]], names[chosen[b]], round(float(corr[a, b]), 3)))
    return Observability(chosen, unidentified, condition, rank, directions, correlations, sv)
