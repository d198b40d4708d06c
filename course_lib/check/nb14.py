"""Checks for notebook 14, rigid bodies: the quaternion step, a box's inertia, the implicit
midpoint step of Euler's equations (and the order of its period error), the collision
impulse, and the friction impulse (and the ball that rolls at 5/7 of its launch speed).

Each answer may call no ``course_lib`` function (``@exercise(allow=())``): the prompts
hand over nothing but NumPy. The case data and the usual mistakes are in
:mod:`course_lib.check._nb14_cases`. The checks of the two simulation exercises run the
answer many times: over two periods of the flip at 50, 100 and 200 steps per period, and
for every step of a ball sliding into rolling.
"""

from __future__ import annotations

import numpy as np

from ..lessons import nb14_rigid_bodies as lesson
from ..rigid import contact, exact, free, inertia
from ..rigid import quaternion as quat
from . import Checker, exercise
from . import _nb14_cases as cases
from .tolerance import blown_up, precision_rtol

EPS = float(np.finfo(float).eps)


@exercise(allow=())
def quaternion_step(ck: Checker, func) -> None:
    """``func(q, omega, dt) -> (4,)``: ``normalize(q + ½ Δt (0, ω) ⊗ q)``, ω in the world frame."""
    right = True
    for what, q, omega, dt in cases.quaternion_cases():
        expected = quat.step(q, omega, dt)
        got = np.asarray(func(q.copy(), omega.copy(), dt), dtype=float)
        if blown_up(ck, got, what, run=False):
            right = False
            continue
        right &= ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-12,
                          mistakes=cases.quaternion_mistakes(q, omega, dt),
                          hint=("write out the product (a, u)⊗(b, v) of Section 1 for (0, ω) ⊗ q",
                                "compute q + ½ Δt (0, ω) ⊗ q with the product (a, u)⊗(b, v) = "
                                "(ab − u·v, a v + b u + u × v), then divide by its length"))
    if right:                               # Section 1's spin: the lag is N(|ω|Δt − 2 atan(|ω|Δt/2))
        q0, omega = quat.from_axis_angle([1.0, 1.0, 0.0], 0.7), np.array([0.0, 10.0, 0.0])
        dt, steps = 0.01, 800
        q = q0.copy()
        for _ in range(steps):
            q = np.asarray(func(q, omega.copy(), dt), dtype=float)
        gap = quat.multiply(q, quat.conjugate(quat.multiply(quat.from_rotvec(omega * steps * dt), q0)))
        lag = 2 * np.arcsin(min(float(np.linalg.norm(gap[1:])), 1.0))
        theory = steps * (0.1 - 2 * np.arctan(0.05))
        ck.expect(abs(lag - theory) < 1e-9,
                  f"{steps} steps at 10 rad/s, Δt = 0.01 s: {lag:.6f} rad behind the exact rotation, "
                  f"{steps} (|ω|Δt − 2 atan(|ω|Δt/2)) = {theory:.6f} rad", f"lag {lag:.6f} rad")


@exercise(allow=())
def box_inertia(ck: Checker, func) -> None:
    """``func(mass, sides, R) -> (3, 3)``: the world inertia tensor ``R I_body Rᵀ`` of a box."""
    for what, mass, sides, R in cases.box_cases():
        moments = inertia.box_moments(mass, sides)
        expected = inertia.world_tensor(R, moments)
        got = np.asarray(func(mass, sides.copy(), R.copy()), dtype=float)
        if blown_up(ck, got, what, run=False):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-14 * mass,
                 mistakes=cases.box_mistakes(mass, sides, R, moments),
                 hint=("check the body tensor on the unturned box first, then the turn",
                       "I_body = m/12 · diag(b² + c², a² + c², a² + b²), then R I_body Rᵀ"))
        if got.shape == (3, 3):
            ck.close(got, got.T, f"{what}: symmetric", rtol=1e-12, atol=1e-14 * mass,
                     hint="R D Rᵀ is symmetric for any rotation R and diagonal D")


@exercise(allow=())
def midpoint_step(ck: Checker, func) -> None:
    """``func(L, moments, dt) -> (3,)``: ``L₁ = L + Δt L_m × (L_m / I)``, ``L_m = ½(L + L₁)``,
    solved to round-off; then its period error at N = 50, 100, 200 steps per period."""
    right = True
    for what, L, moments, dt, turn in cases.spin_cases():
        expected = free.implicit_solve(L, moments, dt, 0.5)
        long_step = ("at a step this long a fixed-point iteration L₁ ← L + Δt g(L_m) does not "
                     "converge: use Newton's method")
        nudge = long_step if turn > 1 else ("compare your L₁ with the formula: does "
                                            "L₁ − L − Δt L_m × Ω_m vanish?")
        with np.errstate(all="ignore"):
            got = np.asarray(func(L.copy(), moments.copy(), dt), dtype=float)
        if blown_up(ck, got, what, run=False, hint=nudge):
            right = False
            continue
        size = np.linalg.norm(L)
        if got.shape == (3,) and 1e-10 * size < np.linalg.norm(got - expected) < 1e-4 * size:
            nudge = long_step if turn > 1 else ("close, but not solved to round-off: iterate "
                                                "until the update is below 1e-12 |L|")
        right &= ck.close(got, expected, what, rtol=1e-10, atol=1e-12 * size,
                          mistakes=cases.midpoint_mistakes(L, moments, dt), hint=nudge)
    if right:
        _period_study(ck, func)


