"""The implementations course_lib is compared with: a naive Python loop (the way a student
first writes it) and a compiled numba loop (the speed a compiler reaches serially).

numba is never a course dependency: ``make bench`` installs it into its own environment
(``.venv-bench``). Without it, :data:`NUMBA` is ``None`` and the numba column is skipped.
"""

from __future__ import annotations

import numpy as np

try:  # pragma: no cover - depends on the benchmark environment
    import numba

    NUMBA = numba.__version__
except ImportError:  # pragma: no cover
    numba = None
    NUMBA = None


# --- naive Python loops -----------------------------------------------------------------


def naive_spring_step(x, v, i, j, rest, k, c, mass, g, dt):
    """One symplectic Euler step of damped springs + gravity, one spring at a time."""
    F = mass[:, None] * g
    for s in range(len(i)):
        a, b = i[s], j[s]
        d = x[a] - x[b]
        length = np.linalg.norm(d)
        u = d / length
        f = -(k[s] * (length - rest[s]) + c[s] * np.dot(v[a] - v[b], u)) * u
        F[a] += f
        F[b] -= f
    v += dt * F / mass[:, None]
    x += dt * v


def naive_nbody(x, mass, G, softening):
    """Softened gravity, one pair at a time."""
    F = np.zeros_like(x)
    for a in range(len(x)):
        for b in range(len(x)):
            if a != b:
                r = x[b] - x[a]
                F[a] += G * mass[a] * mass[b] * r / (r @ r + softening**2) ** 1.5
    return F


# --- numba ----------------------------------------------------------------------------------

_compiled: dict = {}


def _njit(func):
    if numba is None:
        return None
    if func.__name__ not in _compiled:
        _compiled[func.__name__] = numba.njit(cache=False)(func)
    return _compiled[func.__name__]


def _spring_step(x, v, i, j, rest, k, c, mass, g, dt, F):  # pragma: no cover - compiled
    n, dim = x.shape
    for p in range(n):
        for q in range(dim):
            F[p, q] = mass[p] * g[q]
    for s in range(i.shape[0]):
        a, b = i[s], j[s]
        dx = x[a, 0] - x[b, 0]
        dy = x[a, 1] - x[b, 1]
        dz = x[a, 2] - x[b, 2]
        length = np.sqrt(dx * dx + dy * dy + dz * dz)
        rate = (v[a, 0] - v[b, 0]) * dx + (v[a, 1] - v[b, 1]) * dy + (v[a, 2] - v[b, 2]) * dz
        coef = (k[s] * (length - rest[s]) + c[s] * rate / length) / length
        F[a, 0] -= coef * dx
        F[a, 1] -= coef * dy
        F[a, 2] -= coef * dz
        F[b, 0] += coef * dx
        F[b, 1] += coef * dy
        F[b, 2] += coef * dz
    for p in range(n):
        for q in range(dim):
            v[p, q] += dt * F[p, q] / mass[p]
            x[p, q] += dt * v[p, q]


def _nbody(x, mass, G, softening, F):  # pragma: no cover - compiled
    n = x.shape[0]
    eps2 = softening * softening
    F[:] = 0.0
    for a in range(n):               # each pair once (Newton's third law)
        for b in range(a + 1, n):
            dx = x[b, 0] - x[a, 0]
            dy = x[b, 1] - x[a, 1]
            dz = x[b, 2] - x[a, 2]
            r2 = dx * dx + dy * dy + dz * dz + eps2
            s = G * mass[a] * mass[b] / (r2 * np.sqrt(r2))
            F[a, 0] += s * dx
            F[a, 1] += s * dy
            F[a, 2] += s * dz
            F[b, 0] -= s * dx
            F[b, 1] -= s * dy
            F[b, 2] -= s * dz
    return F


def numba_spring_step():
    """The compiled spring step ``(x, v, i, j, rest, k, c, mass, g, dt, F)``, or None."""
    return _njit(_spring_step)


def numba_nbody():
    """The compiled N-body force ``(x, mass, G, softening, F)``, or None."""
    return _njit(_nbody)
