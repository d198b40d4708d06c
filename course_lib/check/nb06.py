"""Checks for notebook 06, forces.

An answer may call no course_lib function (:mod:`course_lib.check.policy`); the two
exercises that ask for a formula (terminal speed, circular speed) also refuse
``scipy.integrate`` and a step-by-step simulation written by hand (more Python lines than
a formula runs, :func:`~course_lib.check._answers.call_analysis`). Hints name the slip the
answer reproduces, or what the data that broke it show.
"""

from __future__ import annotations

import numpy as np

from .. import collisions, forces
from ..integrators import integrate
from ..systems import newtonian, stack_state
from . import Checker, exercise
from ._answers import call_analysis, one_number
from .tolerance import blown_up, escalate, precision_rtol


def _drag_cases():
    rng = np.random.default_rng(6)
    v3, v2 = rng.normal(size=(4, 3)), rng.normal(size=(5, 2))
    return [("four particles in 3D, b = 0.5, still air", v3, 0.5, np.zeros(3)),
            ("b = 2, wind (3, 0, -1) m/s", v3, 2.0, np.array([3.0, 0.0, -1.0])),
            ("five particles in 2D, b = 0.1, wind (-4, 1) m/s", v2, 0.1, np.array([-4.0, 1.0])),
            ("one particle moving with the wind: no drag", np.array([[1.0, 0.0]]), 1.0,
             np.array([1.0, 0.0]))]


@exercise(allow=())
def drag_force(ck: Checker, drag) -> None:
    """``drag(v, b, wind)``: linear drag ``-b (v - wind)`` on velocities ``(N, d)``."""
    for what, v, b, wind in _drag_cases():
        v_in = v.copy()
        got = drag(v_in, b, wind.copy())
        if not np.array_equal(v_in, v):
            ck.expect(False, what, "your function changed its input v",
                      hint="v -= wind (or v *= ...) overwrites the particles' velocities: "
                           "compute a new array, -b * (v - wind)")
            continue
        expected = -b * (v - wind)
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12, mistakes={
            "sign error: drag opposes the motion relative to the air": b * (v - wind),
            "you forgot the wind: drag acts on the velocity relative to the air": -b * v,
            "the relative velocity is v - wind, not v + wind": -b * (v + wind),
            "drag acts on every component of v - wind, a vector, not on its length":
                -b * np.linalg.norm(v - wind, axis=1, keepdims=True) * np.ones(v.shape[1]),
        })


#: Lines of Python a formula needs at most (a simulation runs thousands).
FORMULA_LINES = 200
SIMULATED = ("the exercise asks for the speed from the force balance, a formula: your "
             "function steps a simulation instead")


@exercise(allow=(), forbid=("scipy.integrate",))
def terminal_speed(ck: Checker, speed) -> None:
    """``speed(m, g, b, c)``: the speed at which ``b v + c v²`` balances the weight ``m g``."""
    for m, g, b, c in [(1.0, 9.81, 0.5, 0.05), (0.2, 9.81, 0.05, 0.0), (3.0, 1.62, 0.0, 0.2),
                       (0.01, 9.81, 1e-3, 1e-4), (70.0, 9.81, 1e-4, 0.25),
                       (1.0, 9.81, 0.5, 1e-12)]:
        what = f"m = {m} kg, g = {g} m/s², b = {b} kg/s, c = {c} kg/m"
        ok, got = call_analysis(ck, what, FORMULA_LINES, SIMULATED, speed, m, g, b, c)
        if not ok:
            if "lines of Python" in ck.failed[-1]:
                break                   # a simulation: one case says it, the rest would repeat
            continue
        if blown_up(ck, got, what, run=False, hint=escalate(
                "with c = 0 (or b = 0) your formula divides by zero: rewrite the root so that "
                "neither b nor c is in a denominator",
                "multiply (-b + √(b² + 4 c m g)) / (2 c) by its conjugate: 2 m g / (b + √(b² "
                "+ 4 c m g))")):
            continue
        value = one_number(ck, what, got, "a speed in m/s")
        if value is None:
            continue
        disc = np.sqrt(b * b + 4 * c * m * g)
        exact = 2 * m * g / (b + disc)
        with np.errstate(divide="ignore", invalid="ignore"):
            mistakes = {
                "the other root of c v² + b v - m g = 0 is negative: take the positive one":
                    -(b + disc) / (2 * c) if c else np.nan,
                "you forgot the mass: the weight is m g": 2 * g / (b + np.sqrt(b * b + 4 * c * g)),
                escalate("with c this small, -b + √(b² + 4 c m g) subtracts two nearly equal numbers and "
                 "loses its digits", "rewrite the root without the subtraction: "
                 "2 m g / (b + √(b² + 4 c m g))"): (-b + disc) / (2 * c) if c else np.nan,
            }
        if c:
            mistakes["that is the quadratic drag alone, √(m g / c); the linear drag b v adds to "
                     "it"] = np.sqrt(m * g / c)
        if b:
            mistakes["that is the linear drag alone, m g / b; the quadratic drag c v² adds to "
                     "it"] = m * g / b
        ck.close(value, exact, what, rtol=precision_rtol(got, 1e-9), mistakes=mistakes)


