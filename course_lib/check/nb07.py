"""Checks for notebook 07, springs and mass-spring systems.

An answer may call no course_lib function (:mod:`course_lib.check.policy`); the step-limit
exercise asks for a formula, so it also refuses ``scipy.integrate`` and a search by
simulation written by hand (:func:`~course_lib.check._answers.call_analysis`). Hints name
the slip the answer reproduces, or what the data that broke it show.
"""

from __future__ import annotations

import numpy as np

from .. import springs
from ..lessons import nb07_spring_limits as lesson
from . import Checker, exercise
from ._answers import call_analysis, close, one_number
from .tolerance import blown_up, consistent_hint, escalate, precision_rtol

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


def _spring_mistakes(x1, x2, k, rest) -> dict:
    """The usual wrong forces on particle 1, in the order they are diagnosed (a mistake that
    only differs on a compressed spring comes before the plain sign error)."""
    d = x1 - x2
    length = np.linalg.norm(d)
    u = d / length
    right = -k * (length - rest) * u
    return {
        escalate("your spring pulls even when it is compressed: the stretch |d| - L is "
                 "negative then, and the force must change direction with it",
                 "keep the sign of |d| - L (no absolute value): a compressed spring pushes "
                 "its ends apart"): -k * abs(length - rest) * u,
        escalate("sign error: a stretched spring must pull particle 1 towards particle 2",
                 "d = x1 - x2 points from particle 2 to particle 1; the pull on particle 1 "
                 "points the other way"): -right,
        escalate("the force does not vanish at the rest length: Hooke's law acts on the "
                 "stretch, not on the length",
                 "you used the length |d| where the stretch |d| - L belongs"): -k * length * u,
        escalate("the force does not vanish at the rest length: you used the rest length L "
                 "where the stretch belongs", "the stretch is |d| - L"): -k * rest * u,
        escalate("the stretch is a number (a length minus a length): you subtracted L from "
                 "the vector d", "take the length |d| first, then subtract L"): -k * (d - rest),
        escalate("the size of your force grows with |d| beyond Hooke's law: the direction "
                 "must be a unit vector", "multiply by d/|d|, not by d"):
            -k * (length - rest) * d,
        escalate("the direction must be a unit vector: you divided d by the rest length L",
                 "divide d by its own length |d|"): -k * (length - rest) * d / rest,
        escalate("you divided the stretch by the rest length (a strain): here k is in N/m and "
                 "multiplies the stretch itself, in m", "drop the division by L"):
            -k * (length - rest) / rest * u,
    }


@exercise(allow=())
def spring_force(ck: Checker, func) -> None:
    """``func(x1, x2, k, rest)``: Hooke force on particle 1 of a spring in 3D."""
    results = []
    for what, x1, x2, k, rest in _cases():
        d = x1 - x2
        expected = -k * (np.linalg.norm(d) - rest) * d / np.linalg.norm(d)
        got = func(x1.copy(), x2.copy(), k, rest)
        if blown_up(ck, got, what, run=False):
            continue
        results.append((what, got, expected, _spring_mistakes(x1, x2, k, rest)))
    hint = consistent_hint([(got, exp, mis) for _, got, exp, mis in results])
    for what, got, expected, _ in results:
        close(ck, got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12, hint=hint)
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


