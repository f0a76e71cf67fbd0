"""Identification of the robot's geometric parameters from what its camera saw at many poses.

Views of a board (placed anywhere: its placement is found too) and of surveyed cell features (in the
base frame, which ties the robot to the cell) at known commanded joints. The residual is every
point's reprojection error (px) through the corrected robot's camera pose. The Jacobian is taken by
forward differences (each parameter's effect on every pixel); QR with column pivoting on it
chooses the identifiable subset (:mod:`~calib_core.robot_calibration.observability`); Levenberg-
Marquardt (``scipy.optimize.least_squares``) fits that subset and the board's placement; the
covariance is the noise measured by the residuals times the inverse normal matrix, with each view's
residuals taken as one measurement where they share an error (:mod:`calib_core.solver.clustered_covariance`).
"""

from __future__ import annotations

import time
from dataclasses import replace

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole, project
from calib_core.errors import VideocalError
from calib_core.frames import apply, concat, invert, make_transform
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.left_out_views import OVERFIT_RATIO, left_out_ratio
from calib_core.robot_calibration.mounting_start import mounting_start
from calib_core.robot_calibration.observability import analyse
from calib_core.robot_calibration.observations import BOARD, CELL, OBJECT, PoseView
from calib_core.robot_calibration.calibrated_robot import FD_STEP, RobotCalibration
from calib_core.robot_calibration.parameters import CorrectedRobot, delta_transform
from calib_core.solver.clustered_covariance import clustered_scatter
from calib_core.vision.pnp_sensitivity import pose_derivatives

OUTLIER_RATIO = 4.0
"""A surveyed component's view whose residual is this many times the median of those views' (and
over 3 of its own sigmas) is left out: one edge fit on the wrong edges pulled the tie 0.17 mm."""
OBJECT_TURN_SIGMA_MRAD = 1.0
"""A turn about a component's own origin added to its covariance: the tie rests on where the
components are (three off one line fix the base), less on how each is turned. First set against a
bias of 0.4-1.2 mrad the simulated camera's point-sampled edges put into the edge fits' orientation
(gone with the pixels integrated, :class:`~videocal_sim.sim_camera.CameraLook`); still the
better choice after: on cold cells 0-4 the TCP at held-out poses is 0.036-0.068 mm with it and
0.042-0.093 mm with 0.2 mrad."""
SURVEY_SIGMA_MM = 0.05
"""A theodolite survey's 1-sigma per axis (its points good to about 0.1 mm)."""
MIN_VIEWS = 6


class RobotCalibrationError(VideocalError, ValueError):
    """Views that cannot calibrate the robot (too few, no board pose, nothing identifiable)."""


def residual_count(view) -> int:
    return 6 if view.target == OBJECT else 2 * len(view.points_mm)


