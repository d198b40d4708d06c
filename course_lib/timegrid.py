"""The time grid of a fixed-step run: where :func:`course_lib.integrate` reports the state.

The rule, with ``T = max(|t0|, |t1|)`` and ``tol = 8 * numpy.spacing(T)`` (eight units in
the last place of the times, :data:`ROUNDOFF_ULPS`):

- ``t[0] == t0`` and ``t[n] == t1`` exactly; ``t[k]`` is ``t0 + dt * k`` in floating point for
  ``0 < k < n``; the grid is strictly increasing.
- ``n`` is the fewest steps whose last one, ``t1 - t[n-1]`` computed from ``t1``, is at
  most ``dt + tol``. When that last step is within ``tol`` of ``dt`` the span is a whole
  number of steps and the run takes all ``n`` steps with ``dt`` itself (the loop a student
  writes); otherwise the last step is ``t1 - t[n-1]``, with ``0 < last < dt - tol``.
- So every step the integrator takes is at most ``dt``, and every interval of the grid,
  ``t[k+1] - t[k]``, is within ``tol`` of the step taken over it: at most ``dt + tol``.

``tol`` bounds the round-off of forming the grid: ``t1 = t0 + n * dt`` and
``dt = (t1 - t0) / n`` both give a whole grid of ``n`` steps (each is off by at most about
five units in the last place of ``T``). Refused with a ``ValueError`` that says which: a
``dt`` longer than the span; one not above ``2 tol`` (the times would hardly be distinct,
and round-off could pass for a step); a grid of more than ``max_steps`` steps.
Imports: numpy and ``_validate`` (core layer).
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate

#: Default cap on the number of steps of one run (``integrate(..., max_steps=...)``).
MAX_STEPS = 10_000_000
#: The grid's round-off tolerance, in units in the last place of ``max(|t0|, |t1|)``.
ROUNDOFF_ULPS = 8


def grid_tolerance(t0: float, t1: float) -> float:
    """``tol`` of the rule above: 8 units in the last place of ``max(|t0|, |t1|)`` (s)."""
    return ROUNDOFF_ULPS * float(np.spacing(max(abs(t0), abs(t1))))


def time_grid(t_span, dt: float, max_steps: int = MAX_STEPS) -> tuple[np.ndarray, float]:
    """The times of :func:`integrate`'s grid and the length of its last step.

    Parameters
    ----------
    t_span : (float, float)
        Start and end time (s), ``t1 > t0``.
    dt : float
        Step (s), finite, above ``2 tol`` and at most ``t1 - t0`` (to ``tol``).
    max_steps : int
        Refuse grids of more steps than this.

    Returns
    -------
    t : ndarray, shape (n+1,)
        ``t0 + dt * k`` (in floating point) for ``k < n``, and ``t1``.
    last : float
        The last step (s): ``dt`` when the span is a whole number of steps (to ``tol``),
        else ``t1 - t[n-1]``, shorter than ``dt - tol``.

    Examples
    --------
    >>> time_grid((0.0, 0.3), 0.1)[0].size - 1      # 0.1 * 3 != 0.3, yet three steps
    3
    >>> t, last = time_grid((64.0, 64.25), 0.1)
    >>> t.tolist(), round(last, 12)
    ([64.0, 64.1, 64.2, 64.25], 0.05)
    """
    if not isinstance(t_span, tuple | list | np.ndarray) or len(t_span) != 2:
        raise TypeError(f"t_span must be a pair (t0, t1), got {t_span!r}")
    t0 = _validate.finite_real("t_span[0]", t_span[0])
    t1 = _validate.finite_real("t_span[1]", t_span[1])
    dt = _validate.positive_finite("dt", dt)
    max_steps = _validate.positive_int("max_steps", max_steps)
    if t1 <= t0:
        raise ValueError(f"t_span must have t1 > t0, got ({t0:g}, {t1:g})")
    span = t1 - t0
    if not math.isfinite(span):
        raise ValueError(f"t_span = ({t0:g}, {t1:g}) is too long: t1 - t0 overflows a float")
    ratio = span / dt
    if not ratio <= max_steps + 1:
        _too_many(t0, t1, dt, ratio, max_steps)
    tol = grid_tolerance(t0, t1)
    if dt <= 2 * tol:
        raise ValueError(f"dt = {dt:g} is below the float resolution of times near "
                         f"{max(abs(t0), abs(t1)):g} s: t0 + k dt would not be distinct")

    def last_step(n: int) -> float:
        # t1 - t[n-1], with t[n-1] rounded exactly as numpy rounds t0 + dt * k below
        return t1 - (t0 + dt * float(n - 1))

    n = max(1, round(ratio))
    while last_step(n) > dt + tol:                     # the fewest steps whose last step
        n += 1                                         # is at most dt + tol
    while n > 1 and last_step(n - 1) <= dt + tol:
        n -= 1
    whole = abs(last_step(n) - dt) <= tol
    if not whole and n == 1:
        raise ValueError(f"dt = {dt:g} is longer than the span t1 - t0 = {span:g}: "
                         "integrate shortens only a last step, so dt must be <= t1 - t0")
    if n > max_steps:
        _too_many(t0, t1, dt, ratio, max_steps)
    t = t0 + dt * np.arange(n + 1, dtype=float)
    t[-1] = t1
    return t, (dt if whole else float(t1 - t[-2]))


def _too_many(t0: float, t1: float, dt: float, ratio: float, max_steps: int):
    raise ValueError(
        f"t_span = ({t0:g}, {t1:g}) with dt = {dt:g} needs {ratio:.3g} steps, more than "
        f"max_steps = {max_steps:,}: every step's state is stored, so the run would be "
        "slow and its trajectory huge. Use a larger dt or a shorter span, or pass a "
        "larger max_steps if you mean it."
    )
