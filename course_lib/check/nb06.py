"""Checks for notebook 06, forces."""

from __future__ import annotations

import numpy as np

from .. import forces
from ..integrators import integrate
from ..systems import newtonian, stack_state
from . import Checker, exercise


@exercise
def drag_force(ck: Checker, drag) -> None:
    """``drag(v, b, wind)``: linear drag ``-b (v - wind)`` on velocities ``(N, d)``."""
    rng = np.random.default_rng(6)
    v = rng.normal(size=(4, 3))
    for b, wind, what in [(0.5, np.zeros(3), "four particles, b = 0.5, still air"),
                          (2.0, np.array([3.0, 0.0, -1.0]), "b = 2, wind (3, 0, -1) m/s")]:
        ck.close(drag(v.copy(), b, wind.copy()), forces.linear_drag_force(v, b, wind), what,
                 mistakes={
                     "sign error: drag opposes the motion relative to the air, F = -b (v - w)":
                         b * (v - wind),
                     "you forgot the wind: drag acts on the velocity relative to the air, "
                     "v - wind": -b * v,
                     "the relative velocity is v - wind, not v + wind": -b * (v + wind),
                 }, hint="F = -b (v - wind)")
    ck.close(drag(np.tile([1.0, 0.0], (2, 1)), 1.0, np.array([1.0, 0.0])), np.zeros((2, 2)),
             "moving with the wind: no drag")


@exercise
def terminal_velocity(ck: Checker, vt) -> None:
    """``vt(m, g, b)``: the speed at which linear drag balances gravity, ``m g / b``."""
    for m, g, b in [(1.0, 9.81, 0.5), (0.2, 9.81, 0.05), (3.0, 1.62, 1.5)]:
        ck.close(vt(m, g, b), m * g / b, f"m = {m} kg, g = {g} m/s², b = {b} kg/s", mistakes={
            "you forgot the mass: the weight is m g": g / b,
            "drag b v balances the weight m g, so divide by b": m * g * b,
            "upside down: v = m g / b": b / (m * g),
        }, hint="at terminal velocity the net force is zero: b v = m g")


@exercise
def circular_speed(ck: Checker, speed) -> None:
    """``speed(G, M, r)``: speed of a circular orbit of radius r about a mass M, ``sqrt(GM/r)``."""
    for G, M, r in [(1.0, 1.0, 1.0), (1.0, 4.0, 2.0), (6.674e-11, 5.972e24, 6.771e6)]:
        ck.close(speed(G, M, r), np.sqrt(G * M / r), f"G = {G:g}, M = {M:g}, r = {r:g}",
                 rtol=1e-9, mistakes={
                     "take the square root: v² / r = G M / r²": G * M / r,
                     "sqrt(2 G M / r) is the escape speed, not the circular one":
                         np.sqrt(2 * G * M / r),
                 }, hint="the centripetal acceleration v²/r equals the gravitational G M / r²")
    # Does the orbit close? Fly a test mass around a fixed centre for one Kepler period.
    G, M, r = 1.0, 4.0, 2.0
    v = float(np.asarray(speed(G, M, r), dtype=float))
    period = 2 * np.pi * np.sqrt(r**3 / (G * M))
    pull = newtonian(forces.attractor((0.0, 0.0), G * M, softening=0.0), mass=1.0)
    y0 = stack_state([[r, 0.0]], [[0.0, v]])
    traj = integrate(pull, y0, (0.0, period), period / 2000, "rk4")
    gap = float(np.linalg.norm(traj.y[-1, 0, 0] - y0[0, 0]))
    ck.expect(gap < 1e-6 * r, "the orbit closes after one period 2π sqrt(r³/GM)",
              f"it misses its start by {gap:.3g} m")