def pose_residual(predicted: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """The left perturbation (rotation vector rad, translation mm) taking ``predicted`` to ``measured``."""
    R = measured[:3, :3] @ predicted[:3, :3].T
    return np.r_[Rotation.from_matrix(R).as_rotvec(), measured[:3, 3] - R @ predicted[:3, 3]]


class IdentificationProblem:
    """The least-squares problem of a robot calibration: the corrected robot's parameters (and the intrinsics when
    ``with_intrinsics``) against the ``views`` of a board or surveyed objects, whitened by each view's covariance (the
    survey's ``survey_sigma_mm`` added). Used by the identification, and by the pose planner for observability."""

    def __init__(
        self,
        robot: RobotModel,
        intrinsics: Intrinsics,
        views: list,
        camera_frame: str,
        with_intrinsics: bool,
        survey_sigma_mm: float = 0.0,
    ):
        self.corrected = CorrectedRobot(robot, camera_frame, with_intrinsics)
        self.nominal_intrinsics = intrinsics
        self.views = views
        self.has_board = any(v.target == BOARD for v in views)
        self.board0 = np.eye(4)
        self.size = self.corrected.layout.size
        # An object's measured pose whitened by its covariance, the survey's sigma added to the translation.
        self.whiten = {}
        for k, v in enumerate(views):
            if v.target == OBJECT:
                cov = (
                    np.asarray(v.covariance, dtype=float)
                    + np.diag([0.0, 0.0, 0.0] + [survey_sigma_mm**2] * 3)
                    + turn_about_object(v.obj2cam, OBJECT_TURN_SIGMA_MRAD)
                )
                self.whiten[k] = np.linalg.inv(np.linalg.cholesky(cov + 1e-15 * np.eye(6)))
        # With the intrinsics fitted, an object's pose measured through the starting ones moves with them.
        self.moves_with_intrinsics = {}
        if with_intrinsics:
            for k, v in enumerate(views):
                if v.target == OBJECT and v.points_mm is not None and len(v.points_mm) >= 4:
                    self.moves_with_intrinsics[k] = pose_sensitivity_to_intrinsics(v.obj2cam, v.points_mm, intrinsics)

    def residuals(self, p: np.ndarray, board: np.ndarray) -> np.ndarray:
        self.corrected.set(p)
        intr = self.corrected.intrinsics(self.nominal_intrinsics)
        board2base = concat(self.board0, delta_transform(board))
        out = []
        for k, v in enumerate(self.views):
            base2cam = invert(self.corrected.cam2base(v.joints_deg))
            if v.target == OBJECT:
                r = pose_residual(concat(v.obj2base, base2cam), v.obj2cam)
                if k in self.moves_with_intrinsics:
                    r = r + self.moves_with_intrinsics[k] @ p[self.corrected.layout.intrinsics_block]
                out.append(self.whiten[k] @ r)
                continue
            obj2cam = concat(board2base, base2cam) if v.target == BOARD else base2cam
            out.append((project(apply(obj2cam, v.points_mm), intr) - v.pixels).ravel())
        return np.concatenate(out)

    def jacobian(self, p: np.ndarray, board: np.ndarray, columns: list[int]) -> tuple[np.ndarray, np.ndarray]:
        """(J of the chosen parameter columns, J of the 6 board parameters) by forward differences."""
        r0 = self.residuals(p, board)
        J = np.empty((r0.size, len(columns)))
        for c, k in enumerate(columns):
            dp = p.copy()
            dp[k] += FD_STEP
            J[:, c] = (self.residuals(dp, board) - r0) / FD_STEP
        Jb = np.empty((r0.size, 6 if self.has_board else 0))
        for c in range(Jb.shape[1]):
            db = board.copy()
            db[c] += FD_STEP
            Jb[:, c] = (self.residuals(p, db) - r0) / FD_STEP
        return J, Jb


def turn_about_object(obj2cam: np.ndarray, sigma_mrad: float) -> np.ndarray:
    """(6, 6) covariance, in the left perturbation of ``obj2cam`` (rotation vector rad, translation
    mm, camera frame), of the object turned about its own origin by ``sigma_mrad`` (1-sigma per
    axis): a turn ``w`` about the origin at ``t`` is the left rotation ``w`` with translation ``t x w``."""
    t = obj2cam[:3, 3]
    G = np.vstack([np.eye(3), np.array([[0.0, -t[2], t[1]], [t[2], 0.0, -t[0]], [-t[1], t[0], 0.0]])])
    return (sigma_mrad / 1000.0) ** 2 * G @ G.T


def pose_sensitivity_to_intrinsics(
    obj2cam: np.ndarray, points_mm: np.ndarray, intrinsics: Intrinsics, step: float = 0.1
) -> np.ndarray:
    """(6, 8): how an object's pose measured at ``obj2cam`` (4, 4) mm through ``intrinsics`` moves
    (left perturbation: rotation vector rad, translation mm) per unit of each correction in
    :data:`~calib_core.robot_calibration.parameters.INTRINSICS`: the pose that puts ``points_mm``
    (m, 3, the object's frame) on the same pixels through the corrected intrinsics, by central
    differences of OpenCV's PnP refinement. First order is enough: the corrections are tenths of a
    pixel and thousandths."""
    from calib_core.robot_calibration.parameters import INTRINSICS, corrected_intrinsics

    def correct(j):
        def change(d, pixels):
            delta = np.zeros(len(INTRINSICS))
            delta[j] = d
            return pixels, corrected_intrinsics(intrinsics, delta)

        return change

    return pose_derivatives(
        obj2cam, points_mm, intrinsics, [correct(j) for j in range(len(INTRINSICS))], pose_residual, step
    )


def initial_board2base(
    robot: RobotModel, intrinsics: Intrinsics, views: list[PoseView], camera_frame: str
) -> np.ndarray:
    """The board's placement (4, 4) mm from each board view's PnP through the nominal robot, averaged."""
    placements = []
    for v in views:
        if v.target != BOARD or len(v.points_mm) < 4:
            continue
        pixels, camera = as_pinhole(v.pixels, intrinsics)  # OpenCV's PnP knows no fisheye lens
        ok, rvec, tvec = cv2.solvePnP(v.points_mm, pixels, camera.K, camera.dist_coeffs, flags=cv2.SOLVEPNP_ITERATIVE)
        if ok:
            placements.append(
                concat(make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel()), robot.fk(v.joints_deg, camera_frame))
            )
    if not placements:
        raise RobotCalibrationError("no board view gives the board's pose: every board view needs 4 points or more")
    R = Rotation.from_matrix([P[:3, :3] for P in placements]).mean().as_matrix()
    return make_transform(R, np.median([P[:3, 3] for P in placements], axis=0))


