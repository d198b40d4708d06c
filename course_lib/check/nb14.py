"""Checks for notebook 14, rigid bodies: the quaternion step, a box's inertia, the impulse.

Each answer may call no ``course_lib`` function (``@exercise(allow=())``): the prompts
hand over nothing but NumPy. The data break the usual shortcuts: quaternions that are not
unit and turn about tilted axes (so the order of a product shows), boxes whose three sides
differ and come in every order, turned by rotations about tilted axes (so body and world
frames differ), and contacts off the centre of mass on tilted surfaces.
"""

from __future__ import annotations

import numpy as np

from ..rigid import contact, inertia
from ..rigid import quaternion as quat
from . import Checker, exercise
from .tolerance import blown_up, precision_rtol

_SEED = 1414


def _normalize(q):
    return q / np.linalg.norm(q)


def _pure(v):
    return np.concatenate(([0.0], v))


def _quaternion_cases():
    rng = np.random.default_rng(_SEED)
    yield "identity, ω = (0, 0, 2) rad/s, Δt = 0.1 s", quat.IDENTITY.copy(), np.array([0.0, 0.0, 2.0]), 0.1
    for k in range(3):
        q = _normalize(rng.normal(size=4))
        yield f"a turned body ({k + 1}), Δt = 0.05 s", q, rng.normal(size=3) * 3.0, 0.05
    q = 1.03 * _normalize(rng.normal(size=4))
    yield "a quaternion that drifted to length 1.03, Δt = 0.02 s", q, rng.normal(size=3) * 5.0, 0.02


@exercise(allow=())
def quaternion_step(ck: Checker, func) -> None:
    """``func(q, omega, dt) -> (4,)``: ``normalize(q + ½ Δt (0, ω) ⊗ q)``, ω in the world frame."""
    for what, q, omega, dt in _quaternion_cases():
        expected = quat.step(q, omega, dt)
        got = np.asarray(func(q.copy(), omega.copy(), dt), dtype=float)
        if blown_up(ck, got, what, run=False):
            continue
        raw = q + 0.5 * dt * quat.multiply(_pure(omega), q)
        mistakes = {
            ("your quaternion is not of length 1", "renormalise: divide by its length "
             "np.linalg.norm(q) after the step, or |q| grows every step and R(q) stops being a "
             "rotation"): raw,
            ("the order of the product matters: the world ω multiplies from the left",
             "(0, ω) ⊗ q, not q ⊗ (0, ω) (that one takes ω in the body frame); check the sign "
             "of the cross product in your product too"):
                _normalize(q + 0.5 * dt * quat.multiply(q, _pure(omega))),
            "dq/dt = ½ (0, ω) ⊗ q: you left out the ½": _normalize(q + dt * quat.multiply(_pure(omega), q)),
            "that is the exact rotation by |ω|Δt (the exponential map); this exercise asks for "
            "the explicit step q + ½ Δt (0, ω) ⊗ q, then renormalised":
                _normalize(quat.multiply(quat.from_rotvec(dt * omega), q)),
        }
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-12, mistakes=mistakes,
                 hint=("compute q + ½ Δt (0, ω) ⊗ q with the product (a, u)⊗(b, v) = "
                       "(ab − u·v, a v + b u + u × v), then divide by its length",))


def _rotation(axis, angle):
    return quat.to_matrix(quat.from_axis_angle(axis, angle))


def _box_cases():
    rng = np.random.default_rng(_SEED + 1)
    yield "0.5 kg, sides (0.3, 0.2, 0.1) m, not turned", 0.5, np.array([0.3, 0.2, 0.1]), np.eye(3)
    for sides in ([0.1, 0.3, 0.2], [0.2, 0.1, 0.4], [0.05, 0.25, 0.6]):
        R = _rotation(rng.normal(size=3), rng.uniform(0.5, 2.5))
        mass = float(rng.uniform(0.2, 3.0))
        yield f"{mass:.2f} kg, sides {tuple(sides)} m, turned", mass, np.array(sides), R


