"""Case data of notebook 14's checks (:mod:`course_lib.check.nb14`) and what the usual
mistakes make of them.

The cases break shortcuts: quaternions that are not unit and turn about tilted axes, boxes
whose sides differ and come in every order, turned about tilted axes, contacts off the
centre on tilted surfaces, spins whose moments are not sorted and steps long enough that a
fixed-point iteration diverges, and contact points that do not slide at all. Imports NumPy
and the core.
"""

from __future__ import annotations

import numpy as np

from ..rigid import free, inertia
from ..rigid import quaternion as quat

SEED = 1414


def _normalize(q):
    return q / np.linalg.norm(q)


def _pure(v):
    return np.concatenate(([0.0], v))


def rotation(axis, angle) -> np.ndarray:
    return quat.to_matrix(quat.from_axis_angle(axis, angle))


def quaternion_cases():
    rng = np.random.default_rng(SEED)
    yield "identity, ω = (0, 0, 2) rad/s, Δt = 0.1 s", quat.IDENTITY.copy(), np.array([0.0, 0.0, 2.0]), 0.1
    for k in range(3):
        q = _normalize(rng.normal(size=4))
        yield f"a turned body ({k + 1}), Δt = 0.05 s", q, rng.normal(size=3) * 3.0, 0.05
    q = 1.03 * _normalize(rng.normal(size=4))
    yield "a quaternion that drifted to length 1.03, Δt = 0.02 s", q, rng.normal(size=3) * 5.0, 0.02


def quaternion_mistakes(q, omega, dt) -> dict:
    raw = q + 0.5 * dt * quat.multiply(_pure(omega), q)
    xyzw = quat.step(q[[3, 0, 1, 2]], omega, dt)[[1, 2, 3, 0]]
    return {
        ("your quaternion is not of length 1", "renormalise: divide by its length "
         "np.linalg.norm(q) after the step, or |q| grows every step and R(q) stops being a "
         "rotation"): raw,
        ("the order of the product matters: the world ω multiplies from the left",
         "(0, ω) ⊗ q, not q ⊗ (0, ω) (that one takes ω in the body frame); check the sign "
         "of the cross product in your product too"):
            _normalize(q + 0.5 * dt * quat.multiply(q, _pure(omega))),
        "dq/dt = ½ (0, ω) ⊗ q: you left out the ½": _normalize(q + dt * quat.multiply(_pure(omega), q)),
        "the step adds ½ Δt (0, ω) ⊗ q to q: check its sign": quat.step(q, -omega, dt),
        "q is stored (w, x, y, z): the scalar part comes first, q[0]": xyzw,
        "that is the exact rotation by |ω|Δt (the exponential map); this exercise asks for "
        "the explicit step q + ½ Δt (0, ω) ⊗ q, then renormalised":
            _normalize(quat.multiply(quat.from_rotvec(dt * omega), q)),
    }


def box_cases():
    rng = np.random.default_rng(SEED + 1)
    yield "0.5 kg, sides (0.3, 0.2, 0.1) m, not turned", 0.5, np.array([0.3, 0.2, 0.1]), np.eye(3)
    for sides in ([0.1, 0.3, 0.2], [0.2, 0.1, 0.4], [0.05, 0.25, 0.6]):
        R = rotation(rng.normal(size=3), rng.uniform(0.5, 2.5))
        mass = float(rng.uniform(0.2, 3.0))
        yield f"{mass:.2f} kg, sides {tuple(sides)} m, turned", mass, np.array(sides), R


def box_mistakes(mass, sides, R, moments) -> dict:
    a, b, c = sides

    def world(m):
        return R @ np.diag(m) @ R.T

    return {
        ("that is the body-frame tensor: the box is turned",
         "the world tensor is R I_body Rᵀ, with I_body = diag(...)"): np.diag(moments),
        "R I Rᵀ, not Rᵀ I R: R maps body coordinates to world coordinates": R.T @ np.diag(moments) @ R,
        "R * D * R.T multiplies element by element: use @, the matrix product":
            R * np.diag(moments) * R.T,
        "that is the inverse tensor I⁻¹: return I itself": np.linalg.inv(world(moments)),
        ("I_xx sums the squares of the two sides *across* the x axis",
         "I_xx = m (b² + c²)/12, with b, c the sides along y and z"):
            world(mass / 12 * np.array([a * a + b * b, b * b + c * c, a * a + c * c])),
        ("I_xx sums the squares of the two sides across the x axis, not the x side's own",
         "I_xx = m (b² + c²)/12, with b, c the sides along y and z"):
            world(mass / 12 * np.array([a * a, b * b, c * c])),
        "the sides are full lengths, so the factor is m/12; m/3 is for half-sides":
            world(mass / 3 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])),
        "a solid box has m/12 (b² + c²); you left out the 1/12":
            world(mass * np.array([b * b + c * c, a * a + c * c, a * a + b * b])),
        "sort nothing: each side belongs to its own body axis":
            world(inertia.box_moments(mass, np.sort(sides))),
        "sort nothing: each side belongs to its own body axis, in the order given":
            world(inertia.box_moments(mass, np.sort(sides)[::-1])),
    }


