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
from ..integrators import integrate, symplectic_euler, velocity_verlet
from ..lessons import nb05_newton as lesson
from ..systems import newtonian, oscillator, stack_state, sum_forces
from . import Checker, exercise
from ._answers import as_array, close, mistake_hint, one_number, pure_call
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
    if odd and t != 0.0:
        shown = ", ".join("t" if s == 0 else f"t {'+' if s > 0 else '-'} {abs(s):.3g}"
                          for s in (round(c - t, 12) for c in sorted(set(calls))))
        return (f"your function evaluated f at {shown} (the step starts at t = {t:g} s): "
                f"a force that depends on time needs the step's own times")
    a = as_array(got)
    if a is None or a.shape != expected.shape:
        return None
    for test, hint in tells:
        if test(a, expected, y, dt):
            return hint
    return None


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
             "v_new = v + dt a, then x_new = x + dt v_new (not x + dt v)"):
                np.stack((x + dt * v, v + dt * a)),
            "that is the other symplectic Euler (x first, then v from the new x); here the "
            "velocity comes first": np.stack((x_first, v + dt * f(t, np.stack((x_first, v)))[1])),
            "the acceleration belongs to the start of the step: f(t, y), not f(t + dt, y)":
                np.stack((x + dt * (v + dt * a_late), v + dt * a_late)),
            "a full step, not half of one: v_new = v + dt a": np.stack(
                (x + dt * (v + 0.5 * dt * a), v + 0.5 * dt * a)),
            "no dt²/2 term in symplectic Euler (that is Verlet's drift): x_new = x + dt v_new":
                np.stack((x + dt * (v + dt * a) + 0.5 * dt**2 * a, v + dt * a)),
        }

    _one_step(ck, step, symplectic_euler, mistakes, times_wanted=(0,), tells=[
        (lambda a, e, y, dt: _same(a[1], e[1]),
         escalate("your velocities are right and your positions are not: move x with the velocity you "
          "just computed", "x_new = x + dt v_new")),
        (lambda a, e, y, dt: _same(a[0], y[0] + dt * a[1]),
         escalate("your positions follow from your velocities, but the velocities are off: the "
          "velocity changes by dt times the acceleration at the start of the step",
          "v_new = v + dt f(t, y)[1]"))])


@exercise(allow=())
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
            escalate("use half kicks: the drift moves x with the half-step velocity",
             "v_half = v + dt/2 a, then x_new = x + dt v_half"):
                np.stack((x + dt * (v + dt * a), v + dt * a)),
            "the new acceleration needs the new state (x_new, v_half): you passed the OLD "
            "velocity v, which matters as soon as the force depends on velocity (drag)":
                np.stack((x_new, v_half + 0.5 * dt * f(t + dt, np.stack((x_new, v)))[1])),
            "the new acceleration is at the END of the step: f(t + dt, ...), not f(t, ...)":
                np.stack((x_new, v_half + 0.5 * dt * f(t, np.stack((x_new, v_half)))[1])),
            "the second kick is a HALF kick too: v_new = v_half + dt/2 a_new":
                np.stack((x_new, v_half + dt * f(t + dt, np.stack((x_new, v_half)))[1])),
        }

    _one_step(ck, step, velocity_verlet, mistakes, times_wanted=(0, 1), tells=[
        (lambda a, e, y, dt: _same(a[1], e[1]),
         escalate("your velocities are right and your positions are not: the drift uses the half-step "
          "velocity", "x_new = x + dt v_half, v_half = v + dt/2 a")),
        (lambda a, e, y, dt: _same(a[0], e[0]),
         escalate("your positions are right and your velocities are not: look at the second half kick",
          "v_new = v_half + dt/2 f(t + dt, (x_new, v_half))[1]"))])


def _impact_cases():
    """(what, t, h): the apple by three methods, and data that breaks the shortcuts."""
    cases = []
    for method in ("forward_euler", "symplectic_euler", "velocity_verlet"):
        traj = lesson.apple_drop(method)
        cases.append((f"apple by {method}", traj.t, traj.y[:, 0, 0, 1]))
    cases.append(("samples that touch 0 exactly: h = (1, 0, -1) at t = (0, 1, 2)",
                  np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.0, -1.0])))
    t = np.linspace(0.0, 2.0, 21)
    cases.append(("thrown up from the ground (h starts at 0, rises, then falls)", t,
                  8.0 * t - 4.905 * t**2))
    tb = np.linspace(0.0, 4.5, 46)
    hb = np.abs(np.cos(2.2 * tb)) * np.exp(-0.3 * tb) - 0.25      # dips below 0 four times
    cases.append(("a bouncing height that goes below 0 four times", tb, hb))
    tu = np.cumsum(np.r_[0.0, np.random.default_rng(55).uniform(0.05, 0.3, 14)])
    cases.append(("unevenly spaced samples", tu, 2.0 - 1.5 * tu**2 + 0.2 * np.sin(9 * tu)))
    return cases


