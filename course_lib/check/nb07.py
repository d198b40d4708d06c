"""Checks for notebook 07, springs and mass-spring systems.

An answer may call no course_lib function (:mod:`course_lib.check.policy`); the step-limit
exercise asks for a formula, so it also refuses ``scipy.integrate`` and a search by
simulation written by hand (:func:`~course_lib.check._answers.call_analysis`). Hints name
the slip the answer reproduces, or what the data that broke it show.
"""

from __future__ import annotations

import numpy as np

from .. import springs
from ..lessons import nb07_spring_runs as lesson
from . import Checker, exercise
from ._answers import call_analysis, one_number
from .tolerance import blown_up, escalate, precision_rtol

_RNG_SEED = 707


def _cases():
    """(what, x1, x2, k, rest): random springs, one compressed, one stretched to 4 times its
    rest length, one along an axis."""
    rng = np.random.default_rng(_RNG_SEED)
    for n in range(3):
        x1, x2 = rng.normal(size=3), rng.normal(size=3)
        yield f"case {n}: force on particle 1", x1, x2, float(rng.uniform(5.0, 50.0)), \
            float(rng.uniform(0.3, 1.5))
    yield ("compressed to half its rest length", np.array([0.3, -0.2, 0.5]),
           np.array([0.1, 0.4, 0.2]), 20.0, 2.0 * np.linalg.norm([0.2, -0.6, 0.3]))
    yield ("stretched to 4 times its rest length", np.array([1.0, 2.0, -1.0]),
           np.array([-1.0, 0.5, 1.0]), 7.0, 0.25 * np.linalg.norm([2.0, 1.5, -2.0]))


@exercise(allow=())
def spring_force(ck: Checker, func) -> None:
    """``func(x1, x2, k, rest)``: Hooke force on particle 1 of a spring in 3D."""
    for what, x1, x2, k, rest in _cases():
        d = x1 - x2
        length = np.linalg.norm(d)
        u = d / length
        expected = -k * (length - rest) * u
        got = func(x1.copy(), x2.copy(), k, rest)
        if blown_up(ck, got, what, run=False):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-9),
                 atol=1e-12, mistakes={
            "sign error: the force on particle 1 points from x1 towards x2 when the spring is "
            "stretched, F1 = -k (|d| - L) d/|d| with d = x1 - x2": -expected,
            "forgot to normalise: multiply by the unit vector d/|d|, not by d itself":
                -k * (length - rest) * d,
            "used the rest length L instead of the stretch |d| - L": -k * rest * u,
            "used the length |d| instead of the stretch |d| - L": -k * length * u,
            "the stretch is |d| - L, a scalar: subtract L from the length, not from the "
            "vector d": -k * (d - rest),
            "the direction is the unit vector d / |d|: you divided d by the rest length L":
                -k * (length - rest) * d / rest,
        })
    # Force = -gradient of the spring energy, by central finite differences.
    _, x1, x2, k, rest = next(_cases())

    def energy(p):
        return 0.5 * k * (np.linalg.norm(p - x2) - rest) ** 2

    h = 1e-6
    grad = np.array([(energy(x1 + h * e) - energy(x1 - h * e)) / (2 * h) for e in np.eye(3)])
    ck.close(func(x1.copy(), x2.copy(), k, rest), -grad,
             "F1 = -∂E/∂x1 (finite differences of E = ½ k (|x1 - x2| - L)²)", rtol=1e-6, atol=1e-8)
    f1 = func(x1.copy(), x2.copy(), k, rest)
    f2 = func(x2.copy(), x1.copy(), k, rest)
    # round-off of the answer's precision, relative to the forces and torques involved
    scale = precision_rtol(f1, 1e-14) * 10 * (1.0 + np.abs(f1).max()) * (1.0 + np.abs(x1).max())
    f1, f2 = np.asarray(f1, dtype=float), np.asarray(f2, dtype=float)
    ck.close(f1 + f2, np.zeros(3), "momentum: F1 + F2 = 0", atol=scale,
             hint="with its arguments swapped your function gives the force on particle 2, "
                  "which must be exactly -F1: the same magnitude, the opposite direction")
    ck.close(np.cross(x1, f1) + np.cross(x2, f2), np.zeros(3),
             "angular momentum: x1 × F1 + x2 × F2 = 0", atol=scale,
             hint="the force must act along the line x1 - x2")


#: Lines of Python a formula needs at most (a search by simulation runs thousands).
FORMULA_LINES = 200


