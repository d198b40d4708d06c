"""Time integrators for ``dy/dt = f(t, y)``, and a driver that runs them.

The solvers know nothing of physics (the split of Baraff & Witkin's "Physically Based
Modeling" notes): a model supplies ``f(t, y)`` in the convention of
``scipy.integrate.solve_ivp``, with ``y`` an ndarray of any shape, and a solver advances
it. Each method is a one-step function ``step(f, t, y, dt) -> y_next``:

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
first axis, ``y = (x, v)`` with ``dx/dt = v`` (see :mod:`course_lib.systems`).
Velocity Verlet is second order for forces that depend on position (and time); a
velocity-dependent force (drag, damping) is evaluated at the half-step velocity, which makes
that part first order (notebook 06 measures it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import _validate
from .implicit import Jacobian, solve_implicit

RHS = Callable[[float, np.ndarray], np.ndarray]


# --- one-step methods -------------------------------------------------------------------
# The raw steppers below do no checking: `integrate` validates once and then calls them
# in its loop. The public names (exported at the bottom) validate their arguments.


def _forward_euler(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    return y + dt * f(t, y)


def _midpoint(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    y_mid = y + 0.5 * dt * f(t, y)
    return y + dt * f(t + 0.5 * dt, y_mid)


def _heun(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    k1 = f(t, y)
    k2 = f(t + dt, y + dt * k1)
    return y + 0.5 * dt * (k1 + k2)


def _rk4(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    k1 = f(t, y)
    k2 = f(t + 0.5 * dt, y + 0.5 * dt * k1)
    k3 = f(t + 0.5 * dt, y + 0.5 * dt * k2)
    k4 = f(t + dt, y + dt * k3)
    return y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _backward_euler(
    f: RHS, t: float, y: np.ndarray, dt: float, jac: Jacobian | None = None
) -> np.ndarray:
    guess = y + dt * f(t, y)
    return solve_implicit(f, t + dt, y, dt, guess, jac)


def _trapezoidal(
    f: RHS, t: float, y: np.ndarray, dt: float, jac: Jacobian | None = None
) -> np.ndarray:
    f0 = f(t, y)
    return solve_implicit(f, t + dt, y + 0.5 * dt * f0, 0.5 * dt, y + dt * f0, jac)


def _newtonian_parts(name: str, f: RHS, t: float, y: np.ndarray):
    """Evaluate ``f`` on a stacked ``(x, v)`` state and check that ``dx/dt = v``."""
    if y.ndim < 1 or y.shape[0] != 2:
        raise ValueError(
            f"{name} needs a Newtonian state y = (x, v) stacked along axis 0, i.e. "
            f"y.shape[0] == 2; got y of shape {y.shape}. Build one with "
            "course_lib.systems.stack_state(x, v)."
        )
    dydt = f(t, y)
    if not np.array_equal(dydt[0], y[1]):
        raise ValueError(
            f"{name} needs f(t, y)[0] == y[1] (dx/dt = v); this f is not a Newtonian "
            "system. Use a general method such as 'midpoint' or 'rk4' instead."
        )
    return y[0], y[1], dydt[1]


def _symplectic_euler(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    x, v, a = _newtonian_parts("symplectic_euler", f, t, y)
    v_new = v + dt * a
    x_new = x + dt * v_new
    return np.stack((x_new, v_new))


def _velocity_verlet(f: RHS, t: float, y: np.ndarray, dt: float) -> np.ndarray:
    x, v, a = _newtonian_parts("velocity_verlet", f, t, y)
    v_half = v + 0.5 * dt * a
    x_new = x + dt * v_half
    # Velocity-dependent forces (drag, damping) see the half-step velocity here.
    a_new = f(t + dt, np.stack((x_new, v_half)))[1]
    return np.stack((x_new, v_half + 0.5 * dt * a_new))


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
    "forward_euler": 1,
    "midpoint": 2,
    "heun": 2,
    "rk4": 4,
    "backward_euler": 1,
    "trapezoidal": 2,
    "symplectic_euler": 1,
    "velocity_verlet": 2,
}
#: Right-hand-side evaluations per step of the explicit methods.
EVALS_PER_STEP: dict[str, int] = {
    "forward_euler": 1,
    "midpoint": 2,
    "heun": 2,
    "rk4": 4,
    "symplectic_euler": 1,
    "velocity_verlet": 2,
}


def _checked_rhs(f: RHS, shape: tuple[int, ...], counter: list[int]) -> RHS:
    """Wrap ``f`` so that every call is counted and must return an array of ``shape``."""

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        counter[0] += 1
        out = np.asarray(f(t, y))
        if out.shape != shape:
            raise ValueError(
                f"f(t, y) must return an array of the state's shape {shape}, "
                f"got shape {out.shape}"
            )
        return out

    return rhs


def get_stepper(method: str) -> Callable[..., np.ndarray]:
    """Return the one-step function ``(f, t, y, dt) -> y_next`` for ``method``."""
    return _STEPPERS[_validate.choice("method", method, _STEPPERS)]


def step(method: str, f: RHS, t: float, y, dt: float, jac: Jacobian | None = None) -> np.ndarray:
    """Advance ``y`` by one step of ``method``, with the same checks as :func:`integrate`.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`.
    f : callable
        ``f(t, y) -> dy/dt``, returning an array of ``y``'s shape.
    t : float
        Current time (s).
    y : array_like
        Current state, any shape.
    dt : float
        Step size (s), finite and > 0.
    jac : callable, optional
        ``jac(t, y)``, the Jacobian of ``f`` for the implicit methods.

    Returns
    -------
    ndarray
        The state at ``t + dt``.
    """
    stepper = get_stepper(method)
    f = _validate.callable_arg("f", f)
    t = _validate.finite_real("t", t)
    dt = _validate.positive_finite("dt", dt)
    y = _validate.state_array("y", y)
    rhs = _checked_rhs(f, y.shape, [0])
    if method in IMPLICIT_METHODS:
        return stepper(rhs, t, y, dt, jac)
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


# --- the driver ---------------------------------------------------------------------------


class BlowUpError(RuntimeError):
    """Raised by :func:`integrate` with ``on_blowup="raise"`` when a run goes unstable."""


@dataclass
class Trajectory:
    """The result of :func:`integrate`.

    Attributes
    ----------
    t : ndarray, shape (n+1,)
        Times (s), ``t0 + k dt``.
    y : ndarray, shape (n+1, *y0.shape)
        States; after a blow-up the remaining rows are NaN.
    method : str
        The method used.
    dt : float
        The step (s).
    nfev : int
        Number of right-hand-side evaluations (including those of Newton iterations).
    status : str
        ``"ok"`` or ``"unstable"``.
    blowup_step : int or None
        Index of the first step whose state was non-finite or exceeded the bound.
    message : str
        A one-line verdict, e.g. ``"unstable at step 12, t = 24 (|y| > 1e+06)"``.
    """

    t: np.ndarray
    y: np.ndarray
    method: str
    dt: float
    nfev: int = 0
    status: str = "ok"
    blowup_step: int | None = None
    message: str = "ok"

    @property
    def stable(self) -> bool:
        """True when the run finished without blowing up."""
        return self.status == "ok"

    @property
    def n_steps(self) -> int:
        return len(self.t) - 1

    @property
    def last_valid(self) -> int:
        """Index of the last finite state."""
        return self.n_steps if self.blowup_step is None else self.blowup_step - 1

    def __repr__(self) -> str:
        return (
            f"Trajectory(method={self.method!r}, dt={self.dt:g}, steps={self.n_steps}, "
            f"y.shape={self.y.shape}, nfev={self.nfev}, status={self.message!r})"
        )


def integrate(
    f: RHS,
    y0,
    t_span: tuple[float, float],
    dt: float,
    method: str = "forward_euler",
    *,
    jac: Jacobian | None = None,
    blowup_bound: float | None = None,
    on_blowup: str = "stop",
    post_step: Callable[[float, np.ndarray], np.ndarray] | None = None,
) -> Trajectory:
    """Integrate ``dy/dt = f(t, y)`` from ``t_span[0]`` with a fixed step.

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` (``scipy.integrate.solve_ivp`` convention); must return an
        array of ``y``'s shape.
    y0 : array_like
        Initial state, any shape; finite. Newtonian systems stack ``(x, v)`` on axis 0.
    t_span : (float, float)
        Start and end time (s), ``t1 > t0``.
    dt : float
        Step (s), finite and > 0. The run takes ``n = round((t1 - t0) / dt)`` steps.
    method : str
        One of :data:`METHODS`.
    jac : callable, optional
        ``jac(t, y) -> (y.size, y.size)`` Jacobian of ``f``, used by implicit methods.
    blowup_bound : float, optional
        The run counts as blown up when ``max|y|`` exceeds this, or turns non-finite.
        Default ``1e6 * max(1, max|y0|)``.
    on_blowup : {"stop", "raise"}
        ``"stop"`` ends the run, fills the remaining rows with NaN and records the step in
        ``status``/``message``; ``"raise"`` raises :class:`BlowUpError`.
    post_step : callable, optional
        ``post_step(t, y) -> y`` applied after every step, e.g. to resolve collisions or
        enforce pins (a projection, not part of ``f``).

    Returns
    -------
    Trajectory
        With ``.t`` of shape ``(n+1,)`` and ``.y`` of shape ``(n+1, *y0.shape)``.

    Examples
    --------
    >>> from course_lib import integrate, fields
    >>> traj = integrate(fields.vortex, [0.0, 1.0], (0.0, 1.5), 0.5)
    >>> traj.y[-1]
    array([-1.375,  0.25 ])
    """
    f = _validate.callable_arg("f", f)
    stepper = get_stepper(method)
    y0 = _validate.state_array("y0", y0)
    dt = _validate.positive_finite("dt", dt)
    if not isinstance(t_span, tuple | list | np.ndarray) or len(t_span) != 2:
        raise TypeError(f"t_span must be a pair (t0, t1), got {t_span!r}")
    t0 = _validate.finite_real("t_span[0]", t_span[0])
    t1 = _validate.finite_real("t_span[1]", t_span[1])
    if t1 <= t0:
        raise ValueError(f"t_span must have t1 > t0, got ({t0:g}, {t1:g})")
    n = round((t1 - t0) / dt)
    if n < 1:
        raise ValueError(
            f"dt = {dt:g} is longer than the span t1 - t0 = {t1 - t0:g}: no step to take"
        )
    _validate.choice("on_blowup", on_blowup, ("stop", "raise"))
    if jac is not None and method not in IMPLICIT_METHODS:
        raise ValueError(f"jac is only used by the implicit methods {sorted(IMPLICIT_METHODS)}")
    if method in NEWTONIAN_METHODS and (y0.ndim < 1 or y0.shape[0] != 2):
        raise ValueError(
            f"method {method!r} needs a Newtonian state y0 = (x, v) stacked along axis 0 "
            f"(y0.shape[0] == 2); got y0 of shape {y0.shape}"
        )
    if blowup_bound is None:
        blowup_bound = 1e6 * max(1.0, float(np.max(np.abs(y0))))
    else:
        blowup_bound = _validate.positive_finite("blowup_bound", blowup_bound)

    counter = [0]
    rhs = _checked_rhs(f, y0.shape, counter)
    t = t0 + dt * np.arange(n + 1)
    y = np.full((n + 1, *y0.shape), np.nan, dtype=y0.dtype)
    y[0] = y0
    status, blowup_step, message = "ok", None, "ok"
    current = y0
    # Overflow inside a blowing-up run is expected; we detect it below and stop once,
    # instead of letting numpy print a warning on every step.
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k in range(n):
            if method in IMPLICIT_METHODS:
                current = stepper(rhs, t[k], current, dt, jac)
            else:
                current = stepper(rhs, t[k], current, dt)
            if post_step is not None:
                current = np.asarray(post_step(t[k + 1], current), dtype=y0.dtype)
            size = np.max(np.abs(current))
            if not np.isfinite(size) or size > blowup_bound:
                why = "non-finite state" if not np.isfinite(size) else f"|y| > {blowup_bound:.3g}"
                status, blowup_step = "unstable", k + 1
                message = f"unstable at step {k + 1}, t = {t[k + 1]:.6g} ({why})"
                if np.all(np.isfinite(current)):
                    y[k + 1] = current
                break
            y[k + 1] = current
    traj = Trajectory(t, y, method, dt, counter[0], status, blowup_step, message)
    if status != "ok" and on_blowup == "raise":
        raise BlowUpError(f"{method} with dt = {dt:g}: {message}")
    return traj
