"""The exact expected population of a particle system, and when an age reaches a lifetime.

The functions live here for length and are part of :mod:`course_lib.particles`, which
imports them (their ``__module__`` says so: the checks and their messages name them
``course_lib.particles.…``). A particle emitted in one frame is counted after each later
frame until its age reaches its lifetime (:func:`reached`, within :data:`LIFETIME_RTOL`);
the expected count is a convolution of the mean emissions with the survival function.
Core module: imports NumPy and :mod:`course_lib._validate` only.
"""

from __future__ import annotations

import numpy as np

from . import _validate
from ._validate import mean_and_spread, nonnegative, real_array

#: Tolerance of :func:`reached`: ``m dt`` and a decimal lifetime differ by ~1.5 ulp at most.
LIFETIME_RTOL = 4.0 * np.finfo(float).eps


def reached(age, lifetime):
    """Has ``age`` (s) reached ``lifetime`` (s)? ``age >= lifetime (1 − LIFETIME_RTOL)``."""
    return np.asarray(age) >= np.asarray(lifetime) * (1.0 - LIFETIME_RTOL)


def survival(age, lifetime: float, lifetime_variance: float = 0.0) -> np.ndarray:
    """``P(age has not reached ℓ)`` for lifetimes ``ℓ`` uniform on ``[L − V, L + V]`` (s):
    with ``V = 0`` exactly what a run does (:func:`reached`); with ``V > 0`` the tolerance
    of :func:`reached` would move it by ~1e-16 and is left out."""
    age = real_array("age", age)
    lifetime, lifetime_variance = mean_and_spread("lifetime", lifetime, lifetime_variance)
    if lifetime_variance == 0.0:
        return (~reached(age, lifetime)).astype(float)
    return np.clip((lifetime + lifetime_variance - age) / (2.0 * lifetime_variance), 0.0, 1.0)


def expected_population(mean_counts, dt: float, lifetime: float,
                        lifetime_variance: float = 0.0) -> np.ndarray:
    """Exact expected live count after each frame of emit, step, expire.

    A particle emitted in frame ``k`` has lived ``j − k + 1`` steps when counted after
    frame ``j``, so its age is ``(j − k + 1) dt`` (computed as a run computes it), and
    ``E[N_j] = Σ_k μ_k S((j − k + 1) dt)``: a convolution of the mean counts ``μ_k``
    (shape ``(frames,)``) with the survival function :func:`survival`.
    """
    mu, dt = real_array("mean_counts", mean_counts, (None,)), _validate.positive_finite("dt", dt)
    s = survival(np.arange(1, mu.size + 1, dtype=float) * dt, lifetime, lifetime_variance)
    return np.convolve(mu, s)[: mu.size]


def steady_population(mean_count: float, dt: float, lifetime: float,
                      lifetime_variance: float = 0.0) -> float:
    """Long-run expected population for a constant mean count ``μ`` per frame,
    ``μ Σ_{m>=1} S(m dt)`` (counted at frame ends, at ages ``dt, 2 dt, ...``). When
    ``(L ± V)/dt`` are whole and ``V > 0`` it is ``μ (L/dt − 1/2)``: Little's law (rate ×
    mean lifetime, ``μ L/dt``) less half a frame of emission. With ``V = 0`` and ``L/dt``
    whole it is ``μ (L/dt − 1)``: a particle lives ``L/dt`` steps, deleted before the count.
    """
    mean_count, dt = nonnegative("mean_count", mean_count), _validate.positive_finite("dt", dt)
    lifetime, lifetime_variance = mean_and_spread("lifetime", lifetime, lifetime_variance)
    m = np.arange(1, int(np.ceil((lifetime + lifetime_variance) / dt)) + 2, dtype=float)
    return float(mean_count * survival(m * dt, lifetime, lifetime_variance).sum())


for _f in (reached, survival, expected_population, steady_population):
    _f.__module__ = "course_lib.particles"
