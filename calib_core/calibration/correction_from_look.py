"""The correction (or measurement) a look's result gives for a task location, with the confirmation a result that
is not ``ok`` needs."""

from __future__ import annotations

import numpy as np

from calib_core.calibration.corrections import Correction, StoreCorrection
from calib_core.calibration.end_effector import EndEffectorEstimate
from calib_core.calibration.errors import ConfirmationNeeded
from calib_core.calibration.look_result import SolveContext
from calib_core.calibration.verdict import ResultVerdict
from calib_core.frames import concat


def correction_from_look(
    estimate: EndEffectorEstimate,
    context: SolveContext,
    verdict: ResultVerdict,
    task: str,
    source: str = "",
    *,
    confirmation: str = "",
    fused=None,
    tool_covariance: np.ndarray | None = None,
    kind: str = "correction",
) -> Correction:
    """The :class:`Correction` of ``task`` from a look's ``estimate`` (solved from ``context``, judged ``verdict``).

    A result that is not ``ok`` (implausible, uncertain, ambiguous) raises :class:`ConfirmationNeeded` unless
    ``confirmation`` says who accepted it and why; that text is stored with the correction. ``fused``: the look
    weighed against a calibrated robot (:class:`~calib_core.calibration.look_fusion.FusedCorrection`): stored in the
    look's place when they agree; when they do not, storing the look alone needs the same confirmation.
    ``tool_covariance`` (6, 6: mm, deg, base axes): a measured tool's, which the look reaches the TCP through; added
    to a look stored alone (a fused one holds it already). ``kind``: ``measurement`` keeps the look as what it is,
    never commanded (no confirmation needed: it moves nothing)."""
    confirmation = confirmation.strip()
    if kind == "measurement":
        fused = None  # what this pose measured, alone
    elif not verdict.ok and not confirmation:
        raise ConfirmationNeeded(
            f"the result is {verdict.verdict.value}: {'; '.join(verdict.reasons)}. Storing it needs your confirmation",
            verdict.reasons,
        )
    if fused is not None and not fused.agree and not confirmation:
        raise ConfirmationNeeded(f"{fused.message}. Storing the look alone needs your confirmation", (fused.message,))
    r, numbers = estimate, context.numbers
    source = source or (f"pairs {', '.join(map(str, numbers))}" if numbers else "edges")
    measured, d, rv, std_d, std_r = (
        r.tcp2base_measured,
        r.displacement_mm,
        r.rotation_deg,
        r.std_displacement_mm,
        r.std_rotation_deg,
    )
    if fused is not None and fused.agree:
        std = np.sqrt(np.clip(np.diag(fused.covariance), 0.0, None))
        measured = concat(r.tcp2base_model, fused.delta_base)
        d, rv, std_d, std_r = fused.displacement_mm, fused.rotation_deg, std[:3], std[3:]
        source += f"; {fused.message}"
    else:
        if fused is not None:
            source += f"; the look alone ({fused.message})"
        if tool_covariance is not None and r.covariance is not None:
            std = np.sqrt(np.clip(np.diag(r.covariance + tool_covariance), 0.0, None))
            std_d, std_r = std[:3], std[3:]
            source += "; with the measured tool's uncertainty"
    return Correction(
        task,
        r.tcp2base_model,
        measured,
        d,
        rv,
        std_d,
        std_r,
        np.zeros(0) if context.joints_deg is None else context.joints_deg,
        r.solution.rms_px,
        len(numbers),
        source=source,
        verdict=verdict.verdict.value,
        confirmation="" if verdict.ok and (fused is None or fused.agree) else confirmation,
        kind=kind,
    )


class StoreLook(StoreCorrection):
    """*Store correction*: the ``session``'s last look stored for ``task`` (undoable; ``how`` as
    :func:`correction_from_look`'s). Checks itself when made: a result to store
    (:meth:`~calib_core.calibration.look_result.LookResult.storable_estimate`: there is one, it belongs to the pairs
    on screen, it did not fail) and the confirmation a result that is not ``ok`` needs."""

    def __init__(self, session, task: str, source: str = "", **how):
        result = session.result
        estimate = result.storable_estimate(session.pairs.usable())
        verdict = result.verdict or result.judge(estimate)
        super().__init__(
            session.corrections, correction_from_look(estimate, result.context, verdict, task, source, **how)
        )