@exercise(allow=(), forbid=("scipy.integrate",))
def damped_dt_max(ck: Checker, func) -> None:
    """``func(k, m, c)``: largest stable symplectic Euler step of a damped spring."""
    for k, m, c in [(10.0, 1.0, 0.0), (10.0, 1.0, 2.0), (16.0, 1.0, 8.0), (50.0, 0.2, 0.3),
                    (4.0, 9.0, 40.0)]:
        measured = lesson.damped_dt_limit("symplectic_euler", k, m, c)
        omega, gamma = np.sqrt(k / m), c / m
        zeta = gamma / (2 * omega)
        what = f"k = {k:g} N/m, m = {m:g} kg, c = {c:g} N s/m (measured {measured:.6f} s)"
        ok, got = call_analysis(ck, what, FORMULA_LINES, (
            "the exercise asks for the limit from the stability condition, a formula: your "
            "function searches for it by simulation"), func, k, m, c)
        if not ok:
            if "lines of Python" in ck.failed[-1]:
                break                   # a simulation: one case says it, the rest would repeat
            continue
        if blown_up(ck, got, what, run=False):
            continue
        if one_number(ck, what, got, "a step in s") is None:
            continue
        ck.close(got, measured, what, rtol=precision_rtol(got, 1e-9), mistakes={
                     "that is the undamped limit 2/ω: damping moves it (ω² dt² + 2 (c/m) dt < 4)":
                         2.0 / omega,
                     "you forgot to divide c by m: the condition uses γ = c/m":
                         4.0 / (c + np.sqrt(c**2 + 4 * omega**2)),
                     "wrong root: of the two roots of ω² dt² + 2γ dt - 4 = 0 take the positive one":
                         (gamma + np.sqrt(gamma**2 + 4 * omega**2)) / omega**2,
                     "the discriminant of ω² dt² + 2γ dt - 4 is 4γ² + 16ω²: its square root "
                     "is 2√(γ² + 4ω²)": (-gamma + np.sqrt(gamma**2 + 16 * omega**2)) / omega**2,
                     "only the damping part: 2/γ is the limit for damping alone":
                         2.0 / gamma if gamma else np.inf,
                     "(2/ω)(1 - ζ) is the small-damping approximation, wrong at ζ = 1 and "
                     "beyond: solve the quadratic exactly": 2.0 / omega * (1.0 - zeta),
                 })


class _Indices(np.ndarray):
    """Spring end indices that notice being looped over (one spring at a time)."""

    looped = False

    def __iter__(self):
        _Indices.looped = True
        return super().__iter__()

    def __getitem__(self, key):
        if isinstance(key, int | np.integer):
            _Indices.looped = True
        return super().__getitem__(key)


def _network_case(seed: int, n: int, m: int, dim: int = 3):
    rng = np.random.default_rng(seed)
    i = rng.integers(0, n, m)
    j = (i + rng.integers(1, n, m)) % n                 # i != j, many springs per particle
    i[-1], j[-1] = i[0], j[0]                           # two springs on the same pair
    x, v = rng.normal(size=(n, dim)), rng.normal(size=(n, dim))
    return x, v, i, j, rng.uniform(0.5, 1.5, m), rng.uniform(5.0, 50.0, m), rng.uniform(0.0, 2.0, m)


@exercise(allow=())
def network_forces(ck: Checker, func) -> None:
    """``func(x, v, i, j, rest, k, c)``: net force of a damped spring network, vectorized."""
    for what, (x, v, i, j, rest, k, c) in [
            ("6 particles, 15 springs in 3D", _network_case(1, 6, 15)),
            ("7 particles, 24 springs in 2D", _network_case(2, 7, 24, dim=2))]:
        net = springs.SpringNetwork(i, j, rest, k, c, x.shape[0])
        expected = net.forces(x, v)
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        rate = np.einsum("md,md->m", v[i] - v[j], u)
        f = -(k * (length - rest) + c * rate)[:, None] * u
        buffered = np.zeros_like(x)
        buffered[i] += f
        buffered[j] -= f
        only_i = np.zeros_like(x)
        np.add.at(only_i, i, f)
        unprojected = np.zeros_like(x)
        f_bad = -(k * (length - rest))[:, None] * u - c[:, None] * (v[i] - v[j])
        np.add.at(unprojected, i, f_bad)
        np.add.at(unprojected, j, -f_bad)
        no_damping = springs.SpringNetwork(i, j, rest, k, 0.0, x.shape[0]).forces(x)
        _Indices.looped = False
        got = func(x.copy(), v.copy(), i.view(_Indices), j.view(_Indices), rest.copy(),
                   k.copy(), c.copy())
        if _Indices.looped:
            ck.expect(False, what, "your function loops over the springs one at a time",
                      hint=escalate("work on all springs at once: index the positions with the arrays "
                            "i and j", "d = x[i] - x[j] gives every spring's vector; np.add.at "
                            "(or np.bincount) adds the forces onto particles"))
            continue
        if blown_up(ck, got, what, run=False):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12, mistakes={
            "F[i] += f skips repeated indices (numpy buffers the fancy-index add): a particle "
            "with several springs gets only one of them. Use np.add.at(F, i, f)": buffered,
            "each spring pushes both ends: add f at i AND -f at j": only_i,
            "damp only the stretching rate: c ((v_i - v_j)·u) u, not c (v_i - v_j)": unprojected,
            "you left out the damping term c ((v_i - v_j)·u) u": no_damping,
            "sign error: a stretched spring pulls i towards j": -expected,
        })
