"""Checks for notebook 06, forces.

An answer may call no course_lib function (:mod:`course_lib.check.policy`). The terminal
speed asks for a formula, so it also refuses ``scipy.integrate`` and a step-by-step
simulation written by hand; the drag force and the located bounce ask for whole-array code,
and so do the N-body force and the contact response: they run under a budget of Python
lines that a loop over the particles or bodies exceeds
(:func:`~course_lib.check._answers.call_analysis`, lines counted, not seconds). Hints name
the slip the answer reproduces, or what the data that broke it show. Case data of the
N-body and contact checks: :mod:`course_lib.check._nb06_cases`.
"""

from __future__ import annotations

import numpy as np

from .. import collisions, events, forces
from ..lessons import nb06_forces as lesson
from . import Checker, exercise
from ._answers import call_analysis, close, one_number
from ._nb06_cases import bounce_mistakes, ground_states, located_mistakes, nbody_cases, nbody_mistakes
from .tolerance import blown_up, call_whole_array, close_worst, escalate, precision_rtol


def _drag_cases():
    rng = np.random.default_rng(6)
    v3, v2 = rng.normal(size=(4, 3)), rng.normal(size=(5, 2))
    return [("four particles in 3D, b = 0.5, still air", v3, 0.5, np.zeros(3)),
            ("b = 2, wind (3, 0, -1) m/s", v3, 2.0, np.array([3.0, 0.0, -1.0])),
            ("five particles in 2D, b = 0.1, wind (-4, 1) m/s", v2, 0.1, np.array([-4.0, 1.0])),
            ("one particle moving with the wind: no drag", np.array([[1.0, 0.0]]), 1.0,
             np.array([1.0, 0.0])),
            ("a swarm of 300 particles in 3D, b = 0.3, wind (1, 2, 0) m/s",
             rng.normal(size=(300, 3)), 0.3, np.array([1.0, 2.0, 0.0]))]


#: Lines of Python a whole-array answer needs at most (a loop over 300 particles runs 300).
ARRAY_LINES = 60


@exercise(allow=())
def drag_force(ck: Checker, drag) -> None:
    """``drag(v, b, wind)``: linear drag ``-b (v - wind)`` on velocities ``(N, d)``."""
    for what, v, b, wind in _drag_cases():
        v_in = v.copy()
        ok, got = call_whole_array(ck, what, ARRAY_LINES, escalate(
            "NumPy applies one formula to every row of v at once: no Python loop is needed",
            "write the force for the whole (N, d) array in one expression; the wind, shape "
            "(d,), broadcasts over the rows"), drag, v_in, b, wind.copy())
        if not ok:
            continue
        if not np.array_equal(v_in, v):
            ck.expect(False, what, "your function changed its input v",
                      hint=escalate("v -= wind (or v *= ...) overwrites the particles' "
                                    "velocities", "compute a new array from v instead"))
            continue
        expected = -b * (v - wind)
        speed = np.linalg.norm(v - wind, axis=1, keepdims=True)
        # a failure shows the worst particle, not the whole (300, 3) array
        close_worst(ck, got, expected, what, rtol=precision_rtol(got, 1e-9), atol=1e-12,
                    unit="N", label="particle", mistakes={
            escalate("sign error: drag opposes the motion relative to the air",
                     "the force points along -(v - wind)"): b * (v - wind),
            escalate("you forgot the wind: drag acts on the velocity relative to the air",
                     "subtract the wind from every particle's velocity first"): -b * v,
            escalate("the relative velocity is v - wind, not v + wind",
                     "the air moves with the wind: relative to it, a particle moves at v - wind"):
                -b * (v + wind),
            escalate("drag acts on every component of v - wind, a vector, not on its length",
                     "keep the (N, d) shape: no norm"): -b * speed * np.ones(v.shape[1]),
            escalate("that is quadratic drag, -b |v - w| (v - w): the exercise asks for the "
                     "linear law", "drop the speed factor |v - w|"): -b * speed * (v - wind),
        })