def impulse_cases():
    rng = np.random.default_rng(SEED + 2)
    for k, (e, normal) in enumerate(((0.5, [0.0, 1.0, 0.0]), (0.0, [0.3, 1.0, -0.2]),
                                     (1.0, [-0.5, 0.8, 0.4]), (0.3, [0.2, 0.6, 0.9]))):
        n = np.array(normal) / np.linalg.norm(normal)
        mass = float(rng.uniform(0.5, 4.0))
        R = rotation(rng.normal(size=3), rng.uniform(0.3, 2.0))
        inv_I = inertia.world_inverse(R, inertia.box_moments(mass, rng.uniform(0.1, 0.6, 3)))
        r = rng.normal(size=3) * 0.2
        r -= (0.3 + abs(r @ n)) * n                        # the contact point is below the centre
        v = rng.normal(size=3) - 2.0 * n
        yield f"case {k + 1}: e = {e}, tilted normal" if k else "case 1: e = 0.5, ground", \
            mass, inv_I, r, n, v, rng.normal(size=3) * 3.0, e
    n = np.array([0.0, 1.0, 0.0])
    yield "a point moving away from the surface", 1.0, np.eye(3) * 20.0, np.array([0.1, -0.2, 0.0]), n, \
        np.array([0.3, 0.5, 0.0]), np.zeros(3), 0.5


def impulse_mistakes(mass, inv_I, r, n, v, omega, e) -> dict:
    u_n = float((v + np.cross(omega, r)) @ n)
    rn = np.cross(r, n)
    k_n = 1.0 / mass + float(np.cross(inv_I @ rn, r) @ n)
    if u_n >= 0:
        return {"the point already moves away from the surface (u_n ≥ 0): no impulse":
                -(1 + e) * u_n / k_n,
                "the point already moves away from the surface (u_n ≥ 0): no impulse; "
                "abs(u_n) hides the direction": (1 + e) * abs(u_n) / k_n}
    return {
        ("a body that hits off its centre also starts to spin, which softens the blow",
         "the denominator is 1/m + n·((I⁻¹(r × n)) × r): you left out the rotational term"):
            -(1 + e) * u_n * mass,
        "the contact point moves with v + ω × r, not with v alone": max(-(1 + e) * float(v @ n) / k_n, 0.0),
        "the contact point moves with v + ω × r, not v + r × ω":
            -(1 + e) * float((v + np.cross(r, omega)) @ n) / k_n,
        "restitution: u_n' = −e u_n, so the impulse is (1 + e) times the approach, not e": -e * u_n / k_n,
        "the impulse pushes the body out: it is positive along the normal": (1 + e) * u_n / k_n,
        ("K_n > 0 always (an impulse along n speeds the point up along n): check the order "
         "of your cross products", "K_n = 1/m + n·((I⁻¹(r × n)) × r) = 1/m + (r × n)·I⁻¹(r × n)"):
            -(1 + e) * u_n / (2.0 / mass - k_n),
        "I⁻¹ is the inverse inertia, given as inv_inertia: use it as it is, do not invert it":
            -(1 + e) * u_n / (1.0 / mass + float(np.cross(np.linalg.inv(inv_I) @ rn, r) @ n)),
    }


def spin_cases():
    """Body angular momenta, principal moments in no particular order, and steps from
    short (Δt|Ω| = 0.05) to long enough that a fixed-point iteration diverges."""
    rng = np.random.default_rng(SEED + 8)
    for k, turn in enumerate((0.05, 0.3, 0.6, 2.5)):
        moments = rng.permutation([1.0, 2.0, 3.0]) * rng.uniform(0.5, 2.0)
        L = moments * rng.normal(size=3)
        dt = turn / float(np.linalg.norm(L / moments))
        yield f"spin {k + 1}: moments {np.round(moments, 3).tolist()}, Δt|Ω| = {turn}", L, moments, dt, turn


def midpoint_mistakes(L, moments, dt) -> dict:
    g = free.gyroscopic(L, moments)
    jac = np.eye(3) - 0.5 * dt * (quat.hat(L) / moments - quat.hat(L / moments))
    return {
        ("that is one explicit Euler step: the midpoint rule is implicit",
         "solve L₁ = L + Δt g(L_m) for L₁ by Newton's method, L_m = ½(L + L₁)"): L + dt * g,
        ("that is the explicit midpoint rule (RK2): of order 2 too, but it keeps neither |L| nor E",
         "the implicit midpoint rule solves L₁ = L + Δt g(½(L + L₁)) for L₁, by Newton's method"):
            L + dt * free.gyroscopic(L + 0.5 * dt * g, moments),
        "that is backward Euler (g at L₁): the midpoint rule takes g at L_m = ½(L + L₁)":
            free.implicit_solve(L, moments, dt, 1.0),
        "Euler's equations in the body frame are dL/dt = L × Ω, not Ω × L":
            free.implicit_solve(L, moments, -dt, 0.5),
        "Ω = L / I, element by element, not L · I": free.implicit_solve(L, 1.0 / moments, dt, 0.5),
        ("one Newton iteration is not enough: repeat until the update is below 1e-12 |L|",
         "L₁ ← L₁ − J⁻¹ r(L₁) with r = L₁ − L − Δt g(L_m), J = 1 − ½Δt G(L_m), until |update| < 1e-12 |L|"):
            L + np.linalg.solve(jac, dt * g),
    }


