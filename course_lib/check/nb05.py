"""Checks for notebook 05, Newton's second law.

An answer may call no course_lib function (nothing is handed over but the arguments: the
right-hand side ``f``, the samples, the hidden run), see :mod:`course_lib.check.policy`.
Hints come from the evidence: a known slip the answer reproduces, the times at which the
answer evaluated ``f``, or which half of the state (positions, velocities) is wrong; with
no evidence the check says what differs and nothing more.
"""

from __future__ import annotations

import numpy as np

from .. import events, forces
from ..integrators import symplectic_euler, velocity_verlet
from ..lessons import nb05_newton as lesson
from ..systems import newtonian, oscillator, stack_state, sum_forces
from . import Checker, exercise
from ._answers import as_array, close, mistake_hint, one_number, pure_call
from ._nb05_cases import impact_cases, impact_mistakes, order_mistakes, pendulum_run, power_run
from .tolerance import blown_up, escalate, precision_rtol


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


def _evidence(got, expected, y, calls, t, dt, times_wanted, tells) -> str | None:
    """A hint from what the answer did: the times it called ``f`` at, or the first of
    ``tells`` (``(test(answer, expected, y, dt), hint)``) that its numbers satisfy."""
    odd = sorted({round(c - t, 12) for c in calls} - {round(w * dt, 12) for w in times_wanted})
    wanted = " and ".join("t" if w == 0 else "t + dt" if w == 1 else f"t + {w:g} dt"
                          for w in times_wanted)
    if len(set(calls)) > 2 * len(times_wanted) + 1:
        return (f"your function evaluated f at {len(set(calls))} different times: one step of "
                f"this method evaluates it at {wanted} only (an adaptive solver, or several "
                f"small steps, is not this method)")
    if odd and t != 0.0:
        shown = " and ".join(_when(c, t, dt) for c in sorted(set(calls)))
        return (f"your function evaluated f at {shown}; the step starts at t = {t:g} s: "
                f"a force that depends on time needs the step's own times")
    a = as_array(got)
    if a is None or a.shape != expected.shape:
        return None
    for test, hint in tells:
        if test(a, expected, y, dt):
            return hint
    return None


def _when(time: float, t: float, dt: float) -> str:
    """A time ``f`` was called at, in words: "t + dt/2" near the step, else "time 0.1 s"."""
    for k, name in ((0.0, "t"), (0.5, "t + dt/2"), (1.0, "t + dt"), (-1.0, "t - dt"),
                    (2.0, "t + 2 dt"), (-0.5, "t - dt/2")):
        if abs(time - (t + k * dt)) <= 1e-12 * max(1.0, abs(t)):
            return name
    return "time 0" if time == 0 else f"time {time:.3g} s"


def _same(a, b) -> bool:
    return bool(np.allclose(a, b, rtol=1e-9, atol=1e-12))


def _one_step(ck: Checker, step, reference, mistakes_for, times_wanted, tells) -> None:
    """Run a student's one-step method on every case; blame only what the evidence shows."""
    for what, f, t, y, dt in _cases():
        expected, mistakes = reference(f, t, y.copy(), dt), mistakes_for(f, t, y.copy(), dt)
        calls = []

        def recorded(s, z, f=f, calls=calls):
            calls.append(float(s))
            return f(s, z)

        ok, got = pure_call(ck, what, step, recorded, t, y, dt)
        if not ok:
            continue
        answer = as_array(got)
        if answer is not None and answer.size and not np.all(np.isfinite(answer)):
            ck.expect(False, what, "your step returned NaN or inf")
            continue
        hint = mistake_hint(got, mistakes) or _evidence(got, expected, y, calls, t, dt,
                                                        times_wanted, tells)
        close(ck, got, expected, what, rtol=1e-12, atol=1e-14, hint=hint)


