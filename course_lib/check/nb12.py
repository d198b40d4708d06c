"""Checks for notebook 12, constraints and large steps: the local step of fast mass-springs
(each spring projected onto its rest length) and XPBD's multiplier update.

Expected values come from the library (:meth:`SpringNetwork.project
<course_lib.springs.network.SpringNetwork.project>`, :func:`course_lib.largestep.delta_lambda`);
an answer may call neither (``allow=()``). The cases break the usual shortcuts: springs
listed with their ends in either order, compressed as well as stretched, in 2-D and 3-D,
multipliers that are not zero, compliances from rigid to soft, several step lengths.
"""

from __future__ import annotations

import numpy as np

from .. import springs
from ..largestep import delta_lambda
from . import Checker, exercise
from ._answers import call
from ._answers import close as _close

_SEED = 1212


def _projection_cases():
    rng = np.random.default_rng(_SEED)
    x = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.5, 0.0]])
    yield "a spring stretched along x (ℓ = 2 m, L = 1 m)", x, np.array([1]), np.array([0]), np.array([1.0])
    yield "a spring compressed along y (ℓ = 0.5 m, L = 2 m)", x, np.array([0]), np.array([2]), np.array([2.0])
    x = rng.normal(size=(8, 3))
    i, j = np.array([3, 0, 7, 5, 2, 6]), np.array([1, 4, 2, 0, 6, 7])   # either order, shared ends
    yield "6 springs among 8 particles in 3-D", x, i, j, rng.uniform(0.2, 2.5, 6)
    x2 = rng.normal(size=(5, 2))
    yield "4 springs in 2-D", x2, np.array([0, 2, 4, 1]), np.array([1, 1, 3, 3]), rng.uniform(0.5, 1.5, 4)


@exercise(allow=())
def project_springs(ck: Checker, func) -> None:
    """``func(x, i, j, rest) -> (M, d)``: each spring's vector ``x_i - x_j`` projected onto
    the rest length, ``L (x_i - x_j)/|x_i - x_j|``."""
    for what, x, i, j, rest in _projection_cases():
        net = springs.SpringNetwork(i, j, rest, 1.0, 0.0, len(x))
        expected = net.project(x)
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1, keepdims=True)
        u = d / length
        mistakes = {
            ("that is the spring itself: the local step replaces it by the closest vector of "
             "length L", "that is d = x_i - x_j itself: scale it to length L, L d/|d|"): d,
            ("the result should have length L: divide by the spring's length first",
             "L d has length L |d|: use the unit vector, L d/|d|"): rest[:, None] * d,
            ("that is the stretch along the spring, not the projected spring",
             "(ℓ - L) u is how far the spring is off its rest length; the projection is L u"):
                (length - rest[:, None]) * u,
            ("the projection has length L, not 1", "multiply the unit vector by L: L d/|d|"): u,
            ("the direction is reversed: spring s runs from x[j[s]] to x[i[s]]",
             "use d = x[i] - x[j] (the order the springs are listed in)"): -expected,
        }
        ok, got = call(ck, what, func, x.copy(), i.copy(), j.copy(), rest.copy())
        if ok:
            _close(ck, got, expected, what, mistakes=mistakes,
                   hint=("each row is one spring: the vector between its ends, turned neither way, "
                         "with length L", "p_s = L_s (x_i - x_j)/|x_i - x_j| for every spring s"))


def _lambda_cases():
    rng = np.random.default_rng(_SEED + 1)
    yield ("one stretched spring, λ = 0, h = 1/60 s", np.array([0.01]), np.array([0.0]),
           np.array([2.0]), np.array([1e-3]), 1 / 60)
    yield ("5 springs later in the iterations (λ ≠ 0), h = 1/600 s", rng.normal(0, 0.01, 5),
           rng.normal(0, 1e-4, 5), rng.uniform(10, 100, 5), rng.uniform(1e-5, 1e-2, 5), 1 / 600)
    yield ("rigid (compliance 0) beside soft springs, h = 0.01 s",
           np.array([0.02, -0.01, 0.005]), np.array([1e-3, -2e-3, 0.0]), np.array([1.0, 3.0, 2.0]),
           np.array([0.0, 1e-4, 10.0]), 0.01)


@exercise(allow=())
def xpbd_delta_lambda(ck: Checker, func) -> None:
    """``func(C, lam, w, compliance, h) -> Δλ``: ``(-C - α̃ λ)/(w + α̃)``, ``α̃ = α/h²``."""
    for what, C, lam, w, alpha, h in _lambda_cases():
        expected = delta_lambda(C, lam, w, alpha, h)
        at = alpha / h**2
        mistakes = {
            ("the multiplier λ so far is missing: without it more iterations keep pushing "
             "and the spring gets stiffer with every iteration",
             "the numerator is -C - α̃ λ: λ remembers how much force the spring already "
             "applied in this step"): -C / (w + at),
            ("compliance has units m/N; XPBD uses it per step squared",
             "α̃ = α/h² (divide the compliance by h²)"): (-C - alpha * lam) / (w + alpha),
            ("α̃ = α/h², not α h²", "divide the compliance by h², do not multiply"):
                (-C - alpha * h**2 * lam) / (w + alpha * h**2),
            ("the sign: a stretched spring (C > 0) needs a negative Δλ",
             "Δλ = (-C - α̃ λ)/(w + α̃)"): -expected,
            ("that is PBD's update -C/w: the compliance must appear in both numerator and "
             "denominator", "Δλ = (-C - α̃ λ)/(w + α̃)"): -C / w,
        }
        ok, got = call(ck, what, func, C.copy(), lam.copy(), w.copy(), alpha.copy(), h)
        if ok:
            _close(ck, got, expected, what, mistakes=mistakes,
                   hint=("check the compliance term: it enters with the multiplier on top and "
                         "alone below", "Δλ = (-C - α̃ λ)/(w + α̃) with α̃ = α/h²"))
