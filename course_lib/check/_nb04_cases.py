"""Case data of notebook 04's check of backward Euler on a linear system (``nb04.backward_euler_linear``).

:data:`LINEAR_CASES` holds the systems the check runs (a decay, a damped spring given with
integer x0, a coupled stiff pair, the vortex, no step), :func:`backward_euler_linear_reference`
and :func:`linear_newton` its two references (a solve per step, and course_lib's Newton
solver), and :func:`linear_mistakes` what the usual mistakes make of a run, keyed by hint.
For the implicit midpoint rule (``nb04.implicit_midpoint_step``): the fields
(:func:`pulsing_vortex`, :func:`swirl`), the cases (:data:`MIDPOINT_RULE_CASES`), two
independent solves (:func:`implicit_midpoint_reference`, and the trapezoid's), the usual
mistakes (:func:`midpoint_rule_mistakes`) and the hint for a state of one axis only
(:func:`shape_hint`).
Imports NumPy, SciPy's root finder and :func:`course_lib.integrate`.
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import integrate
from .tolerance import escalate

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


# The three linear-algebra mistakes escalate to the same worked scalar case,
# dx/dt = a x with a = -1 and dt = 0.5, where backward Euler gives x1 = x0/1.5.
_SIGN = escalate(
    "sign: x_next = x + dt A x_next gives (I - dt A) x_next = x, not (I + dt A)",
    "a worked case, the scalar decay a = -1, dt = 0.5: backward Euler gives x1 = x0/(1 - dt a) "
    "= x0/(1 + 0.5) = 0.667 x0, while solving (I + dt A) x1 = x0 gives x0/(1 - 0.5) = 2 x0, "
    "a decay that grows. Move dt A x_next to the left: x_next - dt A x_next = x")
_FORWARD = escalate(
    "(I + dt A) x is FORWARD Euler: backward Euler takes the slope at the unknown end, "
    "x_next = x + dt A x_next",
    "a worked case, the scalar decay a = -1, dt = 0.5: forward Euler gives (1 + dt a) x0 = "
    "0.5 x0, backward Euler x0/(1 - dt a) = x0/(1 + 0.5) = 0.667 x0. Backward Euler divides: "
    "each step solves (I - dt A) x_next = x")
_MULTIPLIED = escalate(
    "you multiplied by (I - dt A); the unknown is x_next in (I - dt A) x_next = x: SOLVE "
    "that system (np.linalg.solve)",
    "a worked case, the scalar decay a = -1, dt = 0.5: multiplying gives (1 + 0.5) x0 = "
    "1.5 x0, a decay that grows; backward Euler divides, x1 = x0/(1 + 0.5) = 0.667 x0, which "
    "for a matrix is np.linalg.solve(I - dt A, x)")


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
            _FORWARD: run(lambda x: x + dt * A @ x),
            _MULTIPLIED: run(lambda x: (eye - dt * A) @ x),
            _SIGN: run(lambda x: np.linalg.solve(eye + dt * A, x)),
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


# --- the implicit midpoint rule (nb04.implicit_midpoint_step) -------------------------------

FROZEN_T = (
    "pass the step's time to f: this field changes with time, and you evaluated it as if "
    "the step started at t = 0"
)


def pulsing_vortex(t, X):
    """The vortex ``V = ω(t) (-y, x)`` whose rate ``ω(t) = 1 + cos(t)/2`` pulses in time.

    Exact solution from ``(r, φ0)``: radius ``r``, angle ``φ0 + t + sin(t)/2``.
    """
    return (1.0 + 0.5 * np.cos(t)) * fields.vortex(t, X)


def swirl(t, X):
    """A nonlinear vortex, ``V = (1 + x) (-y, x)``: ``|X|`` is invariant, the speed is not."""
    X = np.asarray(X, dtype=float)
    return (1.0 + X[..., :1]) * np.stack((-X[..., 1], X[..., 0]), axis=-1)


def _pendulum(t, y):
    return np.array([y[1], -np.sin(y[0])])


def _stiff(t, y):
    return -50.0 * y


#: (description, f, t, y, dt, keeps |y|).
MIDPOINT_RULE_CASES = [
    ("the swirl V = (1 + x)(-y, x) from (1, 0.5), dt = 0.4", swirl, 0.0, [1.0, 0.5], 0.4, True),
    ("a pendulum θ'' = -sin θ from (2, 0), dt = 0.3", _pendulum, 0.0, [2.0, 0.0], 0.3, False),
    ("the pulsing vortex at t = 0.7, dt = 0.4 (time-dependent)", pulsing_vortex, 0.7,
     [0.8, -0.6], 0.4, True),
    ("5 particles in the swirl, y of shape (5, 2), dt = 0.2", swirl, 0.0,
     [[0.3, 0.1], [0.5, -0.4], [-0.2, 0.6], [0.1, 0.1], [-0.5, -0.3]], 0.2, False),
    ("a stiff decay dy/dt = -50 y, dt = 0.5 (dt |∂f/∂y| / 2 = 12.5)", _stiff, 0.0, [1.0], 0.5,
     False),
]


def implicit_midpoint_reference(f, t, y, dt):
    """``Y = y + dt f(t + dt/2, (y + Y)/2)``, solved by ``scipy.optimize.root`` to 1e-14."""
    from scipy.optimize import root

    y = np.asarray(y, dtype=float)

    def residual(flat):
        Y = flat.reshape(y.shape)
        return (Y - y - dt * f(t + 0.5 * dt, 0.5 * (y + Y))).ravel()

    guess = (y + dt * f(t, y)).ravel()
    sol = root(residual, guess, tol=1e-14)
    return sol.x.reshape(y.shape)


def midpoint_rule_mistakes(f, t, y, dt) -> dict:
    """What the usual mistakes make of one implicit midpoint step, keyed by hint."""
    mid = y + 0.5 * dt * f(t, y)
    with np.errstate(all="ignore"):
        return {
            "that is the trapezoid: the implicit midpoint evaluates f once, at the average "
            "state (y + Y)/2 and time t + dt/2": _trapezoid_reference(f, t, y, dt),
            "that is the EXPLICIT midpoint: here the midpoint state is (y + Y)/2, with the "
            "unknown end Y; solve for Y": y + dt * f(t + 0.5 * dt, mid),
            **_explicit_mistakes(f, t, y, dt),
            "evaluate f at the middle of the step, time t + dt/2, not at t":
                implicit_midpoint_reference(lambda s, u, f=f, t=t: f(t, u), t, y, dt),
            FROZEN_T: implicit_midpoint_reference(lambda s, u, f=f, t=t: f(s - t, u), t, y, dt),
        }


def _explicit_mistakes(f, t, y, dt) -> dict:
    """What explicit steps make of one implicit midpoint step, keyed by hint."""
    k1 = f(t, y)
    return {
        "that is forward Euler, y + dt f(t, y): the implicit midpoint takes its slope at the "
        "average state (y + Y)/2, with the unknown end Y; solve for Y": y + dt * k1,
        "that is Heun's explicit method: the implicit midpoint takes ONE slope, at the "
        "average state (y + Y)/2 with the unknown end Y; solve for Y":
            y + 0.5 * dt * (k1 + f(t + dt, y + dt * k1)),
    }


def shape_hint(y: np.ndarray) -> str | None:
    """The hint for an answer that handles a state of one axis only, when ``y`` has more."""
    if y.ndim < 2:
        return None
    return (f"y may have any shape, here {y.shape}: do the Newton solve on the flattened state "
            "(y.ravel(), a Jacobian of size y.size × y.size) and reshape Y back to y's shape")


def _trapezoid_reference(f, t, y, dt):
    from scipy.optimize import root

    f0 = f(t, y)

    def residual(flat):
        Y = flat.reshape(y.shape)
        return (Y - y - 0.5 * dt * (f0 + f(t + dt, Y))).ravel()

    return root(residual, (y + dt * f0).ravel(), tol=1e-14).x.reshape(y.shape)
