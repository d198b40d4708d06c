"""Checks for notebook 07, springs and mass-spring systems."""

from __future__ import annotations

import functools

import numpy as np

from .. import springs
from ..lessons import nb07_springs
from . import Checker, exercise

_RNG_SEED = 707
_measured_dt_max = functools.lru_cache(maxsize=8)(nb07_springs.spring_dt_max)


def _cases():
    rng = np.random.default_rng(_RNG_SEED)
    for _ in range(4):
        x1, x2 = rng.normal(size=3), rng.normal(size=3)
        yield x1, x2, float(rng.uniform(5.0, 50.0)), float(rng.uniform(0.3, 1.5))


@exercise
def spring_force(ck: Checker, func) -> None:
    """``func(x1, x2, k, rest)``: Hooke force on particle 1 of a spring in 3D."""
    for n, (x1, x2, k, rest) in enumerate(_cases()):
        expected = springs.spring_force_pair(x1, x2, k, rest)
        d = x1 - x2
        length = np.linalg.norm(d)
        u = d / length
        got = np.asarray(func(x1.copy(), x2.copy(), k, rest), dtype=float)
        ck.close(got, expected, f"case {n}: force on particle 1", rtol=1e-9, atol=1e-12, mistakes={
            "sign error: the force on particle 1 points from x1 towards x2 when the spring is "
            "stretched, F1 = -k (|d| - L) d/|d| with d = x1 - x2": -expected,
            "forgot to normalise: multiply by the unit vector d/|d|, not by d itself":
                -k * (length - rest) * d,
            "used the rest length L instead of the stretch |d| - L": -k * rest * u,
            "used the length |d| instead of the stretch |d| - L": -k * length * u,
        })
    # Force = -gradient of the spring energy, by central finite differences.
    x1, x2, k, rest = next(_cases())

    def energy(p):
        return 0.5 * k * (np.linalg.norm(p - x2) - rest) ** 2

    h = 1e-6
    grad = np.array([(energy(x1 + h * e) - energy(x1 - h * e)) / (2 * h) for e in np.eye(3)])
    got = np.asarray(func(x1.copy(), x2.copy(), k, rest), dtype=float)
    ck.close(got, -grad, "F1 = -∂E/∂x1 (finite differences of E = ½ k (|x1 - x2| - L)²)",
             rtol=1e-6, atol=1e-8)
    f1 = np.asarray(func(x1.copy(), x2.copy(), k, rest), dtype=float)
    f2 = np.asarray(func(x2.copy(), x1.copy(), k, rest), dtype=float)
    ck.close(f1 + f2, np.zeros(3), "momentum: F1 + F2 = 0", atol=1e-12,
             hint="swap the arguments: the force on particle 2 must be exactly -F1")
    ck.close(np.cross(x1, f1) + np.cross(x2, f2), np.zeros(3),
             "angular momentum: x1 × F1 + x2 × F2 = 0", atol=1e-10,
             hint="the force must act along the line x1 - x2")


@exercise
def predict_dt_max(ck: Checker, func) -> None:
    """``func(k, m)``: largest stable symplectic Euler step for a mass on a spring."""
    for k, m in [(1.0, 1.0), (16.0, 1.0), (50.0, 0.2), (4.0, 9.0)]:
        exact = 2.0 * np.sqrt(m / k)
        ck.close(func(k, m), exact, f"k = {k:g} N/m, m = {m:g} kg", rtol=1e-9, mistakes={
            "missing factor 2: symplectic Euler is stable for ω dt <= 2, so dt_max = 2/ω": np.sqrt(m / k),
            "inverted: ω = √(k/m), and dt_max = 2/ω = 2 √(m/k)": 2.0 * np.sqrt(k / m),
            "you returned 2/ω²; the limit is 2/ω with ω = √(k/m)": 2.0 * m / k,
        })
    measured = _measured_dt_max(16.0, 1.0)
    ck.close(func(16.0, 1.0), measured, f"agrees with the step measured by bisection ({measured:.5f} s)",
             rtol=1e-2)


@exercise
def critical_damping(ck: Checker, func) -> None:
    """``func(k, m)``: the critical damping coefficient of a mass on a spring."""
    for k, m in [(10.0, 1.0), (100.0, 0.5), (2.0, 8.0)]:
        ck.close(func(k, m), springs.critical_damping(k, m), f"k = {k:g} N/m, m = {m:g} kg",
                 rtol=1e-9, mistakes={
                     "missing factor 2: c = 2 √(k m)": np.sqrt(k * m),
                     "that is 2ω = 2 √(k/m) (units 1/s); c has units N s/m = kg/s: c = 2 m ω":
                         2 * np.sqrt(k / m),
                 })