def friction_cases():
    """Contacts just after their normal impulse ``j_n``: a ball whose small slip friction
    stops, a ball that slides on, box corners on tilted surfaces that slide in a slanted
    direction while still approaching (``u`` has a normal part), a rolling ball (no slip at
    all: ``t = u_t/|u_t|`` is 0/0) and a contact without normal impulse."""
    rng = np.random.default_rng(SEED + 4)
    up, ball = np.array([0.0, 1.0, 0.0]), np.eye(3) / (0.4 * 1.0 * 0.1**2)
    low = np.array([0.0, -0.1, 0.0])
    yield "a ball that slips a little: friction stops it", 1.0, ball, low, up, \
        np.array([0.3, 0.0, 0.1]), np.array([0.0, 1.0, 0.0]), 1.0, 0.5
    yield "a ball that slides fast: friction takes μ j_n", 1.0, ball, low, up, \
        np.array([2.0, 0.0, 0.0]), np.zeros(3), 0.01, 0.3
    for k, (normal, mu) in enumerate((([0.3, 1.0, -0.2], 0.8), ([-0.5, 0.8, 0.4], 0.2))):
        n = np.array(normal) / np.linalg.norm(normal)
        mass = float(rng.uniform(0.5, 4.0))
        R = rotation(rng.normal(size=3), rng.uniform(0.3, 2.0))
        inv_I = inertia.world_inverse(R, inertia.box_moments(mass, rng.uniform(0.1, 0.6, 3)))
        r = rng.normal(size=3) * 0.2
        r -= (0.3 + abs(r @ n)) * n
        yield f"a box corner on a tilted surface ({k + 1}), μ = {mu}", mass, inv_I, r, n, \
            rng.normal(size=3) - 0.5 * n, rng.normal(size=3), float(rng.uniform(0.5, 2.0)), mu
    yield "a rolling ball that also approaches: no slip", 1.0, ball, low, up, \
        np.array([1.0, -0.3, 0.0]), np.array([0.0, 0.0, -10.0]), 0.5, 0.5
    yield "a sliding point without normal impulse", 1.0, ball, low, up, \
        np.array([1.0, 0.0, 0.0]), np.zeros(3), 0.0, 0.5


def friction_mistakes(mass, inv_I, r, n, v, omega, j_n, mu) -> dict:
    def impulse(u, k_of, cap=True):
        u_t = u - (u @ n) * n
        speed = float(np.linalg.norm(u_t))
        if speed == 0.0:
            return np.zeros(3)
        t = u_t / speed
        size = speed / k_of(t)
        return -(min(size, mu * j_n) if cap else size) * t

    def k_t(t):
        rt = np.cross(r, t)
        return 1.0 / mass + rt @ inv_I @ rt

    u = v + np.cross(omega, r)
    out = {
        ("the point also turns: an impulse at r spins the body, so K_t has a rotational term",
         "K_t = 1/m + t·((I⁻¹(r × t)) × r), like K_n along t instead of n"):
            impulse(u, lambda t: 1.0 / mass),
        "K_t is taken along the slip direction t, not along the normal n":
            impulse(u, lambda t: 1.0 / mass + np.cross(r, n) @ inv_I @ np.cross(r, n)),
        "the contact point moves with v + ω × r, not with v alone": impulse(v, k_t),
        "Coulomb's law caps the impulse at μ j_n: take the smaller of the two": impulse(u, k_t, cap=False),
        "friction opposes the sliding: the impulse points along −t": -impulse(u, k_t),
    }
    u_t = u - (u @ n) * n
    if np.linalg.norm(u_t) > 0:
        t = u_t / np.linalg.norm(u_t)
        out["friction takes μ j_n only while the point keeps sliding: an impulse that stops "
            "it is smaller, min(|u_t|/K_t, μ j_n)"] = -mu * j_n * t
        out["the cap μ j_n is on the length of J_t (the friction cone), not on each component"] = \
            np.clip(-float(np.linalg.norm(u_t)) / k_t(t) * t, -mu * j_n, mu * j_n)
        # the normal part of u left in: t tilts out of the surface
        speed = float(np.linalg.norm(u))
        out["friction acts in the surface: remove the normal part, u_t = u − (u·n) n"] = \
            -min(speed / k_t(u / speed), mu * j_n) * u / speed
    return out