@exercise(allow=())
def box_inertia(ck: Checker, func) -> None:
    """``func(mass, sides, R) -> (3, 3)``: the world inertia tensor ``R I_body Rᵀ`` of a box."""
    for what, mass, sides, R in _box_cases():
        moments = inertia.box_moments(mass, sides)
        expected = inertia.world_tensor(R, moments)
        got = np.asarray(func(mass, sides.copy(), R.copy()), dtype=float)
        if blown_up(ck, got, what, run=False):
            continue
        a, b, c = sides

        def world(m, R=R):
            return R @ np.diag(m) @ R.T

        mistakes = {
            ("that is the body-frame tensor: the box is turned",
             "the world tensor is R I_body Rᵀ, with I_body = diag(...)"): np.diag(moments),
            "R I Rᵀ, not Rᵀ I R: R maps body coordinates to world coordinates":
                R.T @ np.diag(moments) @ R,
            ("I_xx sums the squares of the two sides *across* the x axis",
             "I_xx = m (b² + c²)/12, with b, c the sides along y and z"):
                world(mass / 12 * np.array([a * a + b * b, b * b + c * c, a * a + c * c])),
            "the sides are full lengths, so the factor is m/12; m/3 is for half-sides":
                world(mass / 3 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])),
            "a solid box has m/12 (b² + c²); you left out the 1/12":
                world(mass * np.array([b * b + c * c, a * a + c * c, a * a + b * b])),
            "sort nothing: each side belongs to its own body axis":
                world(inertia.box_moments(mass, np.sort(sides))),
            "sort nothing: each side belongs to its own body axis, in the order given":
                world(inertia.box_moments(mass, np.sort(sides)[::-1])),
        }
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-14 * mass,
                 mistakes=mistakes, hint=("I_body = m/12 · diag(b² + c², a² + c², a² + b²), "
                                          "then turn it to the world frame",))
        if got.shape == (3, 3):
            ck.close(got, got.T, f"{what}: symmetric", rtol=1e-12, atol=1e-14 * mass,
                     hint="R D Rᵀ is symmetric for any rotation R and diagonal D")


def _impulse_cases():
    rng = np.random.default_rng(_SEED + 2)
    for k, (e, normal) in enumerate(((0.5, [0.0, 1.0, 0.0]), (0.0, [0.3, 1.0, -0.2]),
                                     (1.0, [-0.5, 0.8, 0.4]), (0.3, [0.2, 0.6, 0.9]))):
        n = np.array(normal) / np.linalg.norm(normal)
        mass = float(rng.uniform(0.5, 4.0))
        R = _rotation(rng.normal(size=3), rng.uniform(0.3, 2.0))
        inv_I = inertia.world_inverse(R, inertia.box_moments(mass, rng.uniform(0.1, 0.6, 3)))
        r = rng.normal(size=3) * 0.2
        r -= (0.3 + abs(r @ n)) * n                        # the contact point is below the centre
        v = rng.normal(size=3) - 2.0 * n
        yield f"case {k + 1}: e = {e}, tilted normal" if k else "case 1: e = 0.5, ground", \
            mass, inv_I, r, n, v, rng.normal(size=3) * 3.0, e
    n = np.array([0.0, 1.0, 0.0])
    yield "a point moving away from the surface", 1.0, np.eye(3) * 20.0, np.array([0.1, -0.2, 0.0]), n, \
        np.array([0.3, 0.5, 0.0]), np.zeros(3), 0.5


@exercise(allow=())
def collision_impulse(ck: Checker, func) -> None:
    """``func(mass, inv_inertia, r, normal, v, omega, restitution) -> float``: the normal
    impulse ``j = −(1 + e) u_n / (1/m + n·((I⁻¹(r × n)) × r))``, zero when separating."""
    for what, mass, inv_I, r, n, v, omega, e in _impulse_cases():
        expected = float(contact.normal_impulse(mass, inv_I, r, n, v, omega, e))
        got = np.asarray(func(mass, inv_I.copy(), r.copy(), n.copy(), v.copy(), omega.copy(), e),
                         dtype=float)
        if blown_up(ck, got, what, run=False):
            continue
        u_n = float((v + np.cross(omega, r)) @ n)
        rn = np.cross(r, n)
        k_n = 1.0 / mass + float(np.cross(inv_I @ rn, r) @ n)
        mistakes = {
            ("a body that hits off its centre also starts to spin, which softens the blow",
             "the denominator is 1/m + n·((I⁻¹(r × n)) × r): you left out the rotational term"):
                -(1 + e) * u_n * mass,
            "the contact point moves with v + ω × r, not with v alone":
                max(-(1 + e) * float(v @ n) / k_n, 0.0),
            "restitution: u_n' = −e u_n, so the impulse is (1 + e) times the approach, not e":
                -e * u_n / k_n,
            "the impulse pushes the body out: it is positive along the normal": (1 + e) * u_n / k_n,
            "I⁻¹ is the inverse inertia, given as inv_inertia: use it as it is, do not invert it":
                -(1 + e) * u_n / (1.0 / mass + float(np.cross(np.linalg.inv(inv_I) @ rn, r) @ n)),
        }
        if u_n >= 0:
            mistakes = {"the point already moves away from the surface (u_n ≥ 0): no impulse":
                        -(1 + e) * u_n / k_n}
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-10), atol=1e-12,
                 mistakes=mistakes, hint=("u_n = (v + ω × r)·n; j = −(1 + e) u_n / K_n while u_n < 0",))
