"""Case data of notebook 04's check of backward Euler on a linear system (``nb04.backward_euler_linear``).

:data:`LINEAR_CASES` holds the systems the check runs (a decay, a damped spring given with
integer x0, a coupled stiff pair, the vortex, no step), :func:`backward_euler_linear_reference`
and :func:`linear_newton` its two references (a solve per step, and course_lib's Newton
solver), and :func:`linear_mistakes` what the usual mistakes make of a run, keyed by hint.
Imports NumPy and :func:`course_lib.integrate`.
"""

from __future__ import annotations

import numpy as np

from ..integrators import integrate

_J = np.array([[0.0, -1.0], [1.0, 0.0]])

#: (description, A (1/s), x0, dt (s), n): a decay, a damped spring, a stiff pair that is
#: not diagonal, the vortex, and no step at all. x0 of the spring is given as integers.
LINEAR_CASES = [
    ("one decay dx/dt = -x (A = [[-1]]), dt = 0.1 s, n = 10", [[-1.0]], [1.0], 0.1, 10),
    ("a damped spring x'' = -4x - x', A = [[0, 1], [-4, -1]], x0 = [1, 0], dt = 0.25 s, n = 12",
     [[0.0, 1.0], [-4.0, -1.0]], [1, 0], 0.25, 12),
    ("stiff: a fast decay feeding a slow one, A = [[-100, 0], [50, -1]], dt = 0.1 s "
     "(k dt = 10), n = 5", [[-100.0, 0.0], [50.0, -1.0]], [1.0, 2.0], 0.1, 5),
    ("the vortex A = [[0, -1], [1, 0]] from (0, 1), dt = 0.5 s, n = 4", _J, [0.0, 1.0], 0.5, 4),
    ("no step: n = 0", [[0.0, 1.0], [-4.0, -1.0]], [3.0, 0.0], 0.5, 0),
]


def backward_euler_linear_reference(A, x0, dt: float, n: int) -> np.ndarray:
    """``[x_0, ..., x_n]``, shape ``(n + 1, d)``: ``(I - dt A) x_{k+1} = x_k``, solved each step."""
    A, x = np.asarray(A, dtype=float), np.asarray(x0, dtype=float)
    M = np.eye(len(x)) - dt * A
    out = [x]
    for _ in range(n):
        out.append(np.linalg.solve(M, out[-1]))
    return np.array(out)


def linear_newton(A, x0, dt: float, n: int) -> np.ndarray:
    """The same run by course_lib's general implicit solver (Newton's method)."""
    A, x0 = np.asarray(A, dtype=float), np.asarray(x0, dtype=float)
    if n == 0:
        return x0[None, :]
    return integrate(lambda t, x: A @ x, x0, (0.0, n * dt), dt, method="backward_euler").y


def linear_mistakes(A, x0, dt, n) -> dict:
    A, x0 = np.asarray(A, dtype=float), np.asarray(x0, dtype=float)
    eye = np.eye(len(x0))

    def run(step):
        out = [x0]
        try:
            for _ in range(n):
                out.append(step(out[-1]))
        except np.linalg.LinAlgError:  # this mistake cannot even be made on this case
            return np.full((n + 1, len(x0)), np.nan)
        return np.array(out)

    with np.errstate(all="ignore"):
        diag = 1.0 - dt * np.diag(A)
        return {
            "(I + dt A) x is FORWARD Euler: backward Euler takes the slope at the unknown end, "
            "x_next = x + dt A x_next": run(lambda x: x + dt * A @ x),
            ("you multiplied by (I - dt A); the unknown is x_next in (I - dt A) x_next = x: "
             "SOLVE that system (np.linalg.solve)"): run(lambda x: (eye - dt * A) @ x),
            "sign: x_next = x + dt A x_next gives (I - dt A) x_next = x, not (I + dt A)":
                run(lambda x: np.linalg.solve(eye + dt * A, x)),
            ("that is the exact solution e^(A t) x0 (scipy.linalg.expm), not what backward "
             "Euler computes"): np.array([_expm(A * dt * k) @ x0 for k in range(n + 1)]),
            ("1 - dt A subtracts dt A from 1 in every entry: the matrix is I - dt A, with "
             "np.eye(d)"): run(lambda x: np.linalg.solve(1.0 - dt * A, x)),
            ("solve with the matrix on the left: (I - dt A) x_next = x is "
             "np.linalg.solve(I - dt A, x), not x @ inv(I - dt A)"):
                run(lambda x: np.linalg.solve((eye - dt * A).T, x)),
            ("dividing by 1 - dt A_ii works only when A is diagonal: the components are "
             "coupled, so solve the whole system"): run(lambda x: x / diag),
            ("your states were rounded to whole numbers: an array made like x0 = [1, 0] "
             "(integers) holds integers; build a float array"):
                run(lambda x: np.trunc(np.linalg.solve(eye - dt * A, x))),
        }


def _expm(M) -> np.ndarray:
    w, V = np.linalg.eig(np.asarray(M, dtype=complex))
    return (V @ np.diag(np.exp(w)) @ np.linalg.inv(V)).real
