"""Compiled (numba) inner loops of the pose solver: camera models and the damped Newton loop.

The solver's arithmetic on a handful of points is dominated by interpreter overhead in
numpy (about 1 us per call on arrays of six points); compiled scalar loops make a whole
single solve cheaper than OpenCV's own refinement, and the batch form runs them on every core.
"""
