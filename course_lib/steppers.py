"""One-step methods for ``dy/dt = f(t, y)``: each advances a state by one step ``dt``.

The solvers know nothing of physics (the split of Baraff & Witkin's "Physically Based
Modeling" notes): a model supplies ``f(t, y)`` in the convention of
``scipy.integrate.solve_ivp``, with ``y`` an ndarray of any shape, and a method advances it.

==================  =====  ===========  ==========================================
name                order  f-evals      idea
==================  =====  ===========  ==========================================
forward_euler       1      1            slope at the start of the step
midpoint            2      2            slope at a half-step Euler prediction (RK2)
heun                2      2            average of start and predicted end slopes
rk4                 4      4            classical Runge-Kutta
backward_euler      1      Newton       slope at the (unknown) end of the step
trapezoidal         2      Newton       average of start and (unknown) end slopes
symplectic_euler    1      1            new velocity first, then position with it
velocity_verlet     2      2            half kick, drift, half kick
==================  =====  ===========  ==========================================

``symplectic_euler`` and ``velocity_verlet`` need a Newtonian state stacked along the
first axis, ``y = (x, v)`` with ``dx/dt = v`` (see :mod:`course_lib.systems`). Velocity
Verlet is second order for forces that depend on position (and time); a velocity-dependent
force (drag, damping) is evaluated at the half-step velocity, which makes that part first
order (notebook 06 measures it).

Two habits of fast right-hand sides are allowed: ``f`` may return the same preallocated
buffer every call, and it may modify its argument. So each method copies ``y`` before
its first call of ``f`` (that copy becomes the result) and uses every slope before the
next call. Imports: numpy and :mod:`course_lib.implicit` (core layer).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from . import _validate
from .implicit import Jacobian, NewtonSolver

RHS = Callable[[float, np.ndarray], np.ndarray]


def _forward_euler(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    out = y.copy()
    out += dt * f(t, y)
    return out


def _midpoint(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    out = y.copy()
    k = f(t + 0.5 * dt, out + (0.5 * dt) * f(t, y))
    out += dt * k
    return out


def _heun(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    y0 = y.copy()
    k1 = f(t, y)
    out = y0 + (0.5 * dt) * k1          # half the start slope, taken before f runs again
    k2 = f(t + dt, y0 + dt * k1)
    out += (0.5 * dt) * k2
    return out


def _rk4(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    # y + dt/6 (k1 + 2 k2 + 2 k3 + k4), summed as the slopes arrive.
    y0 = y.copy()
    k = f(t, y)
    out = y0 + (dt / 6.0) * k
    k = f(t + 0.5 * dt, y0 + (0.5 * dt) * k)
    out += (dt / 3.0) * k
    k = f(t + 0.5 * dt, y0 + (0.5 * dt) * k)
    out += (dt / 3.0) * k
    k = f(t + dt, y0 + dt * k)
    out += (dt / 6.0) * k
    return out


def _backward_euler(f: RHS, t: float, y: np.ndarray, dt: float,
                    newton: NewtonSolver | None = None) -> np.ndarray:
    # Start Newton at y: for a stiff f, an explicit predictor would be far worse.
    newton = NewtonSolver() if newton is None else newton
    return newton.solve(f, t + dt, y, dt, y)


def _trapezoidal(f: RHS, t: float, y: np.ndarray, dt: float,
                 newton: NewtonSolver | None = None) -> np.ndarray:
    newton = NewtonSolver() if newton is None else newton
    y0 = y.copy()
    c = y0 + (0.5 * dt) * f(t, y)
    return newton.solve(f, t + dt, c, 0.5 * dt, y0)


def _symplectic_euler(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    out = y.copy()                      # out = (x, v)
    out[1] += dt * f(t, y)[1]           # v_new = v + dt a(x, v)
    out[0] += dt * out[1]               # x_new = x + dt v_new
    return out


def _velocity_verlet(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    out = y.copy()
    out[1] += (0.5 * dt) * f(t, y)[1]   # half kick: v_half
    out[0] += dt * out[1]               # drift: x_new
    # Velocity-dependent forces (drag, damping) see the half-step velocity here.
    a_new = f(t + dt, out.copy())[1]
    out[1] += (0.5 * dt) * a_new
    return out


_STEPPERS: dict[str, Callable[..., np.ndarray]] = {
    "forward_euler": _forward_euler,
    "midpoint": _midpoint,
    "heun": _heun,
    "rk4": _rk4,
    "backward_euler": _backward_euler,
    "trapezoidal": _trapezoidal,
    "symplectic_euler": _symplectic_euler,
    "velocity_verlet": _velocity_verlet,
}

#: Every method name `integrate` accepts, in teaching order.
METHODS: tuple[str, ...] = tuple(_STEPPERS)
#: Methods that solve an equation for the end state each step.
IMPLICIT_METHODS: frozenset[str] = frozenset({"backward_euler", "trapezoidal"})
#: Methods that require the stacked Newtonian layout y = (x, v).
NEWTONIAN_METHODS: frozenset[str] = frozenset({"symplectic_euler", "velocity_verlet"})
#: Order of accuracy of each method (global error ~ dt**order).
ORDER: dict[str, int] = {
    "forward_euler": 1, "midpoint": 2, "heun": 2, "rk4": 4,
    "backward_euler": 1, "trapezoidal": 2, "symplectic_euler": 1, "velocity_verlet": 2,
}
#: Right-hand-side evaluations per step of the explicit methods.
EVALS_PER_STEP: dict[str, int] = {
    "forward_euler": 1, "midpoint": 2, "heun": 2, "rk4": 4,
    "symplectic_euler": 1, "velocity_verlet": 2,
}


class CheckedRHS:
    """``f`` wrapped so that every call is counted and its result checked.

    The result must be numeric, of the state's ``shape``, real when the state is real
    (``TypeError`` otherwise: pass a complex ``y0`` to integrate a complex system), and
    for a Newtonian method satisfy ``dx/dt = v`` exactly. ``converts`` records whether
    ``f`` returned something other than an ndarray (a list, a scalar).
    """

    def __init__(self, f: RHS, shape: tuple[int, ...], dtype: np.dtype, newtonian: str = ""):
        self.f, self.shape, self.dtype, self.newtonian = f, shape, dtype, newtonian
        self.calls = 0
        self.converts = False

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.calls += 1
        v = y[1].copy() if self.newtonian else None
        out = self.f(t, y)
        if type(out) is not np.ndarray:
            self.converts = True
            out = np.asarray(out)
        if out.dtype == object or not (np.issubdtype(out.dtype, np.number)
                                       or out.dtype == np.bool_):
            raise TypeError(f"f(t, y) must return numbers, got dtype {out.dtype}")
        if out.shape != self.shape:
            raise ValueError(f"f(t, y) must return an array of the state's shape {self.shape}, "
                             f"got shape {out.shape}")
        if np.iscomplexobj(out) and not np.iscomplexobj(np.empty(0, self.dtype)):
            raise TypeError("f(t, y) returned complex values for a real state; pass a complex "
                            "y0 (e.g. np.asarray(y0, dtype=complex)) to integrate a complex "
                            "system")
        if self.newtonian and not np.array_equal(out[0], v):
            raise ValueError(f"{self.newtonian} needs f(t, y)[0] == y[1] (dx/dt = v); this f is "
                             "not a Newtonian system. Use a general method such as 'midpoint' "
                             "or 'rk4' instead.")
        return out


def fast_rhs(f: RHS, checked: CheckedRHS) -> RHS:
    """``f`` for the steps after a checked first step: as is, or made to return an ndarray."""
    if not checked.converts:
        return f

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.asarray(f(t, y))

    return rhs


def get_stepper(method: str) -> Callable[..., np.ndarray]:
    """Return the raw one-step function ``(f, t, y, dt) -> y_next`` for ``method``.

    It does no checking, and it may hand ``y`` itself to ``f``. The implicit ones take a
    fifth argument, a :class:`~course_lib.implicit.NewtonSolver`.
    """
    return _STEPPERS[_validate.choice("method", method, _STEPPERS)]


def step(method: str, f: RHS, t: float, y, dt: float, jac: Jacobian | None = None) -> np.ndarray:
    """Advance ``y`` by one step of ``method``, with the same checks as ``integrate``.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    f : callable
        ``f(t, y) -> dy/dt``, returning an array of ``y``'s shape.
    t : float
        Current time (s).
    y : array_like
        Current state, any shape (not modified).
    dt : float
        Step size (s), finite and > 0.
    jac : callable, ndarray or scipy.sparse matrix, optional
        ``df/dy`` for the implicit methods, see :class:`~course_lib.implicit.NewtonSolver`.

    Returns
    -------
    ndarray
        The state at ``t + dt``, a new array of ``y``'s shape.
    """
    stepper = get_stepper(method)
    f = _validate.callable_arg("f", f)
    t = _validate.finite_real("t", t)
    dt = _validate.positive_finite("dt", dt)
    y = _validate.state_array("y", y)            # our own copy: f may modify it
    _validate.method_options(method, y, "y", jac, IMPLICIT_METHODS, NEWTONIAN_METHODS)
    rhs = CheckedRHS(f, y.shape, y.dtype, method if method in NEWTONIAN_METHODS else "")
    if method in IMPLICIT_METHODS:
        return stepper(rhs, t, y, dt, NewtonSolver(jac))
    return stepper(rhs, t, y, dt)


def _public(name: str, doc: str) -> Callable[..., np.ndarray]:
    def stepper(f: RHS, t: float, y, dt: float, **kwargs) -> np.ndarray:
        return step(name, f, t, y, dt, **kwargs)

    stepper.__name__ = stepper.__qualname__ = name
    stepper.__doc__ = doc + "\n\nSignature ``(f, t, y, dt) -> y_next``; see :func:`step`."
    return stepper


forward_euler = _public("forward_euler", "Forward Euler: ``y + dt f(t, y)``.")
midpoint = _public(
    "midpoint", "Explicit midpoint (RK2): slope at ``y + dt/2 f(t, y)``, time ``t + dt/2``."
)
heun = _public("heun", "Heun's method: mean of the slopes at the start and predicted end.")
rk4 = _public("rk4", "Classical fourth-order Runge-Kutta.")
backward_euler = _public(
    "backward_euler", "Backward Euler: solves ``Y = y + dt f(t + dt, Y)`` by Newton."
)
trapezoidal = _public(
    "trapezoidal",
    "Implicit trapezoid: solves ``Y = y + dt/2 (f(t, y) + f(t + dt, Y))`` by Newton.",
)
symplectic_euler = _public(
    "symplectic_euler",
    "Symplectic Euler on ``y = (x, v)``: ``v += dt a(x, v)``, then ``x += dt v_new``.",
)
velocity_verlet = _public(
    "velocity_verlet",
    "Velocity Verlet on ``y = (x, v)``: half kick, drift, half kick with the new force.",
)
