"""Short recordings for the recording tests: noisy frames, a simulated clock, a session recorded to a file."""

import numpy as np

from calib_core.recording.recorder import SessionRecorder
from calib_core.solver import solve_pose
from calib_core.solver.solve_inputs import solve_inputs
from tests.core.solver.scenes import GRIPPER_CAMERA, pixels, random_points, random_pose


def noisy_image(i, rng, noise=3.0):
    """A gradient with a moving square and some noise: video-like, so inter-frame coding matters."""
    image = np.zeros((48, 64, 3), np.uint8) + np.linspace(20, 220, 64).astype(np.uint8)[None, :, None]
    image[10:20, 5 + i : 15 + i] = (250, 30, 30)
    return image if noise == 0 else np.clip(image + rng.normal(0, noise, image.shape), 0, 255).astype(np.uint8)


class SimulatedClock:
    """Host seconds that a test sets: a recording made faster than real time, stamped consistently."""

    def __init__(self, t_s: float = 0.0):
        self.t_s = t_s

    def __call__(self) -> float:
        return self.t_s


def record(path, n_frames=3, n_solves=2, frames="jpeg"):
    rng = np.random.default_rng(0)
    clock = SimulatedClock()
    with SessionRecorder(path, frames=frames, drop_when_busy=False, clock=clock) as rec:
        rec.record_setup(intrinsics=GRIPPER_CAMERA.to_dict())
        for i in range(n_frames):
            image = noisy_image(i, rng)
            clock.t_s = i + 0.02  # each frame reaches the recorder 20 ms after its capture
            rec.record_frame(image, float(i))
            rec.record_joints(i, 10 * i, i + 0.01, [1.0, 2.0, 3.0, 4.0, 5.0, float(i)])
            rec.record_event("pick", number=i)
            if i % 3 == 2:
                rec.flush()  # several chunks, as a recording of some seconds has
        for _ in range(n_solves):
            truth = random_pose(rng)
            P = random_points(rng, 6)
            uv = pixels(P, truth, noise_px=0.4, rng=rng)
            inputs = solve_inputs(P, uv, GRIPPER_CAMERA, prior=truth)
            rec.record_solve(inputs, solve_pose(P, uv, GRIPPER_CAMERA, prior=truth).to_dict())
    return path
