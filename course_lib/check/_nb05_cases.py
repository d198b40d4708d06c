"""Case data of notebook 05's checks of ``impact_time`` and ``observed_order``.

:func:`impact_cases` holds the sampled heights the impact check runs (the apple by three
methods, samples touching 0, a throw from the ground, a bounce that crosses four times,
uneven samples) and :func:`impact_mistakes` what the usual slips return on them, keyed by
hint; :func:`power_run` and :func:`pendulum_run` are the hidden runs of the order check and
:func:`order_mistakes` the orders and errors its usual slips give. Imports NumPy, the
core's events and integrators, notebook 05's lesson and the hint helper.
"""

from __future__ import annotations

import numpy as np

from .. import events
from ..integrators import integrate
from ..lessons import nb05_newton as lesson
from .tolerance import escalate


def impact_cases():
    """(what, t, h): the apple by three methods, and data that breaks the shortcuts."""
    cases = []
    for method in ("forward_euler", "symplectic_euler", "velocity_verlet"):
        traj = lesson.apple_drop(method)
        cases.append((f"apple by {method}", traj.t, traj.y[:, 0, 0, 1]))
    cases.append(("samples that touch 0 exactly: h = (1, 0, -1) at t = (0, 1, 2)",
                  np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.0, -1.0])))
    t = np.linspace(0.0, 2.0, 21)
    cases.append(("thrown up from the ground (h starts at 0, rises, then falls)", t,
                  8.0 * t - 4.905 * t**2))
    tb = np.linspace(0.0, 4.5, 46)
    hb = np.abs(np.cos(2.2 * tb)) * np.exp(-0.3 * tb) - 0.25      # dips below 0 four times
    cases.append(("a bouncing height that goes below 0 four times", tb, hb))
    tu = np.cumsum(np.r_[0.0, np.random.default_rng(55).uniform(0.05, 0.3, 14)])
    cases.append(("unevenly spaced samples", tu, 2.0 - 1.5 * tu**2 + 0.2 * np.sin(9 * tu)))
    return cases


def impact_mistakes(t, h):
    k = int(np.flatnonzero(h < 0)[0])
    dt = t[k] - t[k - 1]
    with np.errstate(all="ignore"):
        out = {
            "you returned the time of the first sample below ground; interpolate between it "
            "and the sample before": t[k],
            "you returned the time of the last sample above ground; interpolate between it "
            "and the next one": t[k - 1],
            "the fraction of the step is the part of the drop still above ground, h[k-1] / "
            "(h[k-1] - h[k]); you put h[k] on top": t[k - 1] + dt * h[k] / (h[k - 1] - h[k]),
            "mind the sign of the fraction: the crossing lies after t[k-1], not before":
                t[k - 1] - dt * h[k - 1] / (h[k - 1] - h[k]),
            "you returned an index; return the time t*": k,
            "you returned the midpoint of the step; interpolate where the line meets 0":
                0.5 * (t[k - 1] + t[k]),
            "these samples are not evenly spaced: the step is t[k] - t[k-1], not t[1] - t[0]":
                t[k - 1] + (t[1] - t[0]) * h[k - 1] / (h[k - 1] - h[k]),
        }
        later = np.flatnonzero((h[1:] < 0) & (h[:-1] >= 0)) + 1
        last = None
        if later.size > 1:
            j = int(later[-1])
            last = t[j - 1] + (t[j] - t[j - 1]) * h[j - 1] / (h[j - 1] - h[j])
            out = {"your time is the LAST crossing of this bouncing height: the impact is the "
                   "first time h goes below 0 (a search from the end of the run finds the "
                   "last one)": last, **out}
        by_interp = np.interp(0.0, h[::-1], t[::-1])
        if not np.isclose(by_interp, events.first_crossing(t, h)) and (
                last is None or not np.isclose(by_interp, last)):
            out["np.interp needs increasing sample points, and h is not monotone here: find "
                "the first sample below 0 and interpolate on that step"] = by_interp
        start = np.flatnonzero(np.diff(np.sign(h)) != 0)
        if h[0] == 0.0 and start.size:
            out["h starts at 0 on the ground: a sign change from 0 to + is the throw, not the "
                "impact; look for the first sample BELOW 0"] = float(t[0])
    return out


def power_run(p: float, shape=(), seed: int = 0):
    """A run whose result approaches a hidden limit like ``C dt^p + D dt^(p+1)``."""
    rng = np.random.default_rng(seed)
    limit, C, D = (rng.normal(size=shape) for _ in range(3))
    return lambda dt: limit + C * dt**p + D * dt ** (p + 1)


def pendulum_run(method: str):
    f = lesson.pendulum()
    return lambda dt: integrate(f, np.array([1.0, 0.0]), (0.0, 2.0), dt, method).y[-1]


def order_mistakes(coarse, middle, fine, p, err) -> tuple[dict, dict]:
    """Wrong orders and wrong errors that the usual slips give."""
    ratio = 2.0**p
    d2 = err * (ratio - 1.0)
    m1, m2 = np.abs(coarse - middle).max(), np.abs(middle - fine).max()
    p_max = np.log2(m1 / m2)
    s1, s2 = np.sum(coarse - middle), np.sum(middle - fine)
    orders = {
        escalate("that is the ratio of the two differences, about 2^p: the order is in its "
                 "exponent", "halving dt divides the difference by 2^p, so p is the base-2 "
                 "logarithm of the ratio"): ratio,
        "use the base-2 logarithm: halving dt divides the difference by 2^p": np.log(ratio),
        "use the base-2 logarithm, not base 10": np.log10(ratio),
        "upside down: the coarse difference |y_h - y_h/2| goes on top": -p,
        "the finest run is not exact: compare consecutive runs, (y_h - y_h/2) with "
        "(y_h/2 - y_h/4)": np.log2(ratio + 1.0),
        "you rounded p: a measured order is not a whole number; return it as measured":
            float(np.round(p)),
        "measure each difference with the Euclidean norm over all components "
        "(np.linalg.norm), as the exercise says, not the largest entry": p_max,
    }
    if coarse.size > 1:   # a signed sum of the components lets them cancel
        signed = escalate("reduce each difference to one size with a norm, not a signed sum: "
                          "components of opposite signs cancel in a sum",
                          "the exercise asks for the Euclidean norm over all components")
        with np.errstate(all="ignore"):
            orders = {signed: np.log2(abs(s1) / abs(s2)), **orders}
    errors = {
        escalate("|y_h/2 - y_h/4| is the error of y_h/2 minus that of y_h/4, not the finest "
                 "run's own error", "write both runs with y_h ≈ y + C h^p: which multiple of "
                 "the finest run's error C (h/4)^p is their difference?"): d2,
        escalate("|y_h - y_h/2| / (2^p - 1) is the error of the MIDDLE run; the finest "
                 "run's is 2^p times smaller", "use the difference of the two finest runs"):
            d2 * ratio / (ratio - 1.0),
        escalate("close, but the difference of the two finest runs is not 2^p times the "
                 "finest run's error", "write y_h/2 - y_h/4 = C (h/2)^p - C (h/4)^p and "
                 "factor out C (h/4)^p, the finest run's error: what is left?"): d2 / ratio,
        "measure each difference with the Euclidean norm over all components": m2 / (2**p_max - 1),
    }
    return orders, errors