@exercise(allow=(), forbid=("scipy.integrate",))
def circular_speed(ck: Checker, speed) -> None:
    """``speed(G, M, r)``: speed of a circular orbit of radius r about a mass M, ``sqrt(GM/r)``."""
    speeds = {}
    for G, M, r in [(1.0, 1.0, 1.0), (1.0, 4.0, 2.0), (6.674e-11, 5.972e24, 6.771e6),
                    (2.5, 0.3, 0.04)]:
        what = f"G = {G:g}, M = {M:g}, r = {r:g}"
        ok, got = call_analysis(ck, what, FORMULA_LINES, SIMULATED.replace("from the force "
                                "balance", "from the balance of forces on the orbit"),
                                speed, G, M, r)
        if not ok:
            if "lines of Python" in ck.failed[-1]:
                break                   # a simulation: one case says it, the rest would repeat
            continue
        if blown_up(ck, got, what, run=False):
            continue
        value = one_number(ck, what, got, "a speed")
        if value is None:
            continue
        speeds[G, M, r] = value
        ck.close(value, np.sqrt(G * M / r), what, rtol=precision_rtol(got, 1e-9), mistakes={
            "take the square root: v² / r = G M / r²": G * M / r,
            "sqrt(2 G M / r) is the escape speed, not the circular one": np.sqrt(2 * G * M / r),
            "the centripetal acceleration is v² / r, so v = √(G M / r), not G M / r²": G * M / r**2,
            "upside down: v = √(G M / r)": np.sqrt(r / (G * M)),
            "you left out G (the first cases have G = 1): v = √(G M / r)": np.sqrt(M / r),
        })
    # Does the orbit close? Fly a test mass around a fixed centre for one Kepler period.
    G, M, r = 1.0, 4.0, 2.0
    if (G, M, r) not in speeds:
        return
    v = speeds[G, M, r]
    period = 2 * np.pi * np.sqrt(r**3 / (G * M))
    pull = newtonian(forces.attractor((0.0, 0.0), G * M, softening=0.0), mass=1.0)
    y0 = stack_state([[r, 0.0]], [[0.0, v]])
    traj = integrate(pull, y0, (0.0, period), period / 2000, "rk4", blowup_bound=1e3)
    if not traj.stable:
        ck.expect(False, "the orbit closes after one period 2π sqrt(r³/GM)",
                  f"your test body escaped: {traj.message}")
        return
    gap = float(np.linalg.norm(traj.y[-1, 0, 0] - y0[0, 0]))
    ck.expect(gap < 1e-6 * r, "the orbit closes after one period 2π sqrt(r³/GM)",
              f"it misses its start by {gap:.3g} m")