#: Lines of Python a formula needs at most (a simulation runs thousands).
FORMULA_LINES = 200
SIMULATED = escalate(
    "the exercise asks for the speed from the force balance, a formula: your function runs a "
    "long loop instead (a simulation of the fall, or an iteration such as v = m g / (b + c v))",
    "the balance b v + c v² = m g is a quadratic in v: solve it once, no loop")


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
                "multiply the root's numerator and denominator by the conjugate of the "
                "numerator: the difference of squares removes both the subtraction and c")):
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
                "you forgot g: the weight is m g, a force in N":
                    2 * m / (b + np.sqrt(b * b + 4 * c * m)),
                escalate("with c this small, -b + √(b² + 4 c m g) subtracts two nearly equal "
                         "numbers and loses its digits", "multiply the root's numerator and "
                         "denominator by b + √(b² + 4 c m g): the difference of squares removes "
                         "the subtraction"): (-b + disc) / (2 * c) if c else np.nan,
            }
        if c:
            mistakes["that is the quadratic drag alone, √(m g / c); the linear drag b v adds to "
                     "it"] = np.sqrt(m * g / c)
        if b:
            mistakes["that is the linear drag alone, m g / b; the quadratic drag c v² adds to "
                     "it"] = m * g / b
        if b and c:
            mistakes[escalate("adding the two terminal speeds overshoots: both drags act at "
                              "once, at one speed", "write one balance, b v + c v² = m g, and "
                              "solve it for v")] = m * g / b + np.sqrt(m * g / c)
        # v = m g / (b + c v) contracts by c v / (b + c v) per step: near 1 it crawls, at
        # b = 0 it swings between two values for ever; a short iteration stops off the root
        slow = c * exact / (b + c * exact) > 0.6 and np.isfinite(value) and value > 0
        close(ck, value, exact, what, rtol=precision_rtol(got, 1e-9), mistakes=mistakes,
              hint=ITERATED if slow else None)


#: The hint for a wrong answer where a fixed-point iteration converges slowly or not at all.
ITERATED = escalate(
    "if you iterate v = m g / (b + c v): with b small next to c v it converges slowly, and at "
    "b = 0 not at all (it swings between two values); solve the balance once instead",
    "b v + c v² = m g is a quadratic in v: its positive root, written 2 m g / (b + √(b² + "
    "4 c m g)), needs no loop and no starting guess")


def _falling_balls(seed: int, n: int, dt: float, g: float, e: float):
    """``n`` balls between 0 and 5 cm up, at -3 to 3 m/s, plus two that have just bounced
    (on the ground, moving up: one lands again within the step, one does not); only balls
    with at most one impact in the step are kept (the exercise promises no more)."""
    rng = np.random.default_rng(seed)
    h = np.r_[rng.uniform(0.0, 0.05, n), 0.0, 0.0]
    v = np.r_[rng.uniform(-3.0, 3.0, n), 0.4 * g * dt, 2.0 * g * dt]
    h1, _ = lesson.located_bounce_step(h, v, dt, g, e)
    keep = h1 >= 0.0
    return h[keep], v[keep]


@exercise(allow=())
def located_bounce(ck: Checker, func) -> None:
    """``func(h, v, dt, g, e) -> (h, v)``: a step of falling balls with the impact located
    inside it; then the apex ratio e² of a ball stepped by it."""
    cases = [("40 balls near the ground, dt = 0.02 s, g = 9.81 m/s², e = 0.8", 1, 40, 0.02, 9.81, 0.8),
             ("40 balls on the Moon, dt = 0.1 s, g = 1.62 m/s², e = 0.5", 2, 40, 0.1, 1.62, 0.5)]
    for what, seed, n, dt, g, e in cases:
        h, v = _falling_balls(seed, n, dt, g, e)
        expected = np.stack(lesson.located_bounce_step(h, v, dt, g, e))
        ok, got = call_whole_array(ck, what, ARRAY_LINES, escalate(
            "work on all the balls at once: no Python loop over them", "np.where chooses, ball "
            "by ball, between the free flight and the bounce"), func, h.copy(), v.copy(), dt, g, e)
        if not ok:
            continue
        try:
            got = np.stack([np.asarray(part, dtype=float) for part in got])
        except (TypeError, ValueError):
            ck.expect(False, what, f"return a pair (h, v) of arrays, got {type(got).__name__}")
            continue
        if blown_up(ck, got, what, run=False):
            continue
        # one row per ball, (h, v): a wrong answer is summarised by its worst ball
        mistakes = {hint: np.stack(wrong).T for hint, wrong in located_mistakes(h, v, dt, g, e).items()}
        close_worst(ck, got.T, expected.T, what, rtol=1e-9, atol=1e-12, mistakes=mistakes,
                    label="ball (h, v)")
    # The whole point: with the impact located, every bounce keeps e² of the height.
    what = "dropped from 1 m with dt = 0.01 s: each apex e² = 0.64 of the one before"
    h, v, heights = np.array([1.0]), np.array([0.0]), [1.0]
    for _ in range(300):
        ok, got = call_analysis(ck, what, ARRAY_LINES, None, func, h, v, 0.01, 9.81, 0.8)
        if not ok:
            return
        try:
            h, v = (np.asarray(part, dtype=float).reshape(1) for part in got)
        except (TypeError, ValueError):
            ck.expect(False, what, "your step did not return a pair (h, v) of arrays")
            return
        heights.append(float(h[0]))
    if blown_up(ck, heights, what):
        return
    _, peaks = events.local_maxima(0.01 * np.arange(301), np.array(heights))
    ratios = peaks[:4] / np.r_[1.0, peaks[:3]]
    ck.close(ratios, np.full(4, 0.64), what, rtol=1e-9, atol=1e-12,
             hint="your apexes do not keep e² of the height: compare your step with the ball "
                  "of section 6")


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


