"""The damped harmonic oscillator: critical damping and the exact solution.

``m x'' + c x' + k x = 0`` is what one spring does along its length; its exact solution is
the reference every integrator in notebook 07 is measured against.

Core module: imports NumPy and :mod:`course_lib._validate` only.
"""

from __future__ import annotations

import numpy as np

from .. import _validate


def critical_damping(k: float, m: float) -> float:
    """Damping ``c = 2 √(k m)`` (N s/m) at which a mass ``m`` (kg) on a spring ``k`` (N/m)
    returns to rest fastest without oscillating."""
    return float(2.0 * np.sqrt(_validate.positive_finite("k", k) * _validate.positive_finite("m", m)))


def damped_oscillator(t, k: float, m: float, c: float = 0.0, x0: float = 1.0, v0: float = 0.0,
                      velocity: bool = False):
    """Exact displacement ``x(t)`` (m) (or velocity, m/s, with ``velocity=True``) of
    ``m x'' + c x' + k x = 0`` with ``x(0) = x0``, ``x'(0) = v0``; ``t`` in s, any shape.

    Under-damped (``c < 2√(km)``) it oscillates inside a decaying envelope, critically
    damped it is ``(x0 + (v0 + ω x0) t) e^{-ω t}`` with ``ω = √(k/m)``, over-damped it
    is a sum of two decaying exponentials.
    """
    t = _validate.real_array("t", t)
    k, m = _validate.positive_finite("k", k), _validate.positive_finite("m", m)
    c = _validate.nonnegative("c", c)
    x0, v0 = _validate.finite_real("x0", x0), _validate.finite_real("v0", v0)
    omega = np.sqrt(k / m)
    zeta = c / (2.0 * np.sqrt(k * m))
    if np.isclose(zeta, 1.0, rtol=1e-12, atol=0.0):
        b = v0 + omega * x0
        if velocity:
            return (b - omega * (x0 + b * t)) * np.exp(-omega * t)
        return (x0 + b * t) * np.exp(-omega * t)
    root = np.sqrt(complex(zeta**2 - 1.0))
    r1, r2 = omega * (-zeta + root), omega * (-zeta - root)
    a = (v0 - r2 * x0) / (r1 - r2)
    if velocity:
        return np.real(a * r1 * np.exp(r1 * t) + (x0 - a) * r2 * np.exp(r2 * t))
    return np.real(a * np.exp(r1 * t) + (x0 - a) * np.exp(r2 * t))