def identify(
    robot: RobotModel,
    intrinsics: Intrinsics,
    views: list[PoseView],
    *,
    camera_frame: str = "camera",
    with_intrinsics: bool = False,
    parameters: list[str] | None = None,
    survey_sigma_mm: float = SURVEY_SIGMA_MM,
    max_iterations: int = 50,
) -> RobotCalibration:
    """Calibrate ``robot`` (its nominal model) from ``views``; see the module's docstring.
    ``survey_sigma_mm``: how well the surveyed points are known (1-sigma per axis), added to the
    surveyed views' measured noise as the pixels it makes at each point's distance.
    ``parameters``: fit exactly these (names as in the result), instead of the subset QR pivoting
    chooses (the observability is reported either way)."""
    started = time.perf_counter()
    if len(views) < MIN_VIEWS:
        raise RobotCalibrationError(f"{len(views)} views, at least {MIN_VIEWS} needed (30-40 recommended)")
    pixel_rows = np.concatenate([np.full(residual_count(v), v.target != OBJECT) for v in views])

    def problem_of(model: RobotModel) -> IdentificationProblem:
        problem = IdentificationProblem(model, intrinsics, views, camera_frame, with_intrinsics, survey_sigma_mm)
        if problem.has_board:
            problem.board0 = initial_board2base(model, intrinsics, views, camera_frame)
        return problem

    def start_rms_px(model: RobotModel) -> float:
        uncorrected = problem_of(model)
        r = uncorrected.residuals(np.zeros(uncorrected.size), np.zeros(6))[pixel_rows]
        return float(np.sqrt(2.0 * np.mean(r**2))) if np.all(np.isfinite(r)) else float("inf")

    problem = problem_of(robot)
    p0, b0 = np.zeros(problem.size), np.zeros(6)
    start_r = problem.residuals(p0, b0)
    nominal_rms_px = float(np.sqrt(2.0 * np.mean(start_r[pixel_rows] ** 2))) if np.all(np.isfinite(start_r)) else np.inf
    start = mounting_start(robot, intrinsics, views, camera_frame, start_rms_px) if problem.has_board else None
    if start is not None and start.note is not None:
        robot = start.robot
        problem = problem_of(robot)
        start_r = problem.residuals(p0, b0)
    if not np.all(np.isfinite(start_r)):
        raise RobotCalibrationError(
            "some points project behind the camera with the nominal model: a view's joints or points are wrong"
        )
    names = problem.corrected.layout.names
    J_all, Jb = problem.jacobian(p0, b0, list(range(problem.size)))
    obs = analyse(J_all, names, problem.corrected.layout.scale, Jb if Jb.size else None)
    if parameters is not None:
        unknown = [n for n in parameters if n not in names]
        if unknown:
            raise RobotCalibrationError(
                f"no parameter {unknown[0]!r}; parameters are named like {names[0]} or camera.rz_mrad"
            )
        chosen = sorted(names.index(n) for n in parameters)
        obs = replace(obs, identified=chosen, unidentified=[k for k in range(len(names)) if k not in chosen])
    chosen = obs.identified
    if not chosen:
        raise RobotCalibrationError(
            "the views determine no parameter: spread the poses (turn every joint, tilt the camera about two axes)"
        )
    k = len(chosen)

    def unpack(x):
        p = np.zeros(problem.size)
        p[chosen] = x[:k]
        return p, (x[k:] if problem.has_board else b0)

    # Board corners and surveyed features have their own noise (a tenth of a pixel against the edges'
    # pose and the survey's tenth of a millimetre): each group weighted by its own measured sigma.
    groups = (BOARD, CELL, OBJECT)
    group_of = np.concatenate([np.full(residual_count(v), groups.index(v.target)) for v in views])
    weights = np.ones(group_of.size)
    # A surveyed point off by survey_sigma_mm moves its pixel by f * sigma / depth: a floor under the
    # surveyed points' noise that their few residuals cannot show (each view's points share one pose).
    survey_px = np.concatenate(
        [
            np.repeat(
                0.5
                * (intrinsics.fu + intrinsics.fv)
                * survey_sigma_mm
                / np.maximum(apply(invert(robot.fk(v.joints_deg, camera_frame)), v.points_mm)[:, 2], 1.0),
                2,
            )
            if v.target == CELL
            else np.zeros(residual_count(v))
            for v in views
        ]
    )

    def fun(x):
        return weights * problem.residuals(*unpack(x))

    def jac(x):
        J, Jb_ = problem.jacobian(*unpack(x), chosen)
        return weights[:, None] * np.hstack([J, Jb_])

    x0 = np.zeros(k + (6 if problem.has_board else 0))
    bounds = np.cumsum([0] + [residual_count(v) for v in views])
    kept = np.ones(group_of.size, dtype=bool)
    left_out: dict[str, str] = {}
    group_sigma = {}
    for _ in range(2 if len(set(group_of.tolist())) > 1 else 1):
        fit = least_squares(fun, x0, jac=jac, method="lm", max_nfev=max_iterations * 2)
        r_px = problem.residuals(*unpack(fit.x))
        left_out.update(_disagreeing_objects(views, bounds, r_px, kept))
        for g in set(group_of.tolist()):
            sel = (group_of == g) & kept
            group_sigma[g] = max(float(np.sqrt(np.mean(r_px[sel] ** 2))), 1e-6) if sel.any() else 1.0
            # Object poses come whitened: their scale is at least the covariance's own (a few views
            # cannot show a covariance too large, and the edge fits' is known to be too small).
            sigma = max(group_sigma[g], 1.0) if groups[g] == OBJECT else group_sigma[g]
            weights[sel] = 1.0 / np.sqrt(sigma**2 + survey_px[sel] ** 2)
        weights[~kept] = 0.0
        x0 = fit.x
    fit = least_squares(fun, x0, jac=jac, method="lm", max_nfev=max_iterations * 2)
    p, board = unpack(fit.x)
    r_all = problem.residuals(p, board)  # the left-out views' too: their residuals are reported
    r = np.where(kept, r_all, 0.0)
    dof = max(int(kept.sum()) - x0.size, 1)
    rp = r[pixel_rows]
    noise = float(np.sqrt(rp @ rp / max(rp.size - x0.size, 1))) if rp.size else float("nan")
    J = fit.jac
    # The weighted residuals have unit variance when the groups' sigmas are right: scale by what they have.
    # A view's residuals share its error (a board view's blur and the board's flatness there, an object
    # pose's edge fit): each view's score is one measurement (clustered_covariance), never less than
    # the independent residuals' covariance.
    scale2 = float(fit.fun @ fit.fun / dof)
    H_inv = np.linalg.pinv(J.T @ J)
    view_of = np.repeat(np.arange(len(views)), np.diff(bounds))
    cov = H_inv @ clustered_scatter(J, fit.fun, view_of, scale2 * (J.T @ J)) @ H_inv
    sig = np.full(problem.size, np.nan)
    sig[chosen] = np.sqrt(np.clip(np.diag(cov)[:k], 0, None))
    problem.corrected.set(p)
    per_view = {
        v.name: float(np.sqrt((1.0 if v.target == OBJECT else 2.0) * np.mean(r_all[a:b] ** 2)))
        for v, a, b in zip(views, bounds[:-1], bounds[1:])
    }
    warnings = [f"{name} left out: {why}" for name, why in left_out.items()]
    if start is not None and start.note is not None:
        warnings.insert(0, start.note)
    if not fit.success:
        warnings.append(f"the fit stopped before converging ({fit.message})")
    loo_ratio = left_out_ratio(J, fit.fun, view_of, kept)
    if loo_ratio > OVERFIT_RATIO:
        warnings.append(
            f"{len(views)} views for {k} identified parameters: each view, left out of the fit, is predicted "
            f"{loo_ratio:.1f} times further off than the fit leaves it: the fit bends the robot's geometry to the "
            "views' own errors (poses, detections); its corrections are what these views allow, not a calibration "
            "to command: plan more views (30-40 recommended)"
        )
    board2base = concat(problem.board0, delta_transform(board)) if problem.has_board else None
    return RobotCalibration(
        names,
        p,
        sig,
        obs,
        board2base,
        float(np.sqrt(2.0 * np.mean(r[pixel_rows] ** 2))),
        per_view,
        noise,
        problem.corrected.calibrated_model(),
        problem.corrected.intrinsics(intrinsics),
        time.perf_counter() - started,
        nominal_rms_px,
        warnings,
        cov[:k, :k],
        robot.copy(),
        camera_frame,
        weights.copy(),
        {groups[g]: v for g, v in group_sigma.items()},
        left_out,
    )


def _disagreeing_objects(views: list, bounds: np.ndarray, residuals: np.ndarray, kept: np.ndarray) -> dict[str, str]:
    """The surveyed components' views (whitened residuals) that disagree with the others, by
    :data:`OUTLIER_RATIO`; ``kept`` (residuals,) is cleared for them. One at a time, the worst first,
    since one bad view raises the others' residuals too."""
    out = {}
    while True:
        rms = {
            k: float(np.sqrt(np.mean(residuals[bounds[k] : bounds[k + 1]] ** 2)))
            for k, v in enumerate(views)
            if v.target == OBJECT and kept[bounds[k]]
        }
        if len(rms) < 4:
            return out
        median = float(np.median(list(rms.values())))
        worst = max(rms, key=rms.get)
        if rms[worst] <= max(OUTLIER_RATIO * median, 3.0):
            return out
        kept[bounds[worst] : bounds[worst + 1]] = False
        out[views[worst].name] = (
            f"its pose is {rms[worst]:.1f} of its sigmas from the fit, the other components' views {median:.1f} "
            "(median)"
        )