def _limit_mistakes(k: float, m: float, c: float) -> dict:
    """The usual wrong step limits (s) for one spring, keyed by hint (the same keys for
    every spring, so that :func:`consistent_hint` can name one mistake for all of them)."""
    omega, gamma = np.sqrt(k / m), c / m
    zeta = gamma / (2 * omega)
    with np.errstate(divide="ignore"):
        half_kicks = 4.0 / gamma if gamma else np.inf
    return {
        escalate("that is the undamped limit 2/ω: the damping moves it",
                 "solve the damped condition of section 5 for dt"): 2.0 / omega,
        escalate("the smaller of 2/ω and 4/γ is velocity Verlet's limit away from light "
                 "damping, which takes the damping in two half kicks; symplectic Euler takes "
                 "it in one full kick, and its limit is neither", "solve the damped "
                 "condition of section 5, the quadratic in dt, for dt"):
            min(2.0 / omega, half_kicks),
        escalate("that is velocity Verlet's first instability (the cubic of section 5): the "
                 "exercise asks for symplectic Euler's", "symplectic Euler's condition is the "
                 "quadratic in dt of section 5"): lesson.velocity_verlet_windows(k, m, c)[0][1],
        escalate("4/γ is the limit of damping applied in two half kicks (velocity Verlet's): "
                 "symplectic Euler applies it in one full kick, and the spring lowers the "
                 "limit further", "keep both terms of the condition of section 5"): half_kicks,
        escalate("the condition uses the damping rate γ = c/m, in 1/s: check what you used "
                 "for γ", "divide c by m"): 4.0 / (c + np.sqrt(c**2 + 4 * omega**2)),
        escalate("wrong root: the quadratic in dt has a negative and a positive root, and "
                 "the step is the positive one",
                 "the positive root has + before the square root, -γ + √(...)"):
            (gamma + np.sqrt(gamma**2 + 4 * omega**2)) / omega**2,
        escalate("check the discriminant of your quadratic in dt",
                 "for a dt² + b dt + c = 0 it is b² - 4ac, here with b = 2γ"):
            (-gamma + np.sqrt(gamma**2 + 16 * omega**2)) / omega**2,
        escalate("a factor 2 went missing: the damping enters the condition as 2 γ dt, not "
                 "γ dt", "redo the algebra of tr S > -(1 + det S) with tr S = 2 - ω² dt² - "
                 "γ dt and det S = 1 - γ dt"):
            (-gamma + np.sqrt(gamma**2 + 16 * omega**2)) / (2 * omega**2),
        escalate("only the damping part: 2/γ is the limit of the damping alone, and the "
                 "spring lowers it further", "keep both terms of the condition"):
            2.0 / gamma if gamma else np.inf,
        escalate("(2/ω)(1 - ζ) is the small-damping approximation, wrong at ζ = 1 and "
                 "beyond", "solve the quadratic exactly"): 2.0 / omega * (1.0 - zeta),
        # the mass misplaced: right wherever m = 1 kg, wrong elsewhere
        escalate("the critical damping is 2√(k m), not 2√k: with ζ = c/(2√k) your damping "
                 "rate is c/√m where it should be γ = c/m", "γ = c/m, in 1/s; ζ = γ/(2ω)"):
            _se_limit(omega, c / np.sqrt(m)),
        escalate("the spring's frequency is ω² = k/m: you left the mass out of it",
                 "divide k by m"): _se_limit(np.sqrt(k), gamma),
        escalate("the mass is missing from both terms: γ = c/m and ω² = k/m",
                 "divide c and k by m"): _se_limit(np.sqrt(k), c),
        # the quadratic formula with a factor 2 lost (or doubled) in 2a or b
        escalate("every value is off by exactly a factor of 2: redo the quadratic formula",
                 "ω² dt² + 2γ dt - 4 = 0 has the root dt = (-2γ + √(4γ² + 16ω²)) / (2ω²): "
                 "the 2 of 2a and the 2 of b = 2γ are both needed"): 2.0 * _se_limit(omega, gamma),
        escalate("every value is off by exactly a factor of 2 (half the limit): redo the "
                 "quadratic formula", "ω² dt² + 2γ dt - 4 = 0 has the root dt = (-2γ + "
                 "√(4γ² + 16ω²)) / (2ω²): divide by 2a = 2ω², not 4ω²"):
            0.5 * _se_limit(omega, gamma),
    }


def _se_limit(omega: float, gamma: float) -> float:
    """Symplectic Euler's step limit (s) for the rates ``omega`` and ``gamma`` (1/s)."""
    return 4.0 / (gamma + np.sqrt(gamma**2 + 4.0 * omega**2))


