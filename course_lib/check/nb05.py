"""Checks for notebook 05, Newton's second law."""

from __future__ import annotations

import numpy as np

from .. import events, forces
from ..integrators import symplectic_euler, velocity_verlet
from ..lessons import nb05_newton as demos
from ..systems import newtonian, oscillator, stack_state, sum_forces
from . import Checker, exercise


def _cases():
    """Newtonian systems and states to try a stepper on: (name, f, y, dt)."""
    rng = np.random.default_rng(5)
    osc = oscillator(omega=2.0)
    falling = newtonian(sum_forces(forces.constant_gravity(np.array([1.0, 2.0]), g=[0.0, -9.81]),
                                   forces.drag(b=0.3)), mass=np.array([1.0, 2.0]))
    y_fall = stack_state(rng.normal(size=(2, 2)), rng.normal(size=(2, 2)))
    return [("oscillator x'' = -4x, y = (1, 0.5), dt = 0.1", osc, 0.0, np.array([1.0, 0.5]), 0.1),
            ("two particles under gravity and drag, dt = 0.05", falling, 0.0, y_fall, 0.05)]


@exercise
def symplectic_euler_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: new velocity first, then the position with it."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        x_first = x + dt * v
        return {
            "this is forward Euler: move x with the NEW velocity v + dt a, not the old one":
                np.stack((x + dt * v, v + dt * a)),
            "that is the other symplectic Euler (x first, then v from the new x); "
            "here update v first": np.stack((x_first, v + dt * f(t, np.stack((x_first, v)))[1])),
        }

    ck.one_step_cases(step, _cases(), symplectic_euler, mistakes, hint=(
        "v_new = v + dt a(t, x, v); x_new = x + dt v_new; return np.stack((x_new, v_new))"))


@exercise
def velocity_verlet_step(ck: Checker, step) -> None:
    """``step(f, t, y, dt)``: half kick, drift, half kick with the force at the new position."""
    def mistakes(f, t, y, dt):
        x, v = y[0], y[1]
        a = f(t, y)[1]
        return {
            "the second half kick must use the acceleration at the NEW position "
            "f(t + dt, (x_new, v_half))[1], not the old one":
                np.stack((x + dt * v + 0.5 * dt**2 * a, v + dt * a)),
            "use half kicks: v_half = v + dt/2 a, then x_new = x + dt v_half":
                np.stack((x + dt * v + dt**2 * a, v + dt * a)),
        }

    ck.one_step_cases(step, _cases(), velocity_verlet, mistakes, hint=(
        "v_half = v + dt/2 a; x_new = x + dt v_half; "
        "v_new = v_half + dt/2 f(t + dt, (x_new, v_half))[1]"))


@exercise
def impact_time(ck: Checker, impact) -> None:
    """``impact(t, h)``: linear interpolation between the last sample above 0 and the first below."""
    for method in ("forward_euler", "symplectic_euler", "velocity_verlet"):
        traj = demos.apple_drop(method)
        t, h = traj.t, traj.y[:, 0, 0, 1]
        k = int(np.flatnonzero(h < 0)[0])
        ck.close(impact(t.copy(), h.copy()), events.first_crossing(t, h), f"apple by {method}",
                 rtol=1e-9, mistakes={
                     "you returned the time of the first step below ground; interpolate "
                     "between it and the step before": t[k],
                     "you returned the time of the last step above ground; interpolate "
                     "between it and the next step": t[k - 1],
                 }, hint="t* = t[k-1] + (t[k] - t[k-1]) h[k-1] / (h[k-1] - h[k])")
    t = np.linspace(0.0, 1.0, 11)
    ck.close(impact(t, 0.75 - t), 0.75, "a straight line h = 0.75 - t crosses at t = 0.75")


@exercise
def euler_apple_height(ck: Checker, height) -> None:
    """``height(n, dt, h0, g)``: forward Euler's height after n steps, in closed form."""
    for n, dt, h0, g in [(14, 0.1, 10.0, 9.81), (15, 0.1, 10.0, 9.81), (7, 0.05, 3.0, 1.62)]:
        traj = demos.apple_drop("forward_euler", dt=dt, h0=h0, g=g, t_end=(n + 1) * dt)
        ck.close(height(n, dt, h0, g), traj.y[n, 0, 0, 1],
                 f"n = {n}, dt = {dt}, h0 = {h0}, g = {g}", mistakes={
                     "h0 - g dt² n(n+1)/2 is symplectic Euler's height; forward Euler moves "
                     "with the OLD velocity, so its sum is 0 + 1 + ... + (n-1)":
                         demos.symplectic_apple_height(n, dt, h0, g),
                     "h0 - g (n dt)²/2 is the exact height; forward Euler lags behind it":
                         h0 - 0.5 * g * (n * dt) ** 2,
                 }, hint="v_k = -g k dt, and h_n = h0 + dt (v_0 + ... + v_(n-1))")