def _period_study(ck: Checker, func) -> None:
    """Run the answer over 2.2 periods of the notebook's flip at N steps per period; its
    period error against 4K(m)/λ must be the library's and fall as 1/N²."""
    moments, omega0 = lesson.spin_moments(), np.array(lesson.SPIN["omega0"])
    T = exact.period(moments, omega0)
    reference = lesson.period_errors((50, 100, 200), ("implicit_midpoint",))["implicit_midpoint"]
    errors, drift = [], 0.0
    for n in (50, 100, 200):
        L = np.empty((int(2.2 * n) + 1, 3))
        L[0] = moments * omega0
        with np.errstate(all="ignore"):
            for k in range(len(L) - 1):
                L[k + 1] = func(L[k].copy(), moments.copy(), T / n)
        if blown_up(ck, L, f"the flip at N = {n} steps per period"):
            return
        energy = 0.5 * np.sum(L * L / moments, axis=1)
        drift = max(drift, float(np.abs(np.linalg.norm(L, axis=1) / np.linalg.norm(L[0]) - 1).max()),
                    float(np.abs(energy / energy[0] - 1).max()))
        try:
            errors.append(exact.measured_period(T / n * np.arange(len(L)), L / moments, 1) / T - 1)
        except ValueError:
            ck.expect(False, f"the flip at N = {n} steps per period", "Ω_y never changed sign twice")
            return
    errors = np.array(errors)
    order = float(np.log2(errors[1] / errors[2]))
    listed = ", ".join(f"{e:+.1e}" for e in errors)
    ck.close(errors, reference, f"period error at N = 50, 100, 200 steps per period: {listed}",
             rtol=1e-6, atol=1e-9)
    ck.expect(abs(order - 2.0) < 0.1, f"observed order of the period error {order:.2f} (the midpoint "
              "rule is of order 2)", f"order {order:.2f}")
    # 16 eps per step over 440 steps, as the library's own midpoint runs are held to
    ck.expect(drift < 16 * EPS * 440 + 1e-10, "|L| and E kept to round-off over the runs",
              f"they drifted by {drift:.1e}", hint="solve each step to round-off")


@exercise(allow=())
def collision_impulse(ck: Checker, func) -> None:
    """``func(mass, inv_inertia, r, normal, v, omega, restitution) -> float``: the normal
    impulse ``j = −(1 + e) u_n / (1/m + n·((I⁻¹(r × n)) × r))``, zero when separating."""
    for what, mass, inv_I, r, n, v, omega, e in cases.impulse_cases():
        expected = float(contact.normal_impulse(mass, inv_I, r, n, v, omega, e))
        got = np.asarray(func(mass, inv_I.copy(), r.copy(), n.copy(), v.copy(), omega.copy(), e),
                         dtype=float)
        if blown_up(ck, got, what, run=False):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-12,
                 mistakes=cases.impulse_mistakes(mass, inv_I, r, n, v, omega, e),
                 hint=("find u_n first, then K_n; print both for the first case",
                       "u_n = (v + ω × r)·n; j = −(1 + e) u_n / K_n while u_n < 0"))


@exercise(allow=())
def friction_impulse(ck: Checker, func) -> None:
    """``func(mass, inv_inertia, r, normal, v, omega, j_n, mu) -> (3,)``: the tangential
    impulse that stops the slip, capped at ``μ j_n``; then a ball sliding into rolling."""
    right = True
    for what, mass, inv_I, r, n, v, omega, j_n, mu in cases.friction_cases():
        expected = contact.friction_impulse(mass, inv_I, r, n, v, omega, j_n, mu)
        with np.errstate(all="ignore"):
            got = np.asarray(func(mass, inv_I.copy(), r.copy(), n.copy(), v.copy(), omega.copy(),
                                  j_n, mu), dtype=float)
        if blown_up(ck, got, what, run=False, hint="when the point does not slide (u_t = 0), "
                    "t = u_t/|u_t| is 0/0: return np.zeros(3) then"):
            right = False
            continue
        right &= ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-12,
                          mistakes=cases.friction_mistakes(mass, inv_I, r, n, v, omega, j_n, mu),
                          hint=("find u_t and t first, then the impulse that stops the slip",
                                "J_t = −min(|u_t| / K_t, μ j_n) t, K_t = 1/m + t·((I⁻¹(r × t)) × r)"))
    if not right:
        return
    for mu in (0.3, 0.1):
        mine, library = lesson.slide_to_roll(func, mu=mu), lesson.slide_to_roll(mu=mu)
        steps = len(mine["v"]) - 1
        what = (f"a ball launched at {mine['v0']:g} m/s, μ = {mu}: rolls from t = "
                f"{mine['t'][mine['k_roll']]:.3f} s (2v₀/(7μg) = {mine['t_roll']:.3f} s) "
                f"at v/v₀ = {mine['v'][-1] / mine['v0']:.12f} (5/7)")
        if blown_up(ck, mine["v"], what):
            return
        ok = mine["k_roll"] == library["k_roll"] and abs(mine["v"][-1] / mine["v_roll"] - 1) < 8 * EPS * steps
        ck.expect(ok, what, "the ball does not settle to rolling at 5/7 v₀ where it should")