@exercise(allow=())
def symplectic_euler_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: new velocity first, then the position with it."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        x_first = x + dt * v
        a_late = f(t + dt, y)[1]
        return {
            escalate("this is forward Euler: symplectic Euler moves x with the NEW velocity",
                     "update the velocity first, then move the position with the velocity you "
                     "just computed, not with the one the step started from"):
                np.stack((x + dt * v, v + dt * a)),
            escalate("your acceleration ignores the velocity: the forces here depend on it "
                     "(drag, damping)", "evaluate f at the whole state y of the start of the "
                     "step, positions and velocities"):
                np.stack((x + dt * (v + dt * f(t, np.stack((x, 0 * v)))[1]),
                          v + dt * f(t, np.stack((x, 0 * v)))[1])),
            escalate("that is the other symplectic Euler (x first, then v from the new x); "
                     "here the velocity comes first", "kick v with the acceleration at the "
                     "start of the step, then move x with the new v"):
                np.stack((x_first, v + dt * f(t, np.stack((x_first, v)))[1])),
            escalate("the acceleration belongs to the start of the step: f(t, y), not "
                     "f(t + dt, y)", "the force is evaluated once, at the step's start time t "
                     "and the state y"): np.stack((x + dt * (v + dt * a_late), v + dt * a_late)),
            escalate("a full step, not half of one: the velocity changes by dt times the "
                     "acceleration", "symplectic Euler has no half kicks (that is Verlet)"):
                np.stack((x + dt * (v + 0.5 * dt * a), v + 0.5 * dt * a)),
            escalate("no dt²/2 term in symplectic Euler (that is Verlet's drift)",
                     "move x by dt times the new velocity, and nothing else"):
                np.stack((x + dt * (v + dt * a) + 0.5 * dt**2 * a, v + dt * a)),
        }

    _one_step(ck, step, symplectic_euler, mistakes, times_wanted=(0,), tells=[
        (lambda a, e, y, dt: _same(a[1], e[1]),
         escalate("your velocities are right and your positions are not: move x with the "
                  "velocity you just computed", "one full step dt with the new velocity, and "
                  "nothing else")),
        (lambda a, e, y, dt: _same(a[0], y[0] + dt * a[1]),
         escalate("your positions follow from your velocities, but the velocities are off: the "
                  "velocity changes by dt times the acceleration at the start of the step",
                  "the acceleration is the second half of f(t, y), at the step's start time"))])


@exercise(allow=())
def velocity_verlet_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: half kick, drift, half kick with the force at the new position."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        v_half = v + 0.5 * dt * a
        x_new = x + dt * v_half
        v_full = v + dt * a                               # a whole first kick
        x_far = x + dt * v_full
        v_implicit = v_half.copy()                        # the implicit kick, solved
        for _ in range(200):
            v_implicit = v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v_implicit)))[1]
        return {
            escalate("both half kicks used the same acceleration: the second one needs the "
                     "acceleration at the NEW position", "call f again once the drift has "
                     "moved x: at the end of the step, with the new positions"):
                np.stack((x_new, v_half + 0.5 * dt * a)),
            escalate("use half kicks: the drift moves x with the half-step velocity",
                     "kick the velocity by half a step, drift a full step with that velocity, "
                     "then kick again by half a step"):
                np.stack((x + dt * (v + dt * a), v + dt * a)),
            escalate("the first kick is a HALF kick: the drift uses the velocity half a step "
                     "in", "kick by dt/2 with the acceleration at the start, drift a full dt, "
                     "kick by dt/2 again"):
                np.stack((x_far, v_full + 0.5 * dt * f(t + dt, np.stack((x_far, v_full)))[1])),
            escalate("that is the implicit last kick of section 2 (the force at the velocity "
                     "being computed, solved for it): the exercise asks for the explicit form",
                     "evaluate the last kick's force once, at the new position and the "
                     "half-step velocity"): np.stack((x_new, v_implicit)),
            escalate("the new acceleration needs the new state (x_new, v_half): you passed the "
                     "OLD velocity v, which matters as soon as the force depends on velocity "
                     "(drag)", "the state you hand to f at the end of the step is the new "
                     "position with the velocity after the first half kick"):
                np.stack((x_new, v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v)))[1])),
            escalate("the new acceleration is at the END of the step: f(t + dt, ...), not "
                     "f(t, ...)", "a force that depends on time is evaluated at the time of "
                     "the state you hand it"):
                np.stack((x_new, v_half + 0.5 * dt * f(t, np.stack((x_new, v_half)))[1])),
            escalate("the second kick is a HALF kick too", "kick by dt/2 at the end of the "
                     "step, as at its start"):
                np.stack((x_new, v_half + dt * f(t + dt, np.stack((x_new, v_half)))[1])),
        }

    _one_step(ck, step, velocity_verlet, mistakes, times_wanted=(0, 1), tells=[
        (lambda a, e, y, dt: _same(a[1], e[1]),
         escalate("your velocities are right and your positions are not: the drift uses the "
                  "half-step velocity", "a full step dt of drift with the velocity after the "
                  "first half kick")),
        (lambda a, e, y, dt: _same(a[0], e[0]),
         escalate("your positions are right and your velocities are not: look at the second "
                  "half kick", "half a step, with the acceleration at the end of the step, "
                  "the new positions and the half-step velocities"))])