@exercise(allow=(), forbid=("scipy.integrate",))
def damped_dt_max(ck: Checker, func) -> None:
    """``func(k, m, c)``: largest stable symplectic Euler step of a damped spring."""
    results = []
    for k, m, c in [(10.0, 1.0, 0.0), (10.0, 1.0, 2.0), (16.0, 1.0, 8.0), (50.0, 0.2, 0.3),
                    (4.0, 9.0, 40.0)]:
        measured = lesson.damped_dt_limit("symplectic_euler", k, m, c)
        what = f"k = {k:g} N/m, m = {m:g} kg, c = {c:g} N s/m (measured {measured:.6f} s)"
        ok, got = call_analysis(ck, what, FORMULA_LINES, (
            "the exercise asks for the limit as a formula, solved from the stability "
            "condition: your function searches for it step by step (a simulation or a "
            "bisection)"), func, k, m, c)
        if not ok:
            if "lines of Python" in ck.failed[-1]:
                break                   # a simulation: one case says it, the rest would repeat
            continue
        if blown_up(ck, got, what, run=False):
            continue
        if one_number(ck, what, got, "a step in s") is None:
            continue
        results.append((what, got, measured, _limit_mistakes(k, m, c)))
    # one mistake that explains every spring names it on all of them (2/ω and 4/γ agree at
    # critical damping, so a per-spring match alone would name two different mistakes)
    hint = consistent_hint([(got, exp, mis) for _, got, exp, mis in results])
    for what, got, measured, mistakes in results:
        close(ck, got, measured, what, rtol=precision_rtol(got, 1e-9), hint=hint,
              mistakes=None if hint else mistakes)


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
        same_way = np.zeros_like(x)                  # +f on both ends: no reaction
        np.add.at(same_way, i, f)
        np.add.at(same_way, j, f)
        f_anti = -(k * (length - rest) - c * rate)[:, None] * u
        anti_damped = np.zeros_like(x)               # the damping pushes with the stretching
        np.add.at(anti_damped, i, f_anti)
        np.add.at(anti_damped, j, -f_anti)
        _Indices.looped = False
        got = func(x.copy(), v.copy(), i.view(_Indices), j.view(_Indices), rest.copy(),
                   k.copy(), c.copy())
        if _Indices.looped:
            ck.expect(False, what, "your function loops over the springs one at a time",
                      hint=escalate("work on all springs at once: index the positions with the arrays "
                            "i and j", "d = x[i] - x[j] gives every spring's vector at once; the "
                            "forces then go onto the particles in one whole-array call"))
            continue
        if blown_up(ck, got, what, run=False):
            continue
        close(ck, got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12, mistakes={
            escalate("a particle that belongs to several springs got the force of only one "
                     "of them: F[i] += f does not add up repeated indices (NumPy buffers a "
                     "fancy-index update, so the last write wins)",
                     "NumPy has an unbuffered version of the add for this (np.add.at), and "
                     "np.bincount can sum per particle too"): buffered,
            escalate("each spring pushes both of its ends", "add f at i and -f at j"): only_i,
            escalate("each spring pushes its two ends in opposite directions (Newton's third "
                     "law, section 2): the force on particle j is minus the force on i",
                     "with that, the forces of every spring sum to zero, and so does the "
                     "total force: check the sum of your answer over the particles"): same_way,
            escalate("your damping pushes a stretching spring to stretch faster: the damping "
                     "force opposes the stretching rate (V_i - V_j)·u",
                     "the damping adds c times the rate to k(ℓ - L), with the same sign: both "
                     "pull the ends together while the spring stretches"): anti_damped,
            escalate("the damping must act along the spring only, on the stretching rate",
                     "project the relative velocity on u first: ((v_i - v_j)·u) u"): unprojected,
            escalate("you left out the damping", "add c times the stretching rate, along u"):
                no_damping,
            escalate("sign error: a stretched spring pulls i towards j",
                     "d = x_i - x_j points from j to i"): -expected,
        })
