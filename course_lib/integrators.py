"""The fixed-step driver: ``integrate(f, y0, t_span, dt, method) -> Trajectory``.

The one-step methods live in :mod:`course_lib.steppers` (all their names are importable
from here too); this module runs one of them over a time grid, checks the run and reports.

The time grid (:mod:`course_lib.timegrid`) lands exactly on ``t1``: every step is ``dt``,
except, when ``t1 - t0`` is not a whole number of steps (to 8 units in the last place of the
times), the last one, ``t1 - t[n-1]``, computed from ``t1`` and shorter than ``dt``.

The run is checked, not the physics: ``f``'s first evaluations are checked for shape,
type and (for the symplectic methods) ``dx/dt = v``; states are checked in blocks of steps
for non-finite values (and a ``blowup_bound`` if given), so that the loop costs little more
than calling ``f``. Imports: numpy and the core modules ``_validate``, ``steppers``,
``implicit`` and ``timegrid``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from . import _validate
from .implicit import ConvergenceError, Jacobian, NewtonSolver
from .steppers import (  # noqa: F401  (re-exported: course_lib.integrators.<name>)
    EVALS_PER_STEP,
    IMPLICIT_METHODS,
    METHODS,
    NEWTONIAN_METHODS,
    ORDER,
    RHS,
    CheckedRHS,
    backward_euler,
    fast_rhs,
    forward_euler,
    get_stepper,
    heun,
    midpoint,
    rk4,
    step,
    symplectic_euler,
    trapezoidal,
    velocity_verlet,
)
from .timegrid import MAX_STEPS, time_grid


class BlowUpError(RuntimeError):
    """Raised by :func:`integrate` with ``on_blowup="raise"`` when a run goes unstable."""


@dataclass
class Trajectory:
    """The result of :func:`integrate`.

    Attributes
    ----------
    t : ndarray, shape (n+1,)
        Times (s): ``t0 + k dt``, and exactly ``t1`` at the end.
    y : ndarray, shape (n+1, *y0.shape)
        States; after a stop the remaining rows are NaN.
    method : str
        The method used.
    dt : float
        The step (s); the last one may be shorter (see :func:`integrate`).
    nfev : int
        Right-hand-side evaluations of the completed steps (with Newton's and the
        finite-difference Jacobian's).
    status : str
        ``"ok"``; ``"unstable"`` (a non-finite state, or one past ``blowup_bound``);
        ``"failed"`` (an implicit step whose Newton iteration did not converge).
    blowup_step : int or None
        Index of the first step that was non-finite, past the bound, or failed.
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
        """True when the run finished without blowing up or failing."""
        return self.status == "ok"

    @property
    def n_steps(self) -> int:
        return len(self.t) - 1

    @property
    def last_valid(self) -> int:
        """Index of the last stored state (a state past the bound is kept; NaN is not)."""
        if self.blowup_step is None:
            return self.n_steps
        kept = bool(np.all(np.isfinite(self.y[self.blowup_step])))
        return self.blowup_step if kept else self.blowup_step - 1

    def __repr__(self) -> str:
        return (
            f"Trajectory(method={self.method!r}, dt={self.dt:g}, steps={self.n_steps}, "
            f"y.shape={self.y.shape}, nfev={self.nfev}, status={self.message!r})"
        )


class _StepFailed(Exception):
    def __init__(self, done: int, error: Exception):
        self.done, self.error = done, error


def _advance(stepper, f, post, t, out, start: int, end: int, h: float, cur):
    """Steps ``start .. end-1`` with step ``h``; rows ``start+1 .. end`` are stored."""
    times = t[start:end + 1].tolist()
    k = start
    try:
        if post is None:
            for k, tk in zip(range(start, end), times, strict=False):
                cur = stepper(f, tk, cur, h)
                out[k + 1] = cur
        else:
            for k, tk in zip(range(start, end), times, strict=False):
                cur = post(times[k + 1 - start], stepper(f, tk, cur, h))
                out[k + 1] = cur
    except Exception as error:  # report how far the block got
        raise _StepFailed(k, error) from error
    return cur


def _first_bad(rows: np.ndarray, bound: float | None) -> tuple[int, str] | None:
    """Index of the first non-finite row of ``rows`` (or past ``bound``), and why."""
    if bound is None:
        if np.isfinite(rows).all():
            return None
        ok = np.isfinite(rows.reshape(len(rows), -1)).all(axis=1)
        return int(np.argmin(ok)), "non-finite state"
    sizes = np.abs(rows.reshape(len(rows), -1)).max(axis=1)
    ok = sizes <= bound
    if ok.all():
        return None
    j = int(np.argmin(ok))
    return j, ("non-finite state" if not np.isfinite(sizes[j]) else f"|y| > {bound:.3g}")


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
    max_steps: int = MAX_STEPS,
) -> Trajectory:
    """Integrate ``dy/dt = f(t, y)`` from ``t_span[0]`` to ``t_span[1]`` with a fixed step.

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` (``scipy.integrate.solve_ivp`` convention), returning an
        array of ``y``'s shape; real for a real ``y0`` (``TypeError`` otherwise). It may
        return the same buffer every call and may modify its argument.
    y0 : array_like
        Initial state, any shape; finite. Newtonian systems stack ``(x, v)`` on axis 0.
        Complex for a complex system.
    t_span : (float, float)
        Start and end time (s), ``t1 > t0``.
    dt : float
        Step (s), finite, ``0 < dt <= t1 - t0``. The run ends exactly at ``t1``: when
        ``t1 - t0`` is a whole number ``n`` of steps (to ``tol``, 8 units in the last place
        of the times) it takes ``n`` steps of ``dt``; otherwise the fewest steps of ``dt``
        and a last, shorter one, ``t1 - t[-2]``. Every interval of ``t`` is within ``tol``
        of the step taken over it (:mod:`course_lib.timegrid` states the rule).
    method : str
        One of :data:`METHODS`.
    jac : callable, ndarray or scipy.sparse matrix, optional
        ``df/dy`` for the implicit methods, shape ``(y0.size, y0.size)``: constant, or
        ``jac(t, y)`` returning it. A sparse one gives a sparse solve; without one, a
        finite-difference Jacobian (dense) is used. See :class:`~course_lib.implicit.NewtonSolver`.
    blowup_bound : float, optional
        Stop when ``max|y|`` exceeds this (units of ``y``). Default ``None``: no bound, only
        a non-finite state stops the run, so an accurate run is never called unstable.
    on_blowup : {"stop", "raise"}
        What to do when a state is non-finite or past the bound, or an implicit step
        fails: ``"stop"`` keeps the good steps, fills the remaining rows with NaN and says
        why in ``status``/``message``; ``"raise"`` raises :class:`BlowUpError`.
    post_step : callable, optional
        ``post_step(t, y) -> y`` applied after every step, e.g. to resolve collisions or
        enforce pins (a projection, not part of ``f``). Must return the state's shape.
    max_steps : int
        Refuse runs of more steps than this (default 10 million): all states are stored.

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
    t, last = time_grid(t_span, dt, max_steps)
    dt = float(dt)
    _validate.choice("on_blowup", on_blowup, ("stop", "raise"))
    _validate.method_options(method, y0, "y0", jac, IMPLICIT_METHODS, NEWTONIAN_METHODS)
    bound = None if blowup_bound is None else _validate.positive_finite("blowup_bound",
                                                                         blowup_bound)
    post = None
    if post_step is not None:
        post = _validate.post_step_checker(_validate.callable_arg("post_step", post_step),
                                           y0.shape, y0.dtype)

    implicit = method in IMPLICIT_METHODS
    checked = CheckedRHS(f, y0.shape, y0.dtype, method if method in NEWTONIAN_METHODS else "")
    if implicit:
        stepper = partial(stepper, newton=NewtonSolver(jac))
    n = len(t) - 1
    out = np.empty((n + 1, *y0.shape), dtype=y0.dtype)
    out[0] = y0
    # Blocks of steps between checks: one step for costly (implicit, large) states, up to
    # 64 for small ones, where a check per step would cost more than the step itself.
    block = 1 if implicit else int(np.clip(4096 // y0.size, 1, 64))
    rhs, cur, start, explicit_steps = checked, y0, 0, 0
    stop = None  # (step, status, reason, error, whether that step's state is kept)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        while start < n and stop is None:
            end = 1 if start == 0 else min(start + block, n - 1 if last != dt else n)
            end = max(end, start + 1)
            h = last if start == n - 1 else dt
            try:
                cur = _advance(stepper, rhs, post, t, out, start, end, h, cur)
                done, error = end, None
            except _StepFailed as failed:
                done, error = failed.done, failed.error
            if start > 0:
                explicit_steps += done - start
            bad = _first_bad(out[start + 1:done + 1], bound)
            if bad is not None:
                k = start + 1 + bad[0]
                stop = (k, "unstable", bad[1], None, bool(np.all(np.isfinite(out[k]))))
            elif isinstance(error, ConvergenceError):
                status = "unstable" if error.nonfinite else "failed"
                stop = (done + 1, status, str(error).split(": ", 1)[-1], error, False)
            elif error is not None:
                raise error
            if start == 0 and not implicit:
                rhs = fast_rhs(f, checked)
            start = end
    nfev = checked.calls + (0 if implicit else explicit_steps * EVALS_PER_STEP[method])
    traj = Trajectory(t, out, method, dt, nfev)
    if stop is not None:
        k, traj.status, reason, error, keep = stop
        out[k + 1 if keep else k:] = np.nan
        word = "unstable" if traj.status == "unstable" else "stopped"
        traj.blowup_step, traj.message = k, f"{word} at step {k}, t = {t[k]:.6g} ({reason})"
        if on_blowup == "raise":
            raise BlowUpError(f"{method} with dt = {dt:g}: {traj.message}") from error
    return traj