LOOPED_BODIES = escalate("work on every pair at once with broadcasting, no loop over bodies",
                         "r = x[:, None, :] - x[None, :, :] holds every pair at once, shape "
                         "(N, N, d)")


@exercise(allow=())
def nbody_force(ck: Checker, func) -> None:
    """``func(x, mass, G, softening)``: softened gravity of every body on every other."""
    for what, x, m, G, eps in nbody_cases():
        expected = forces.nbody_gravity_force(x, m, G, eps)
        # Two watches: the positions notice being indexed body by body, and the lines of
        # Python run are counted (a copy made with np.asarray(x) no longer notices anything).
        _Bodies.looped = False
        ok, got = call_analysis(ck, what, ARRAY_LINES, LOOPED_BODIES, func, x.view(_Bodies),
                                m.copy(), G, eps, why="it loops over the bodies one at a time "
                                "instead of working on every pair at once")
        if ok and _Bodies.looped:
            ck.expect(False, what, "your function loops over the bodies one at a time",
                      hint=LOOPED_BODIES)
        if not ok or _Bodies.looped:
            continue
        got = np.asarray(got)
        if blown_up(ck, got, what, run=False):
            continue
        close_worst(ck, got, expected, what, rtol=precision_rtol(got, 1e-9),
                    atol=1e-12 * float(np.abs(expected).max()), unit="N", label="body",
                    mistakes=nbody_mistakes(x, m, G, eps, expected))
        if got.shape == expected.shape:
            ck.close(got.sum(axis=0), np.zeros(x.shape[1]), f"{what}: the forces sum to zero",
                     atol=1e-9 * float(np.abs(expected).sum()) + precision_rtol(got, 0.0),
                     hint="each pair must push both bodies equally and oppositely")


@exercise(allow=())
def bounce(ck: Checker, func) -> None:
    """``func(y, restitution, friction)``: contact response with the ground ``y >= 0``."""
    for what, y, e, mu in ground_states():
        normal = np.eye(y.shape[-1])[1]
        expected = collisions.plane(normal=normal, restitution=e, friction=mu)(0.0, y)
        y_in = y.copy()
        ok, got = call_whole_array(ck, what, ARRAY_LINES, escalate(
            "respond to all the particles at once: no Python loop over them", "boolean masks "
            "(below, moving in) pick the rows to change; np.where or mask assignment changes "
            "them together"), func, y_in, e, mu)
        if not ok:
            continue
        if not np.array_equal(y_in, y):
            ck.expect(False, what, "your function changed its input y",
                      hint="copy the positions and velocities before changing them")
            continue
        if blown_up(ck, got, what, run=False, hint=(
                "some particles fall straight down (no sideways speed): your friction divides "
                "by |v_t| = 0 there; leave a particle without sideways speed without it")):
            continue
        # a row per particle, its (position, velocity): the worst particle is shown
        def per_particle(a, shape=y.shape):
            return np.asarray(a, dtype=float).transpose(1, 0, 2) if np.shape(a) == shape else a

        close_worst(ck, per_particle(got), per_particle(expected), what,
                    rtol=precision_rtol(got, 1e-9), atol=1e-12, label="particle (x, v)",
                    mistakes={h: per_particle(w)
                              for h, w in bounce_mistakes(y, e, mu, expected).items()})
