"""Checks for notebook 05, Newton's second law.

Every exercise names the course_lib functions it must not call (besides the automatic ones
of :mod:`course_lib.check.policy`): an answer that calls them earns nothing.
"""

from __future__ import annotations

import numpy as np

from .. import events, forces
from ..integrators import symplectic_euler, velocity_verlet
from ..lessons import nb05_newton as lesson
from ..systems import newtonian, oscillator, stack_state, sum_forces
from . import Checker, exercise
from ._answers import step_cases
from .tolerance import blown_up, precision_rtol


def _driven(t, y):
    """x'' = -4 x - 0.5 x' + 2 cos 3t: a force that depends on time AND velocity."""
    return np.array([y[1], -4.0 * y[0] - 0.5 * y[1] + 2.0 * np.cos(3.0 * t)])


def _cases():
    """Newtonian systems and states to try a stepper on: (what, f, t, y, dt)."""
    rng = np.random.default_rng(5)
    falling = newtonian(sum_forces(forces.constant_gravity(np.array([1.0, 2.0]), g=[0.0, -9.81]),
                                   forces.drag(b=0.3), forces.attractor((0.0, 0.0), 3.0, 0.5)),
                        mass=np.array([1.0, 2.0]))
    y_fall = stack_state(rng.normal(size=(2, 2)), rng.normal(size=(2, 2)))
    return [("oscillator x'' = -4x, y = (1, 0.5), dt = 0.1", oscillator(omega=2.0), 0.0,
             np.array([1.0, 0.5]), 0.1),
            ("two particles under gravity, drag and a central pull, dt = 0.05", falling, 0.0,
             y_fall, 0.05),
            ("driven, damped x'' = -4x - 0.5x' + 2 cos 3t at t = 0.7 s, dt = 0.1", _driven, 0.7,
             np.array([0.3, -1.2]), 0.1)]


def _one_step(ck: Checker, step, reference, mistakes_for, hint: str) -> None:
    """Run a student's one-step method on every case; blame only what it got wrong."""
    step_cases(ck, step, _cases(), reference, mistakes_for, hint, rtol=1e-12, atol=1e-14)


@exercise
def symplectic_euler_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: new velocity first, then the position with it."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        x_first = x + dt * v
        a_late = f(t + dt, y)[1]
        return {
            "this is forward Euler: move x with the NEW velocity v + dt a, not the old one":
                np.stack((x + dt * v, v + dt * a)),
            "that is the other symplectic Euler (x first, then v from the new x); "
            "here update v first": np.stack((x_first, v + dt * f(t, np.stack((x_first, v)))[1])),
            "the acceleration belongs to the start of the step: f(t, y), not f(t + dt, y)":
                np.stack((x + dt * (v + dt * a_late), v + dt * a_late)),
            "a full step, not half of one: v_new = v + dt a": np.stack(
                (x + dt * (v + 0.5 * dt * a), v + 0.5 * dt * a)),
            "no dt²/2 term in symplectic Euler (that is Verlet's drift): x_new = x + dt v_new":
                np.stack((x + dt * (v + dt * a) + 0.5 * dt**2 * a, v + dt * a)),
        }

    _one_step(ck, step, symplectic_euler, mistakes, hint=(
        "v_new = v + dt f(t, y)[1]; x_new = x + dt v_new; return np.stack((x_new, v_new))"))


@exercise
def velocity_verlet_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: half kick, drift, half kick with the force at the new position."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        v_half = v + 0.5 * dt * a
        x_new = x + dt * v_half
        return {
            "the second half kick must use the acceleration at the NEW position "
            "f(t + dt, (x_new, v_half))[1], not the old one":
                np.stack((x_new, v_half + 0.5 * dt * a)),
            "use half kicks: v_half = v + dt/2 a, then x_new = x + dt v_half":
                np.stack((x + dt * (v + dt * a), v + dt * a)),
            "the new acceleration needs the new state (x_new, v_half): you passed the OLD "
            "velocity v, which matters as soon as the force depends on velocity (drag)":
                np.stack((x_new, v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v)))[1])),
            "the new acceleration is at the END of the step: f(t + dt, ...), not f(t, ...)":
                np.stack((x_new, v_half + 0.5 * dt * f(t, np.stack((x_new, v_half)))[1])),
            "the second kick is a HALF kick too: v_new = v_half + dt/2 a_new":
                np.stack((x_new, v_half + dt * f(t + dt, np.stack((x_new, v_half)))[1])),
        }

    _one_step(ck, step, velocity_verlet, mistakes, hint=(
        "v_half = v + dt/2 a; x_new = x + dt v_half; "
        "v_new = v_half + dt/2 f(t + dt, (x_new, v_half))[1]"))


