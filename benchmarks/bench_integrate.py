"""Per-step overhead of ``integrate`` on a 2-vector, against a plain NumPy loop calling the
same ``f``: what the driver's checks and bookkeeping cost when ``f`` itself is cheap."""

from __future__ import annotations

import numpy as np

import course_lib as cl
from benchmarks.timing import Row, check_equal, interleaved

DT = 0.01


def f(t, y):
    """The unit oscillator ``x'' = -x`` with ``y = (x, v)``."""
    return np.array([y[1], -y[0]])


def plain_forward_euler(y0, n):
    out = np.empty((n + 1, 2))
    out[0] = y = y0
    for k in range(n):
        y = y + DT * f(k * DT, y)
        out[k + 1] = y
    return out


def plain_symplectic_euler(y0, n):
    out = np.empty((n + 1, 2))
    out[0] = y = y0
    for k in range(n):
        a = f(k * DT, y)[1]
        v = y[1] + DT * a
        y = np.array([y[0] + DT * v, v])
        out[k + 1] = y
    return out


def run(quick: bool = False) -> list[Row]:
    n, rounds = (50, 2) if quick else (2000, 15)
    y0 = np.array([1.0, 0.0])
    rows = []
    for method, plain, target in (("forward_euler", plain_forward_euler, 1.5),
                                  ("symplectic_euler", plain_symplectic_euler, 2.0)):
        impls = {"course_lib": lambda m=method: cl.integrate(f, y0, (0.0, n * DT), DT, m).y,
                 "plain": lambda p=plain: p(y0, n)}
        check_equal({k: g() for k, g in impls.items()}, "course_lib")
        t = interleaved(impls, rounds=rounds)
        ratio = t.ratio("course_lib", "plain")
        rows.append(Row(f"integrate per-step overhead, {method}, 2-vector ({n} steps)",
                        t.median["course_lib"] / n, f"≤ {target:g}× plain NumPy loop",
                        ratio <= target, t.median["plain"] / n, None,
                        f"{ratio:.2f}× plain loop (per step)"))
    return rows