class _Bodies(np.ndarray):
    """Positions that notice being taken apart one body at a time (a Python loop)."""

    looped = False

    def __iter__(self):
        _Bodies.looped = True
        return super().__iter__()

    def __getitem__(self, key):
        if isinstance(key, int | np.integer) or (
                isinstance(key, tuple) and key and isinstance(key[0], int | np.integer)):
            _Bodies.looped = True
        return super().__getitem__(key)


def _nbody_cases():
    rng = np.random.default_rng(66)
    yield "5 bodies in 2D, G = 1, softening 0.1", rng.normal(size=(5, 2)), rng.uniform(0.5, 2, 5), 1.0, 0.1
    yield ("7 bodies in 3D, G = 6.674e-11, no softening", rng.normal(size=(7, 3)) * 1e3,
           rng.uniform(1e10, 1e12, 7), 6.674e-11, 0.0)
    x = rng.normal(size=(4, 2))
    x[3] = x[0]                                      # two bodies at the same point
    yield "4 bodies in 2D, two of them at one point, softening 0.5", x, np.ones(4), 2.0, 0.5


def _nbody_mistakes(x, m, G, eps, expected) -> dict:
    r = x[:, None, :] - x[None, :, :]
    d2 = np.sum(r * r, axis=-1)
    np.fill_diagonal(d2, np.inf)

    def pairs(den, weight=m[:, None] * m[None, :]):
        return -G * np.einsum("ij,ijk->ik", weight / den, r)

    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            "sign error: gravity pulls body i TOWARDS j, along x_j - x_i": -expected,
            "that is the acceleration; the force is m_i times it": expected / m[:, None],
            "each pair's force is G m_i m_j ...: you left out m_j":
                pairs((d2 + eps**2) ** 1.5, m[:, None] * np.ones_like(d2)),
            "soften with the square: (|r|² + ε²)^{3/2}, not (|r|² + ε)^{3/2}":
                pairs((d2 + eps) ** 1.5),
            "soften inside: (|r|² + ε²)^{3/2}, not (|r| + ε)³": pairs((np.sqrt(d2) + eps) ** 3),
            "soften inside: (|r|² + ε²)^{3/2}, not |r|³ + ε³": pairs(d2**1.5 + eps**3),
            "r_ij/|r|³ is the inverse-square law; dividing r_ij by |r|² gives 1/r":
                pairs(d2 + eps**2),
            "you left out the softening ε": pairs(d2**1.5),
            "each body has its own mass: you gave every body the same one":
                pairs((d2 + eps**2) ** 1.5, np.full_like(d2, m.mean() ** 2)),
        }


@exercise(allow=())
def nbody_force(ck: Checker, func) -> None:
    """``func(x, mass, G, softening)``: softened gravity of every body on every other."""
    for what, x, m, G, eps in _nbody_cases():
        expected = forces.nbody_gravity_force(x, m, G, eps)
        _Bodies.looped = False
        got = func(x.view(_Bodies), m.copy(), G, eps)
        if _Bodies.looped:
            ck.expect(False, what, "your function loops over the bodies one at a time",
                      hint=escalate("work on every pair at once with broadcasting, no loop over bodies",
                            "r = x[:, None, :] - x[None, :, :] holds every pair at once, "
                            "shape (N, N, d)"))
            continue
        got = np.asarray(got)
        if blown_up(ck, got, what, run=False):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-9),
                 atol=1e-12 * float(np.abs(expected).max()),
                 mistakes=_nbody_mistakes(x, m, G, eps, expected))
        if got.shape == expected.shape:
            ck.close(got.sum(axis=0), np.zeros(x.shape[1]), f"{what}: the forces sum to zero",
                     atol=1e-9 * float(np.abs(expected).sum()) + precision_rtol(got, 0.0),
                     hint="each pair must push both bodies equally and oppositely")