@exercise(allow=())
def impact_time(ck: Checker, impact) -> None:
    """``impact(t, h)``: linear interpolation between the last sample at or above 0 and the
    first below, on data with several crossings, uneven steps and a start on the ground."""
    for what, t, h in impact_cases():
        got = impact(t.copy(), h.copy())
        value = one_number(ck, what, got, "a time in s")
        if value is None:
            continue
        ck.close(value, events.first_crossing(t, h), what, rtol=precision_rtol(got, 1e-9),
                 mistakes=impact_mistakes(t, h))


@exercise(allow=())
def observed_order(ck: Checker, func) -> None:
    """``func(run, dt) -> (p, error)``: order and finest-run error from three runs."""
    cases = [("a hidden first-order run, scalar result", power_run(1.0, (), 1), 0.1),
             ("a hidden third-order run (no method of this notebook), 2×3 result",
              power_run(3.0, (2, 3), 2), 0.2),
             ("a hidden fourth-order run, dt = 0.5", power_run(4.0, (5,), 3), 0.5),
             ("midpoint on the pendulum, state at t = 2 s", pendulum_run("midpoint"), 0.02)]
    for what, run, dt in cases:
        asked = []

        def recorded(h, run=run, asked=asked):
            asked.append(float(h))
            return run(h)

        got = func(recorded, dt)
        coarse, middle, fine = (np.asarray(run(h), dtype=float) for h in (dt, dt / 2, dt / 4))
        p, err = lesson.three_grid_order(run, dt)
        wanted = np.array([dt / 4, dt / 2, dt])
        used = np.unique(np.round(np.array(asked) / dt, 12)) * dt
        if not asked:
            ck.expect(False, what, "your function never called run",
                      hint="call run with the three steps and compare what it returns")
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
        if np.ndim(got_p) or np.ndim(got_err):
            ck.expect(False, what, f"p and the error must be numbers, got shapes "
                      f"{np.shape(got_p)} and {np.shape(got_err)}",
                      hint="the runs return arrays here: reduce each difference to one number "
                           "with np.linalg.norm over all its components")
            continue
        if blown_up(ck, [got_p, got_err], what, run=False, hint=(
                "look for a division by zero, or the logarithm of a negative number: a "
                "signed difference can be negative, its size (a norm) cannot")):
            continue
        orders, errors = order_mistakes(coarse, middle, fine, p, err)
        ck.close(got_p, p, f"{what}: order", rtol=precision_rtol(got_p, 1e-9), mistakes=orders)
        with np.errstate(all="ignore"):
            follows = float(np.linalg.norm(middle - fine)) / (2.0 ** float(got_p) - 1.0)
        if not np.isclose(got_p, p, rtol=1e-6) and np.isclose(got_err, follows, rtol=1e-6):
            errors = {"your error estimate is right for your order: fix the order first": follows,
                      **errors}
        ck.close(got_err, err, f"{what}: error of the finest run",
                 rtol=precision_rtol(got_err, 1e-9), mistakes=errors)