def _impact_mistakes(t, h):
    k = int(np.flatnonzero(h < 0)[0])
    dt = t[k] - t[k - 1]
    with np.errstate(all="ignore"):
        out = {
            "you returned the time of the first sample below ground; interpolate between it "
            "and the sample before": t[k],
            "you returned the time of the last sample above ground; interpolate between it "
            "and the next one": t[k - 1],
            "the fraction of the step is the part of the drop still above ground, h[k-1] / "
            "(h[k-1] - h[k]); you put h[k] on top": t[k - 1] + dt * h[k] / (h[k - 1] - h[k]),
            "mind the sign of the fraction: the crossing lies after t[k-1], not before":
                t[k - 1] - dt * h[k - 1] / (h[k - 1] - h[k]),
            "you returned an index; return the time t*": k,
            "you returned the midpoint of the step; interpolate where the line meets 0":
                0.5 * (t[k - 1] + t[k]),
            "these samples are not evenly spaced: the step is t[k] - t[k-1], not t[1] - t[0]":
                t[k - 1] + (t[1] - t[0]) * h[k - 1] / (h[k - 1] - h[k]),
            "np.interp needs increasing sample points, and h is not monotone here: find the "
            "first sample below 0 and interpolate on that step": np.interp(0.0, h[::-1], t[::-1]),
        }
        later = np.flatnonzero((h[1:] < 0) & (h[:-1] >= 0)) + 1
        if later.size > 1:
            j = int(later[-1])
            out["that is the last crossing: the impact is the FIRST time h goes below 0"] = (
                t[j - 1] + (t[j] - t[j - 1]) * h[j - 1] / (h[j - 1] - h[j]))
        start = np.flatnonzero(np.diff(np.sign(h)) != 0)
        if h[0] == 0.0 and start.size:
            out["h starts at 0 on the ground: a sign change from 0 to + is the throw, not the "
                "impact; look for the first sample BELOW 0"] = float(t[0])
    return out


@exercise(allow=())
def impact_time(ck: Checker, impact) -> None:
    """``impact(t, h)``: linear interpolation between the last sample at or above 0 and the
    first below, on data with several crossings, uneven steps and a start on the ground."""
    for what, t, h in _impact_cases():
        got = impact(t.copy(), h.copy())
        value = one_number(ck, what, got, "a time in s")
        if value is None:
            continue
        ck.close(value, events.first_crossing(t, h), what, rtol=precision_rtol(got, 1e-9),
                 mistakes=_impact_mistakes(t, h))


def _power_run(p: float, shape=(), seed: int = 0):
    """A run whose result approaches a hidden limit like ``C dt^p + D dt^(p+1)``."""
    rng = np.random.default_rng(seed)
    limit, C, D = (rng.normal(size=shape) for _ in range(3))
    return lambda dt: limit + C * dt**p + D * dt ** (p + 1)


def _pendulum_run(method: str):
    f = lesson.pendulum()
    return lambda dt: integrate(f, np.array([1.0, 0.0]), (0.0, 2.0), dt, method).y[-1]


def _order_mistakes(coarse, middle, fine, p, err) -> tuple[dict, dict]:
    """Wrong orders and wrong errors that the usual slips give."""
    ratio = 2.0**p
    d2 = err * (ratio - 1.0)
    m1, m2 = np.abs(coarse - middle).max(), np.abs(middle - fine).max()
    p_max = np.log2(m1 / m2)
    orders = {
        "use the base-2 logarithm: halving dt divides the difference by 2^p": np.log(ratio),
        "use the base-2 logarithm, not base 10": np.log10(ratio),
        "upside down: the coarse difference |y_h - y_h/2| goes on top": -p,
        "the finest run is not exact: compare consecutive runs, (y_h - y_h/2) with "
        "(y_h/2 - y_h/4)": np.log2(ratio + 1.0),
        "you rounded p: a measured order is not a whole number; return it as measured":
            float(np.round(p)),
        "measure each difference with the Euclidean norm over all components "
        "(np.linalg.norm), as the exercise says, not the largest entry": p_max,
    }
    errors = {
        escalate("|y_h/2 - y_h/4| is the error of y_h/2 minus that of y_h/4, not the finest run's "
         "own error", "divide it by 2^p - 1"): d2,
        "|y_h - y_h/2| / (2^p - 1) is the error of the MIDDLE run; the finest run's is 2^p "
        "times smaller": d2 * ratio / (ratio - 1.0),
        "measure each difference with the Euclidean norm over all components": m2 / (2**p_max - 1),
    }
    return orders, errors


@exercise(allow=())
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
        if blown_up(ck, [got_p, got_err], what, run=False):
            continue
        orders, errors = _order_mistakes(coarse, middle, fine, p, err)
        ck.close(got_p, p, f"{what}: order", rtol=precision_rtol(got_p, 1e-9), mistakes=orders)
        ck.close(got_err, err, f"{what}: error of the finest run",
                 rtol=precision_rtol(got_err, 1e-9), mistakes=errors)