def _ground_states():
    rng = np.random.default_rng(606)
    x = rng.normal(size=(12, 2))
    v = 2.0 * rng.normal(size=(12, 2))
    x[:3, 1] = np.abs(x[:3, 1]) + 0.1           # above the ground
    x[3:, 1] = -np.abs(x[3:, 1]) * 0.1 - 0.01    # below it
    v[3:6, 1] = np.abs(v[3:6, 1]) + 0.1          # below but already moving up
    v[6:9, 1] = -np.abs(v[6:9, 1]) - 0.1         # below and moving down
    v[6:9, 0] = 0.05 * np.sign(v[6:9, 0])        # slow sideways: friction stops them
    v[9:, 1] = -np.abs(v[9:, 1]) - 0.1           # below, down, fast sideways
    v[11, 0] = 0.0                               # straight down: no sideways speed
    yield "12 particles in 2D, e = 0.6, μ = 0.4", stack_state(x, v), 0.6, 0.4
    x3, v3 = rng.normal(size=(8, 3)), rng.normal(size=(8, 3))
    x3[:, 1] = -0.01 - 0.1 * np.abs(x3[:, 1])
    v3[:, 1] = -np.abs(v3[:, 1])
    v3[0, [0, 2]] = 0.0                          # straight down
    yield "8 particles in 3D, all hitting, e = 0.3, μ = 0.2", stack_state(x3, v3), 0.3, 0.2
    yield "same, e = 1 and μ = 0 (a perfect bounce)", stack_state(x3, v3), 1.0, 0.0


def _bounce_mistakes(y, e, mu, expected) -> dict:
    x, v = y[0], y[1]
    normal = np.eye(x.shape[-1])[1]
    below = x[:, 1] < 0
    vn = v[:, 1]
    vt = v * (1 - normal)
    speed_t = np.linalg.norm(vt, axis=1, keepdims=True)
    approaching = below & (vn < 0)

    def respond(scale, hit, normal_v):
        out = v.copy()
        out[hit] = (scale * vt + normal_v[:, None] * normal)[hit]
        return np.stack((np.where(below[:, None], x * (1 - normal), x), out))

    safe = np.where(speed_t > 0, speed_t, 1.0)       # no sideways speed: nothing to scale
    with np.errstate(divide="ignore", invalid="ignore"):
        drop = mu * (1 + e) * np.abs(vn)[:, None] / safe
        clamp = np.maximum(0.0, 1 - drop)
        return {
            "friction can stop the sliding but never reverse it: clamp the tangential "
            "scale at 0": respond(1 - drop, approaching, -e * vn),
            "only a particle moving INTO the ground bounces; one already moving up "
            "keeps its velocity": respond(clamp, below, -e * vn),
            "move penetrating particles back to the surface (y = 0)": np.stack((x, expected[1])),
            "friction takes μ times the change of the normal speed, (1 + e)|v_n|, not μ|v_n|":
                respond(np.maximum(0.0, 1 - mu * np.abs(vn)[:, None] / safe), approaching,
                        -e * vn),
            "restitution scales the normal velocity only; friction handles the tangential "
            "part": respond(e * clamp, approaching, -e * vn),
            "Coulomb friction removes speed, μ (1 + e) |v_n|, from the tangential velocity; "
            "scaling it by (1 - μ) is a different law":
                respond(np.full_like(drop, 1 - mu), approaching, -e * vn),
            "sign: after the bounce the normal velocity points up, v_n' = -e v_n":
                respond(clamp, approaching, e * vn),
        }


@exercise(allow=())
def bounce(ck: Checker, func) -> None:
    """``func(y, restitution, friction)``: contact response with the ground ``y >= 0``."""
    for what, y, e, mu in _ground_states():
        normal = np.eye(y.shape[-1])[1]
        expected = collisions.plane(normal=normal, restitution=e, friction=mu)(0.0, y)
        y_in = y.copy()
        got = func(y_in, e, mu)
        if not np.array_equal(y_in, y):
            ck.expect(False, what, "your function changed its input y",
                      hint="copy the positions and velocities before changing them")
            continue
        if blown_up(ck, got, what, run=False, hint=(
                "some particles fall straight down (no sideways speed): your friction divides "
                "by |v_t| = 0 there; leave a particle without sideways speed without it")):
            continue
        ck.close(got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12,
                 mistakes=_bounce_mistakes(y, e, mu, expected))
