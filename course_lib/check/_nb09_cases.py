"""Case data of notebook 09's checks of the emit step, the expire step and the expected
population.

- :func:`counts_and_points` draws an emit answer's frames; :func:`dependence` (χ² on a
  4 × 4 table, against :data:`CHI2_LIMIT`) and :func:`pairs_within_frames` test the
  independence of what it draws;
- :func:`expire_frame` builds a particle system's arrays with counted ages, some exactly at
  their lifetime and some one unit of round-off below it, and dead rows beyond ``n``;
  :data:`EXPIRE_MISTAKES` are the expire step as the usual mistakes write it, each with the
  hint it deserves, so that a hint is given only to an answer that did exactly what that
  mistake does (arrays and return value alike);
- :func:`population_cases` are the emission schedules :func:`course_lib.check.nb09.expected_population`
  tries, and :func:`wrong_populations` what the usual mistakes make of one of them.

Imports NumPy and :mod:`course_lib.particles` (the survival function the mistakes shift).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from .. import particles
from .tolerance import escalate

# --- the emit step: draws and their statistics -------------------------------------------


def counts_and_points(func, mean, variance, radius, calls: int, seed: int):
    """The counts of ``calls`` frames of ``func(mean, variance, radius, rng)`` and all their
    points, from one seeded generator."""
    rng = np.random.default_rng(seed)
    counts, points = [], []
    for _ in range(calls):
        p = np.asarray(func(mean, variance, radius, rng), dtype=float)
        if p.ndim != 2 or p.shape[1:] != (2,):
            raise ValueError(f"expected positions of shape (k, 2), got shape {p.shape}")
        counts.append(p.shape[0])
        points.append(p)
    return np.array(counts), np.concatenate(points)


#: Counts drawn as a uniform number, rounded, have a kurtosis μ₄/σ⁴ near 1.8; a normal draw
#: has 3 (2.6 once clipped at 0 for the small emitter). Below this, the draw was uniform.
FLAT = 2.4

#: The hint for counts drawn uniformly over the wrong width (√(3 variance) × U, 2 variance × U).
WIDTH_HINT = escalate("your counts are spread evenly, but over the wrong width: Reeves' variance is the "
               "half-width of the spread, not its statistical variance",
               "mean + variance × U(-1, 1) with U = rng.uniform(-1, 1): the count then spreads "
               "evenly from mean - variance to mean + variance")


def flat(counts) -> bool:
    """Whether ``counts`` look drawn from a uniform number (kurtosis below :data:`FLAT`)."""
    d = np.asarray(counts, dtype=float) - np.mean(counts)
    var = np.mean(d**2)
    return bool(var > 0 and np.mean(d**4) / var**2 < FLAT)


#: χ² threshold of a test of independence on a 4 × 4 table (9 degrees of freedom):
#: exceeded by independent variables with probability 1e-6.
CHI2_LIMIT = float(chi2.isf(1e-6, 9))


def dependence(a, b) -> float:
    """χ² of the 4 × 4 table of ``a`` against ``b`` (each in [0, 1]) against the product of
    its own row and column sums: large only when the two depend on each other, whatever
    their separate distributions (a wrong radius law alone does not raise it)."""
    table, _, _ = np.histogram2d(np.clip(a, 0, 1), np.clip(b, 0, 1), bins=4, range=[[0, 1], [0, 1]])
    expected = table.sum(axis=1, keepdims=True) * table.sum(axis=0, keepdims=True) / max(table.sum(), 1)
    seen = expected > 0
    return float(np.sum((table - expected)[seen] ** 2 / expected[seen]))


def pairs_within_frames(counts) -> np.ndarray:
    """Index of the first particle of the pairs (0, 1), (2, 3), ... of every frame."""
    start = np.repeat(np.cumsum(counts) - counts, counts)
    place = np.arange(counts.sum()) - start
    return np.flatnonzero((place % 2 == 0) & (place + 1 < np.repeat(counts, counts)))


# --- the expire step ----------------------------------------------------------------------


#: Row 4 of :func:`expire_frame` has this many units of round-off (ε relative) of its
#: lifetime left: a tolerance of a few ε keeps it, one of more than about 60 ε deletes it.
ROUNDOFF_AHEAD = 64


def expire_frame(rng: np.random.Generator, n: int, capacity: int, fps: int = 24) -> dict:
    """Arrays of ``capacity`` rows, ``n`` of them live, at ``fps`` frames per second: ages
    counted as ``steps × dt`` with ``dt = 1/fps`` (as a particle system counts them) and
    lifetimes of a whole number of frames written as decimals, ``frames / fps``; so some
    ages equal their lifetime and some land one unit of round-off below it (at 24 frames
    per second, 5 × (1/24) < 5/24). Row 1 is exactly at its lifetime in frames, one unit
    of round-off short; row 2 has 2 μs of its lifetime left (it lives); row 3 is exactly at
    its lifetime; row 4 has 64 units of round-off left (it lives, and catches a tolerance
    larger than round-off). Dead rows beyond ``n`` are aged 0."""
    dt = 1.0 / fps
    steps = rng.integers(1, 40, capacity)
    frames = rng.integers(5, 40, capacity)
    data = {
        "x": rng.normal(size=(capacity, 3)),
        "age": steps * dt,
        "lifetime": frames / fps,
        "colour": rng.uniform(size=(capacity, 3)),
    }
    if n > 2:
        data["age"][1], data["lifetime"][1] = 5 * dt, 5 / fps       # reached, one ulp short
        data["lifetime"][2] = data["age"][2] + 2e-6                 # 2 μs to go: alive
    if n > 3:
        data["age"][3], data["lifetime"][3] = 6 * dt, 6 / fps       # reached (equal at 24 fps)
    if n > 4:                                   # 64 units of round-off to go: alive
        data["age"][4], data["lifetime"][4] = 7 * dt, 7 * dt * (1 + ROUNDOFF_AHEAD * np.finfo(float).eps)
    data["age"][n:] = 0.0                       # dead rows beyond n must be left alone
    return data


def _compact(data: dict, keep: np.ndarray) -> int:
    m = int(np.count_nonzero(keep))
    for values in data.values():
        values[:m] = values[: keep.size][keep]
    return m


def _le(data, n):
    return _compact(data, data["age"][:n] <= data["lifetime"][:n])


def _strict(data, n):
    return _compact(data, data["age"][:n] < data["lifetime"][:n])


def _isclose(data, n):
    age, life = data["age"][:n], data["lifetime"][:n]
    return _compact(data, (age < life) & ~np.isclose(age, life))


def _loose(data, n):
    """Any tolerance between about 1e-13 and 1e-6 (relative, or absolute in s) does this."""
    return _compact(data, data["age"][:n] < data["lifetime"][:n] * (1 - 1e-9))


def _alive(data, n):
    return ~particles.reached(data["age"][:n], data["lifetime"][:n])


def _whole_capacity(data, n):
    return _compact(data, ~particles.reached(data["age"], data["lifetime"]))


def _inverted(data, n):
    return _compact(data, ~_alive(data, n))


def _swap_with_last(data, n):
    keep = _alive(data, n)
    m = int(np.count_nonzero(keep))
    holes, movers = np.flatnonzero(~keep[:m]), np.flatnonzero(keep[m:]) + m
    for values in data.values():
        values[holes] = values[movers]
    return m


def _returns_n(data, n):
    _compact(data, _alive(data, n))
    return n


def _returns_dead(data, n):
    return n - _compact(data, _alive(data, n))


_RIGHT_ARRAYS = ("your arrays hold the survivors, in order, but the function did not return "
                 "their number")

#: (the mistake, the hint it deserves): an answer whose arrays and return value both match
#: the mistake's on a case gets its hint.
EXPIRE_MISTAKES = (
    (_le, ("a particle whose age has reached its lifetime dies",
           "a particle whose age has reached its lifetime dies: it survives only while its age "
           "is below its lifetime (not below or equal), within round-off")),
    (_strict, escalate("an age counted as steps × dt can land one unit of round-off below a lifetime it "
                       "has reached (Section 1): 5 × (1/24) < 5/24",
                       "treat an age within a few units of round-off of its lifetime as reached: a relative "
                       "tolerance of a few ε (np.finfo(float).eps), as Section 1 does")),
    (_isclose, escalate("np.isclose's default tolerance (1e-5 relative) kills a particle whose lifetime is "
                        "still 2 μs ahead of its age",
                        "round-off in a counted age is a unit or two in the last place, about 1e-16 "
                        "relative: a tolerance of a few ε is enough, and a larger one kills particles "
                        "early")),
    (_loose, escalate(f"a particle with {ROUNDOFF_AHEAD} units of round-off (ε) of its lifetime still to go "
                      "was deleted: your tolerance is larger than round-off",
                      "round-off in a counted age is a unit or two in the last place: a relative tolerance "
                      "of a few ε (np.finfo(float).eps) is enough, and a tolerance of 1e-9 or of a "
                      "microsecond deletes particles that still have time to live")),
    (_whole_capacity, "only the first n rows are live; the rows beyond n are free slots"),
    (_inverted, "you kept the expired particles and deleted the living ones"),
    (_swap_with_last, escalate("keep the survivors in their original order",
                               "moving the last particles into the holes breaks the order: gather the "
                               "survivors' rows with the boolean mask instead, all at once")),
    (_returns_n, _RIGHT_ARRAYS),
    (_returns_dead, _RIGHT_ARRAYS),
)


def population_cases():
    """Schedules that break shortcuts, spread lifetimes first: a burst (the survival
    function itself), a constant rate (Little's law less half a frame), a ramp that stops
    (never steady), lifetimes spread down to zero; then fixed
    lifetimes of exactly six frames (is the last frame counted?), of 5.6 and 5.3 frames
    (rounding the lifetime to whole frames), of five frames of 1/24 s (the counted age
    5 × (1/24) lands one unit of round-off below 5/24: compared without Section 1's
    tolerance, the particle lives a frame too long) and of a hundred frames of 0.1 s (an
    age summed frame by frame falls short of 10 s: it must be counted, Section 1)."""
    burst = np.zeros(12)
    burst[0] = 1000.0
    ramp = np.concatenate((np.arange(40.0), np.zeros(30)))
    yield "a burst of 1000 in the first frame, lifetimes 0.5 ± 0.25 s, dt = 1/8 s", burst, 0.125, 0.5, 0.25
    yield "40 per frame, lifetimes 2.5 ± 0.5 s, dt = 1/30 s", np.full(150, 40.0), 1 / 30, 2.5, 0.5
    yield ("a ramp 0, 1, ..., 39 per frame, then none; lifetimes 1 ± 0.4 s, dt = 1/16 s",
           ramp, 0.0625, 1.0, 0.4)
    yield "12 per frame, lifetimes 0.5 ± 0.5 s, dt = 1/16 s", np.full(30, 12.0), 0.0625, 0.5, 0.5
    yield "5 per frame, every lifetime 0.75 s (6 frames), dt = 1/8 s", np.full(20, 5.0), 0.125, 0.75, 0.0
    yield "5 per frame, every lifetime 0.7 s (5.6 frames), dt = 1/8 s", np.full(20, 5.0), 0.125, 0.7, 0.0
    yield ("5 per frame, every lifetime 0.6625 s (5.3 frames), dt = 1/8 s", np.full(20, 5.0),
           0.125, 0.6625, 0.0)
    yield ("5 per frame, every lifetime 5/24 s (5 frames), dt = 1/24 s", np.full(20, 5.0),
           1 / 24, 5 / 24, 0.0)
    yield ("5 per frame, every lifetime 10 s (100 frames), dt = 0.1 s", np.full(120, 5.0),
           0.1, 10.0, 0.0)


def shows_at_lifetime(got, expected, mu, dt, life, var) -> bool:
    """Whether ``got`` is, on this fixed-lifetime case and on no other reading of it, the
    population of an answer that still counts a particle whose age equals its lifetime
    (``a <= L``)."""
    if var:
        return False
    ages = np.arange(1, mu.size + 1) * dt
    le = np.convolve(mu, (ages <= life).astype(float))[: mu.size]
    lt = np.convolve(mu, (ages < life).astype(float))[: mu.size]    # no tolerance: another reading
    try:
        got = np.asarray(got, dtype=float)
    except (TypeError, ValueError):
        return False
    return bool(got.shape == le.shape and not np.allclose(le, expected, rtol=1e-9, atol=1e-9)
                and not np.allclose(le, lt, rtol=1e-9, atol=1e-9)
                and np.allclose(got, le, rtol=1e-9, atol=1e-9))


def wrong_populations(mu, dt, life, var, at_lifetime_seen: bool = False) -> dict:
    """What the usual mistakes return for one case, with the hint each deserves (a mistake
    that gives the right numbers on this case is left out). On a hundred frames of 0.1 s,
    ``a <= L`` and summed ages give the same numbers: ``at_lifetime_seen`` (an earlier case
    showed ``a <= L`` alone) names ``a <= L`` first."""
    n = mu.size
    ages = np.arange(1, n + 1) * dt
    right = np.convolve(mu, particles.survival(ages, life, var))[:n]

    def spread(s):
        return np.convolve(mu, s)[:n]

    summed = np.cumsum(np.full(n, dt))                    # ages added up step by step
    half = (n - 1) // 2                                   # where mode="same" starts
    at_lifetime = escalate("a particle whose age has reached its lifetime is deleted before the count",
                           "with fixed lifetimes S(a) = 1 while a < L, and 0 from a = L on (not a <= L)")
    first_frames = escalate("the first frames come out wrong: which part of the full convolution is the "
                            "population after frame j?", "element j of the full convolution adds counts[k] "
                            "times S at the age (j - k + 1) dt, for k = 0 ... j: that is the population "
                            "after frame j, for the first len(counts) elements")
    mistakes = {  # first match wins: on one case two mistakes can give the same numbers
        escalate("the ages are summed, dt + dt + ...: after 100 steps of 0.1 s the sum falls short of "
                 "10 s (Section 1)", "count the ages, m × dt for m = 1, 2, ...: a sum of m steps piles "
                 "up m roundings, and the particle lives a frame too long"):
            spread((summed < life * (1 - 4 * np.finfo(float).eps)).astype(float)) if var == 0 else None,
        escalate("a counted age m·dt can land a hair below a lifetime of m frames (Section 1): compare "
                 "it with a tolerance", "with dt = 1/24 s the age 5 × dt is one unit of round-off below "
                 "5/24 s: treat an age within a few units of round-off of the lifetime as reached, as "
                 "particles.reached does (age ≥ L (1 − 4ε))"):
            spread((ages < life).astype(float)) if var == 0 else None,
        at_lifetime:
            spread((ages <= life).astype(float)) if var == 0 else None,
        escalate("the lifetime is not a whole number of frames: do not round it",
                 "a particle is counted at every age m·dt below its lifetime, however close the "
                 "lifetime is to a whole number of frames"):
            spread((ages < np.round(life / dt) * dt * (1 - 1e-12)).astype(float)) if var == 0 else None,
        escalate("a particle emitted in frame k has lived j - k + 1 steps when counted after frame j "
                 "(it is stepped in its own frame)",
                 "count ages (j - k + 1) dt: the convolution of the counts with S(dt), S(2 dt), ..., "
                 "not S(0), S(dt), ..."): spread(particles.survival(ages - dt, life, var)),
        escalate("a particle is counted at the end of a frame, when it has lived a whole number of steps",
                 "its ages when counted are dt, 2 dt, ...: not half a step less"):
            spread(particles.survival(ages - 0.5 * dt, life, var)),
        escalate("the lifetimes are spread over [L - V, L + V]: not every particle lives exactly L",
                 "S(a), the chance that a lifetime exceeds a, falls linearly from 1 at a = L - V to 0 "
                 "at a = L + V"):
            spread((ages < life).astype(float)) if var else None,
        escalate("nobody dies in your answer: the population only ever grows",
                 "weight each past frame's count by the chance that its particles are still alive"):
            np.cumsum(mu),
        escalate("rate × mean lifetime is the long-run value for a constant rate, not the population "
                 "of every frame", "convolve the counts with the survival function"):
            mu * life / dt,
        escalate("the long-run value, less half a frame, holds for a constant rate once it has settled, "
                 "not for every frame", "convolve the counts with the survival function"):
            mu * (life / dt - 0.5),
        escalate("the lifetimes are spread uniformly over [L - V, L + V], 2V wide",
                 "S(a) falls linearly from 1 at a = L - V to 0 at a = L + V"):
            spread(np.clip((life + var - ages) / var, 0, 1)) if var else None,
        first_frames: np.convolve(mu, particles.survival(ages, life, var))[n - 1:],
        (first_frames[0] + " (mode=\"same\" keeps the middle of it)", first_frames[1]):
            np.convolve(mu, particles.survival(ages, life, var))[half:half + n],
    }
    if at_lifetime_seen:                       # summed ages after a <= L, the rest in order
        order = list(mistakes)
        summed_first = order.pop(0)
        order.insert(order.index(at_lifetime) + 1, summed_first)
        mistakes = {h: mistakes[h] for h in order}
    return {hint: wrong for hint, wrong in mistakes.items()
            if wrong is not None and not np.allclose(wrong, right, rtol=1e-9, atol=1e-9)}
