"""The time grid of a fixed-step run: where :func:`course_lib.integrate` reports the state.

The rule: the grid lands exactly on ``t1``. When ``t1 - t0`` is a whole number ``n`` of
steps to round-off (``|t1 - t0 - n dt| <= 1e-12 (t1 - t0)`` plus the float spacing of the
times), the run takes ``n`` steps of ``dt``; otherwise ``n = ceil((t1 - t0) / dt)`` and only
the last step is shortened, to ``t1 - t[n-1]``. A ``dt`` longer than the span, one below
the float resolution of the times, or a grid of more than ``max_steps`` steps is refused
with a ``ValueError`` that says which. Imports: numpy and ``_validate`` (core layer).
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate

#: Default cap on the number of steps of one run (``integrate(..., max_steps=...)``).
MAX_STEPS = 10_000_000


def time_grid(t_span, dt: float, max_steps: int = MAX_STEPS) -> tuple[np.ndarray, float]:
    """The times of :func:`integrate`'s grid and the length of its last step.

    Parameters
    ----------
    t_span : (float, float)
        Start and end time (s), ``t1 > t0``.
    dt : float
        Step (s), finite and > 0, at most ``t1 - t0``.
    max_steps : int
        Refuse grids of more steps than this.

    Returns
    -------
    t : ndarray, shape (n+1,)
        ``t0 + k dt`` for ``k < n``, and ``t1``.
    last : float
        The last step (s): ``dt`` when the span is a whole number of steps, else shorter.
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
    if not ratio <= max_steps:
        raise ValueError(
            f"t_span = ({t0:g}, {t1:g}) with dt = {dt:g} needs {ratio:.3g} steps, more than "
            f"max_steps = {max_steps:,}: every step's state is stored, so the run would be "
            "slow and its trajectory huge. Use a larger dt or a shorter span, or pass a "
            "larger max_steps if you mean it."
        )
    resolution = 4.0 * float(np.spacing(max(abs(t0), abs(t1))))
    if dt <= resolution:
        raise ValueError(f"dt = {dt:g} is below the float resolution of times near "
                         f"{max(abs(t0), abs(t1)):g} s: t0 + k dt would not be distinct")
    n, short = round(ratio), False
    if not (n >= 1 and abs(span - n * dt) <= 1e-12 * span + resolution):
        if ratio < 1.0:
            raise ValueError(f"dt = {dt:g} is longer than the span t1 - t0 = {span:g}: "
                             "integrate shortens only a last step, so dt must be <= t1 - t0")
        n, short = math.ceil(ratio), True
    t = t0 + dt * np.arange(n + 1, dtype=float)
    t[-1] = t1
    last = t1 - t[-2] if short else dt
    return t, last
