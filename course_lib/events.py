"""Measuring events on sampled trajectories: crossings, impacts, peaks, periods, circles.

A fixed-step integrator only knows the state at the step points ``t_k``. An event that
happens between two steps (an apple reaching the ground, an orbit completing a turn) has
to be located from the samples around it. Two rules are provided:

- **linear**: join the last sample above the level and the first one below by a straight
  line and take where it meets the level (exact when the quantity moves at constant
  speed during the step, as forward Euler's position does);
- **ballistic**: from the last state above the level, solve the step's own quadratic
  ``h + v s + ½ a s² = level`` for the time ``s`` into the step (exact under a constant
  acceleration ``a``, the motion that velocity Verlet reproduces exactly).

Samples must be 1-D arrays of one length (``ValueError`` naming them otherwise).
Times must be finite; the sampled values may hold NaN (a run stopped by a blow-up).
Imports: numpy and ``_validate`` (core layer).
"""

from __future__ import annotations

import numpy as np

from . import _validate


def _samples(t, h, names: str = "t, h") -> tuple[np.ndarray, np.ndarray]:
    first, second = names.split(", ")
    t, h = _validate.real_array(first, t), _validate.numbers(second, h)
    if t.ndim != 1 or t.shape != h.shape:
        raise ValueError(f"{names} must be 1-D arrays of one length, got shapes {t.shape} and "
                         f"{h.shape}")
    return t, h


def crossing_linear(t0: float, h0: float, t1: float, h1: float, level: float = 0.0) -> float:
    """Time at which the straight line through ``(t0, h0)`` and ``(t1, h1)`` meets ``level``."""
    t0, h0, t1, h1, level = (_validate.finite_real(k, x) for k, x in
                             (("t0", t0), ("h0", h0), ("t1", t1), ("h1", h1), ("level", level)))
    if h0 == h1:
        raise ValueError("h0 == h1: the line never crosses the level")
    return t0 + (t1 - t0) * (h0 - level) / (h0 - h1)


def crossing_ballistic(h: float, v: float, a: float, level: float = 0.0) -> float:
    """Smallest ``s >= 0`` with ``h + v s + ½ a s² = level`` (NaN if it is never reached).

    Written in the cancellation-free form of the quadratic formula so that it stays
    accurate when ``a`` is tiny or zero (then it reduces to ``(level - h) / v``).
    """
    h, v, a, level = (_validate.finite_real(k, x)
                      for k, x in (("h", h), ("v", v), ("a", a), ("level", level)))
    c = h - level
    if c == 0.0:
        return 0.0
    half_a = 0.5 * a
    disc = v * v - 4.0 * half_a * c
    if disc < 0:
        return float("nan")
    q = -0.5 * (v + np.copysign(np.sqrt(disc), v))
    roots = []
    if q != 0.0:
        roots.append(c / q)
    if half_a != 0.0:
        roots.append(q / half_a)
    roots = [r for r in roots if r >= 0.0]
    return float(min(roots)) if roots else float("nan")


def first_crossing(t, h, level: float = 0.0, *, rule: str = "linear", v=None, a=None) -> float:
    """Time at which the samples ``h(t)`` first fall below ``level``, located between steps.

    Parameters
    ----------
    t, h : array_like, shape (n,)
        Sample times (s) and values (e.g. heights, m).
    level : float
        The level to cross (the ground, 0 m).
    rule : {"linear", "ballistic"}
        How to locate the crossing between the last sample at or above the level and the
        first below: ``"linear"`` interpolates ``h``; ``"ballistic"`` solves
        ``h_k + v_k s + ½ a s² = level`` from the last sample above (needs ``v`` and ``a``).

    Returns
    -------
    float
        The crossing time (s), or NaN when ``h`` never goes below ``level``.
    """
    if rule not in ("linear", "ballistic"):
        raise ValueError(f"unknown rule {rule!r}; use 'linear' or 'ballistic'")
    t, h = _samples(t, h)
    level = _validate.finite_real("level", level)
    below = np.flatnonzero(h < level)
    if below.size == 0:
        return float("nan")
    k = int(below[0])
    if k == 0:
        return float(t[0])
    if rule == "linear":
        return crossing_linear(t[k - 1], h[k - 1], t[k], h[k], level)
    if v is None or a is None:
        raise ValueError("rule='ballistic' needs the velocities v and the acceleration a")
    s = crossing_ballistic(h[k - 1], np.asarray(v, dtype=float)[k - 1], float(a), level)
    return float(t[k - 1] + s)


def upward_crossings(t, s, level: float = 0.0) -> np.ndarray:
    """All times at which ``s(t)`` crosses ``level`` upwards, by linear interpolation.

    Vectorized over the samples. Useful for periods: the y-coordinate of an orbit crosses
    zero upwards once per turn.
    """
    t, s = _samples(t, s, "t, s")
    s = s - _validate.finite_real("level", level)
    k = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    return t[k] + (t[k + 1] - t[k]) * (-s[k]) / (s[k + 1] - s[k])


def measured_period(t, s, level: float = 0.0) -> float:
    """Mean time between successive upward crossings of ``level`` (NaN if fewer than two)."""
    times = upward_crossings(t, s, level)
    if times.size < 2:
        return float("nan")
    return float((times[-1] - times[0]) / (times.size - 1))


def local_maxima(t, h) -> tuple[np.ndarray, np.ndarray]:
    """Interior peaks of ``h(t)``, each refined by the parabola through its 3 samples.

    The refinement is exact when the samples lie on one parabola (a ballistic arc sampled
    by an integrator that is exact for constant acceleration). Needs equally spaced ``t``.
    Returns the peak times and heights.
    """
    t, h = _samples(t, h)
    k = 1 + np.flatnonzero((h[1:-1] > h[:-2]) & (h[1:-1] >= h[2:]))
    a, b, c = h[k - 1], h[k], h[k + 1]
    denom = a - 2.0 * b + c
    safe = np.where(denom == 0.0, -1.0, denom)
    shift = np.where(denom == 0.0, 0.0, 0.5 * (a - c) / safe)   # in units of dt
    dt = t[1] - t[0] if t.size > 1 else 0.0
    return t[k] + shift * dt, b - 0.25 * (a - c) * shift


def fit_circle(points) -> tuple[np.ndarray, float]:
    """Least-squares circle through 2D points (Kåsa's algebraic fit): ``(center, radius)``.

    Exact when the points lie on a circle; used to measure the radius of a gyrating charge.
    """
    p = _validate.real_array("points", points)
    if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 3:
        raise ValueError(f"points must have shape (n >= 3, 2), got {p.shape}")
    A = np.column_stack((2.0 * p, np.ones(len(p))))
    rhs = np.sum(p * p, axis=1)
    (cx, cy, c), *_ = np.linalg.lstsq(A, rhs, rcond=None)
    center = np.array([cx, cy])
    return center, float(np.sqrt(c + cx * cx + cy * cy))