@exercise(reference=(events.first_crossing, events.crossing_linear))
def impact_time(ck: Checker, impact) -> None:
    """``impact(t, h)``: linear interpolation between the last sample above 0 and the first below."""
    cases = []
    for method in ("forward_euler", "symplectic_euler", "velocity_verlet"):
        traj = lesson.apple_drop(method)
        cases.append((f"apple by {method}", traj.t, traj.y[:, 0, 0, 1]))
    line = np.linspace(0.0, 1.0, 11)
    cases.append(("a straight line h = 0.75 - t crosses at t = 0.75", line, 0.75 - line))
    cases.append(("samples that touch 0 exactly: h = (1, 0, -1) at t = (0, 1, 2)",
                  np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.0, -1.0])))
    for what, t, h in cases:
        k = int(np.flatnonzero(h < 0)[0])
        got = impact(t.copy(), h.copy())
        if blown_up(ck, got, what, run=False):
            continue
        dt = t[k] - t[k - 1]
        ck.close(got, events.first_crossing(t, h), what, rtol=precision_rtol(got, 1e-9), mistakes={
            "you returned the time of the first step below ground; interpolate "
            "between it and the step before": t[k],
            "you returned the time of the last step above ground; interpolate "
            "between it and the next step": t[k - 1],
            "the fraction of the step is h[k-1] / (h[k-1] - h[k]), the part of the drop "
            "still above ground; you used h[k] in the numerator":
                t[k - 1] + dt * h[k] / (h[k - 1] - h[k]),
            "the fraction of the step is h[k-1] / (h[k-1] - h[k]): mind the sign of the "
            "denominator": t[k - 1] - dt * h[k - 1] / (h[k - 1] - h[k]),
            "you returned an index; return the time t*": k,
            "you returned the midpoint of the step; interpolate where the line meets 0":
                0.5 * (t[k - 1] + t[k]),
        }, hint="t* = t[k-1] + (t[k] - t[k-1]) h[k-1] / (h[k-1] - h[k])")


def _power_run(p: float, shape=(), seed: int = 0):
    """A run whose result approaches a hidden limit like ``C dt^p + D dt^(p+1)``."""
    rng = np.random.default_rng(seed)
    limit, C, D = (rng.normal(size=shape) for _ in range(3))
    return lambda dt: limit + C * dt**p + D * dt ** (p + 1)


@exercise(reference=(lesson.three_grid_order,))
def observed_order(ck: Checker, func) -> None:
    """``func(run, dt) -> (p, error)``: order and finest-run error from three runs."""
    cases = [("a hidden first-order run, scalar result", _power_run(1.0, (), 1), 0.1),
             ("a hidden third-order run (no method of this notebook), 2×3 result",
              _power_run(3.0, (2, 3), 2), 0.2),
             ("a hidden fourth-order run, dt = 0.5", _power_run(4.0, (5,), 3), 0.5),
             ("midpoint on the pendulum, state at t = 2 s", _pendulum_run("midpoint"), 0.02)]
    for what, run, dt in cases:
        asked = []

        def recorded(h, run=run, asked=asked):
            asked.append(float(h))
            return run(h)

        got = func(recorded, dt)
        p, err = lesson.three_grid_order(run, dt)
        wanted = np.array([dt / 4, dt / 2, dt])
        used = np.unique(np.round(np.array(asked) / dt, 12)) * dt
        if not asked:
            ck.expect(False, what, "your function never called run",
                      hint="call run(dt), run(dt / 2) and run(dt / 4) and compare the results")
            continue
        if used.shape != wanted.shape or not np.allclose(used, wanted, rtol=1e-12):
            ck.expect(False, what, f"your function ran the steps {used.tolist()}",
                      hint=f"run the three grids dt, dt/2 and dt/4, here {wanted[::-1].tolist()}")
            continue
        try:
            got_p, got_err = got
        except (TypeError, ValueError):
            ck.expect(False, what, f"return a pair (p, error), got {got!r:.60}")
            continue
        if blown_up(ck, [got_p, got_err], what, run=False):
            continue
        ratio = 2.0**p
        d2 = err * (ratio - 1.0)
        ck.close(got_p, p, f"{what}: order", rtol=precision_rtol(got_p, 1e-9), mistakes={
            "use the base-2 logarithm: halving dt divides the difference by 2^p": np.log(ratio),
            "use the base-2 logarithm, not base 10": np.log10(ratio),
            "upside down: the coarse difference |y_h - y_h/2| goes on top": -p,
            "the finest run is not exact: compare consecutive runs, |y_h - y_h/2| / "
            "|y_h/2 - y_h/4|": np.log2(2.0**p + 1.0),
        }, hint="p = log2(|y_h - y_h/2| / |y_h/2 - y_h/4|)")
        ck.close(got_err, err, f"{what}: error of the finest run", rtol=precision_rtol(got_err, 1e-9),
                 mistakes={
                     "|y_h/2 - y_h/4| is the error of y_h/2 minus that of y_h/4; divide by "
                     "2^p - 1 to get the finest run's own error": d2,
                     "|y_h - y_h/2| / (2^p - 1) is the error of the MIDDLE run; the finest "
                     "run's is 2^p times smaller: use |y_h/2 - y_h/4|": d2 * ratio / (ratio - 1.0),
                 }, hint="y_h/2 - y_h/4 ≈ C (h/4)^p (2^p - 1), and the finest run is off by "
                         "C (h/4)^p")


def _pendulum_run(method: str):
    from ..integrators import integrate

    f = lesson.pendulum()
    return lambda dt: integrate(f, np.array([1.0, 0.0]), (0.0, 2.0), dt, method).y[-1]
