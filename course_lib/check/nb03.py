"""Checks for notebook 03, stability."""

from __future__ import annotations

import numpy as np

from ..stability import amplification_factor
from . import Checker, exercise

#: The ``k`` values (1/s) the step-limit checks try.
RATES = (1.0, 4.0, 0.5)

#: The (method, z) pairs of the classification exercise, with exactly representable
#: boundary cases (|R| = 1 exactly) and the implicit methods' poles.
PAIRS: list[tuple[str, complex]] = [
    ("forward_euler", -1.5),
    ("forward_euler", -2.0),       # R = -1: on the boundary
    ("forward_euler", 0.5j),       # the vortex: |R| = √1.25 > 1
    ("midpoint", -2.0),            # R = 1: on the boundary
    ("midpoint", 1.0j),
    ("rk4", 2.5j),
    ("rk4", 3.0j),
    ("backward_euler", -10.0),
    ("backward_euler", 0.5),       # inside the unstable disk |z - 1| < 1
    ("backward_euler", 1.0),       # the pole: R = ∞
    ("backward_euler", 3.0),       # right half-plane, yet stable: |R| = 1/2
    ("trapezoidal", 2.0j),         # R = i exactly: on the boundary
    ("trapezoidal", 2.0),          # the pole: R = ∞
    ("symplectic_euler", 1.5j),
    ("velocity_verlet", 2.5j),
]


def _abs_R(pairs) -> np.ndarray:
    return np.array([abs(complex(amplification_factor(m, z))) for m, z in pairs])


def classification_answer(pairs=PAIRS, tol: float = 1e-12) -> list[bool]:
    """The reference answer: ``|R(z)| <= 1`` (with round-off allowance ``tol``)."""
    return [bool(a <= 1.0 + tol) for a in _abs_R(pairs)]


def _strict_answer(pairs=PAIRS) -> list[bool]:
    return [bool(a < 1.0) for a in _abs_R(pairs)]


def _implicit_always_stable(pairs=PAIRS) -> list[bool]:
    ref = classification_answer(pairs)
    return [True if m in ("backward_euler", "trapezoidal") else s
            for (m, _), s in zip(pairs, ref, strict=True)]


@exercise
def largest_stable_dt(ck: Checker, func) -> None:
    """``func(k)``: the largest stable forward Euler step on dx/dt = -k x, by experiment."""
    for k in RATES:
        got = func(k)
        ck.close(
            got, 2.0 / k, f"largest stable dt for k = {k:g} is 2/k = {2.0 / k:g} (within 1%)",
            rtol=1e-2, atol=0.0,
            hint="bisect: keep the stable half [lo, mid] or the unstable half [mid, hi]; run "
                 "enough steps (hundreds) with a small blowup_bound (e.g. 2) so slow growth "
                 "just above the limit is caught",
            mistakes={
                "that is 1/k, the limit for a run without sign flips (R = 1 - k dt >= 0); "
                "stability only needs |1 - k dt| <= 1": 1.0 / k,
                "your bisection never saw an unstable run: start hi above 2/k and check "
                "traj.stable": 10.0,
            },
        )


@exercise
def euler_dt_limits(ck: Checker, func) -> None:
    """``func(k) -> (dt_stable, dt_no_oscillation)`` for forward Euler on dx/dt = -k x."""
    for k in RATES:
        got = func(k)
        ck.close(
            got, (2.0 / k, 1.0 / k), f"k = {k:g}: (2/k, 1/k) = ({2.0 / k:g}, {1.0 / k:g})",
            mistakes={
                "the two limits are swapped: |1 - k dt| <= 1 gives the stability limit 2/k, "
                "1 - k dt >= 0 the oscillation-free one 1/k": (1.0 / k, 2.0 / k),
                "the limits scale like 1/k (a faster decay needs a smaller step), not like k":
                    (2.0 * k, 1.0 * k),
            },
        )


@exercise
def classify_stability(ck: Checker, func) -> None:
    """``func(pairs) -> list[bool]``: is each (method, z) in the method's stability region?"""
    try:
        got = func(list(PAIRS))
    except ZeroDivisionError:
        ck.expect(False, "classify every pair", "your code divided by zero",
                  hint="the implicit methods have a pole (backward Euler at z = 1, the "
                       "trapezoid at z = 2) where R = ∞: unstable. cl.amplification_factor "
                       "returns inf there instead of raising")
        return
    if isinstance(got, np.ndarray):
        got = got.tolist()
    if not isinstance(got, list | tuple) or not all(
        isinstance(b, bool | np.bool_) for b in got
    ):
        ck.expect(False, "return a list of booleans",
                  f"got {type(got).__name__}: {got!r}"[:200])
        return
    ok = ck.close(
        np.asarray(got, dtype=float), np.asarray(classification_answer(), dtype=float),
        f"all {len(PAIRS)} pairs classified (1 = stable)",
        mistakes={
            "stable means |R(z)| <= 1, boundary included (|R| = 1 neither grows nor decays); "
            "you used |R| < 1. Allow round-off: |R| <= 1 + 1e-12":
                np.asarray(_strict_answer(), dtype=float),
            "implicit methods are not stable everywhere: backward Euler is unstable inside "
            "the disk |z - 1| < 1 and the trapezoid for Re z > 0; at their poles (z = 1 and "
            "z = 2) R = ∞": np.asarray(_implicit_always_stable(), dtype=float),
        },
    )
    if not ok and len(got) == len(PAIRS):
        ref = classification_answer()
        wrong = [f"{m} at z = {z}: expected {r}, got {bool(g)}"
                 for (m, z), g, r in zip(PAIRS, got, ref, strict=True) if bool(g) != r]
        ck.failed[-1] += "".join(f"\n      {w}" for w in wrong)
