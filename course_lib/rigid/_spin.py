"""One body's torque-free step in plain Python floats: the fast path of ``free_body``.

The methods are those of :func:`course_lib.rigid.free.rotate` (see
:mod:`course_lib.rigid.free`), written out for a single body on 3- and 4-tuples of
floats: NumPy's per-call overhead (microseconds) dwarfs arithmetic on three numbers, and a
spin is a loop over time steps that cannot be vectorized. ``tests/test_rigid_core.py``
checks every method here against the vectorized version. Imports only :mod:`math`.
"""

from __future__ import annotations

import math

from ..integrators import BlowUpError

EPS = 2.220446049250313e-16


def cross(a, b):
    """``a × b`` of 3-tuples."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def qmul(p, q):
    """Hamilton product of 4-tuples (scalar first)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + qw * px + py * qz - pz * qy,
            pw * qy + qw * py + pz * qx - px * qz, pw * qz + qw * pz + px * qy - py * qx)


def qnormalize(q):
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def qrotate(q, r):
    """Rotate the 3-tuple ``r`` by the unit quaternion ``q``."""
    w, u = q[0], q[1:]
    t = cross(u, r)
    t = (2 * t[0], 2 * t[1], 2 * t[2])
    c = cross(u, t)
    return (r[0] + w * t[0] + c[0], r[1] + w * t[1] + c[1], r[2] + w * t[2] + c[2])


def cayley(q, omega, dt):
    """``normalize(q ⊗ (1, Δt Ω / 2))``: the renormalised quaternion step, body frame."""
    h = 0.5 * dt
    return qnormalize(qmul(q, (1.0, h * omega[0], h * omega[1], h * omega[2])))


def implicit_solve(L, Ib, dt, theta, tol_ulps, max_iter):
    """Newton's method for ``L1 = L + Δt Lθ × (Lθ / Ib)``, ``Lθ = (1−θ) L + θ L1``, as in
    :func:`course_lib.rigid.free.implicit_solve`."""
    g = cross(L, (L[0] / Ib[0], L[1] / Ib[1], L[2] / Ib[2]))
    L1 = [L[k] + dt * g[k] for k in range(3)]
    scale = tol_ulps * EPS * math.sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2])
    c = dt * theta
    for _ in range(max_iter):
        X = [(1.0 - theta) * L[k] + theta * L1[k] for k in range(3)]
        W = (X[0] / Ib[0], X[1] / Ib[1], X[2] / Ib[2])
        g = cross(X, W)
        r = [L1[k] - L[k] - dt * g[k] for k in range(3)]
        # Jacobian 1 − c (X̂ D − Ŵ), D = diag(1/Ib), solved by Cramer's rule.
        a = [[1.0, c * (X[2] / Ib[1] - W[2]), -c * (X[1] / Ib[2] - W[1])],
             [-c * (X[2] / Ib[0] - W[2]), 1.0, c * (X[0] / Ib[2] - W[0])],
             [c * (X[1] / Ib[0] - W[1]), -c * (X[0] / Ib[1] - W[0]), 1.0]]
        det = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
               - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
               + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))
        d = [0.0, 0.0, 0.0]
        for k in range(3):
            m = [row[:] for row in a]
            for i in range(3):
                m[i][k] = r[i]
            d[k] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) / det
        L1 = [L1[k] - d[k] for k in range(3)]
        if math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) <= scale:
            return tuple(L1)
    raise BlowUpError(f"Newton's method did not converge in {max_iter} iterations: "
                      f"the step dt = {dt:g} s is too long for this spin")


def _rk4(q, L, Ib, dt):
    def f(q, L):
        w = (L[0] / Ib[0], L[1] / Ib[1], L[2] / Ib[2])
        dq = qmul(q, (0.0, w[0], w[1], w[2]))
        return tuple(0.5 * x for x in dq), cross(L, w)

    def add(a, b, h):
        return tuple(x + h * y for x, y in zip(a, b, strict=True))

    k1 = f(q, L)
    k2 = f(add(q, k1[0], 0.5 * dt), add(L, k1[1], 0.5 * dt))
    k3 = f(add(q, k2[0], 0.5 * dt), add(L, k2[1], 0.5 * dt))
    k4 = f(add(q, k3[0], dt), add(L, k3[1], dt))
    q1 = tuple(q[i] + dt / 6.0 * (k1[0][i] + 2 * k2[0][i] + 2 * k3[0][i] + k4[0][i]) for i in range(4))
    L1 = tuple(L[i] + dt / 6.0 * (k1[1][i] + 2 * k2[1][i] + 2 * k3[1][i] + k4[1][i]) for i in range(3))
    return qnormalize(q1), L1


def step(q, L, Ib, dt, method, tol_ulps, max_iter):
    """One step of ``(q, L)`` (tuples) by ``method``; see :func:`course_lib.rigid.free.rotate`."""
    if method == "forward_euler":
        w = (L[0] / Ib[0], L[1] / Ib[1], L[2] / Ib[2])
        g = cross(L, w)
        return cayley(q, w, dt), (L[0] + dt * g[0], L[1] + dt * g[1], L[2] + dt * g[2])
    if method == "baraff_euler":
        h = 0.5 * dt
        turn = qnormalize((1.0, h * L[0] / Ib[0], h * L[1] / Ib[1], h * L[2] / Ib[2]))
        return qmul(q, turn), qrotate((turn[0], -turn[1], -turn[2], -turn[3]), L)
    if method == "rk4":
        return _rk4(q, L, Ib, dt)
    if method == "backward_euler":
        L1 = implicit_solve(L, Ib, dt, 1.0, tol_ulps, max_iter)
        return cayley(q, (L1[0] / Ib[0], L1[1] / Ib[1], L1[2] / Ib[2]), dt), L1
    if method == "implicit_midpoint":
        L1 = implicit_solve(L, Ib, dt, 0.5, tol_ulps, max_iter)
        w = tuple(0.5 * (L[k] + L1[k]) / Ib[k] for k in range(3))
        return cayley(q, w, dt), L1
    # splitting: exact rotations about the body axes 1, 2, 3, 2, 1
    for axis, h in ((0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)):
        half = 0.5 * h * dt * L[axis] / Ib[axis]
        turn = [math.cos(half), 0.0, 0.0, 0.0]
        turn[1 + axis] = math.sin(half)
        q = qmul(q, turn)
        L = qrotate((turn[0], -turn[1], -turn[2], -turn[3]), L)
    return q, L
