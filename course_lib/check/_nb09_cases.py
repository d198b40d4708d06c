"""Case data of notebook 09's checks of the expire step and of the expected population.

- :func:`expire_frame` builds a particle system's arrays with particles exactly at their
  lifetime and dead rows beyond ``n``; :data:`EXPIRE_MISTAKES` are the expire step as the
  usual mistakes write it, each with the hint it deserves, so that a hint is given only to
  an answer that did exactly what that mistake does (arrays and return value alike);
- :func:`population_cases` are the emission schedules :func:`course_lib.check.nb09.expected_population`
  tries, and :func:`wrong_populations` what the usual mistakes make of one of them.

Imports NumPy and :mod:`course_lib.particles` (the survival function the mistakes shift).
"""

from __future__ import annotations

import numpy as np

from .. import particles


def expire_frame(rng: np.random.Generator, n: int, capacity: int) -> dict:
    """Arrays of ``capacity`` rows, ``n`` of them live: ages and lifetimes on a 0.1 s grid
    (so some are equal), one particle exactly at its lifetime, dead rows aged 0."""
    data = {
        "x": rng.normal(size=(capacity, 3)),
        "age": np.round(rng.uniform(0.0, 2.0, capacity), 1),
        "lifetime": np.round(rng.uniform(0.5, 2.0, capacity), 1),
        "colour": rng.uniform(size=(capacity, 3)),
    }
    data["age"][n:] = 0.0                       # dead rows beyond n must be left alone
    if n > 2:
        data["age"][1] = data["lifetime"][1]    # exactly at its lifetime: it dies
    return data


def _compact(data: dict, keep: np.ndarray) -> int:
    m = int(np.count_nonzero(keep))
    for values in data.values():
        values[:m] = values[: keep.size][keep]
    return m


def _le(data, n):
    return _compact(data, data["age"][:n] <= data["lifetime"][:n])


def _whole_capacity(data, n):
    return _compact(data, data["age"] < data["lifetime"])


def _inverted(data, n):
    return _compact(data, data["age"][:n] >= data["lifetime"][:n])


def _swap_with_last(data, n):
    keep = data["age"][:n] < data["lifetime"][:n]
    m = int(np.count_nonzero(keep))
    holes, movers = np.flatnonzero(~keep[:m]), np.flatnonzero(keep[m:]) + m
    for values in data.values():
        values[holes] = values[movers]
    return m


def _returns_n(data, n):
    _compact(data, data["age"][:n] < data["lifetime"][:n])
    return n


def _returns_dead(data, n):
    return n - _compact(data, data["age"][:n] < data["lifetime"][:n])


_RIGHT_ARRAYS = ("your arrays hold the survivors, in order, but the function did not return "
                 "their number")

#: (the mistake, the hint it deserves): an answer whose arrays and return value both match
#: the mistake's on a case gets its hint.
EXPIRE_MISTAKES = (
    (_le, ("a particle whose age has reached its lifetime dies",
           "a particle whose age has reached its lifetime dies: keep age < lifetime, "
           "not age <= lifetime")),
    (_whole_capacity, "only the first n rows are live; the rows beyond n are free slots"),
    (_inverted, "you kept the expired particles and deleted the living ones"),
    (_swap_with_last, ("keep the survivors in their original order",
                       "keep the survivors in their original order: data[k][:m] = data[k][:n][alive] "
                       "moves them all at once")),
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
    tolerance, the particle lives a frame too long)."""
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


def wrong_populations(mu, dt, life, var) -> dict:
    """What the usual mistakes return for one case, with the hint each deserves (a mistake
    that gives the right numbers on this case is left out)."""
    n = mu.size
    ages = np.arange(1, n + 1) * dt
    right = np.convolve(mu, particles.survival(ages, life, var))[:n]

    def spread(s):
        return np.convolve(mu, s)[:n]

    mistakes = {  # first match wins: on one case two mistakes can give the same numbers
        ("a counted age m·dt can land a hair below a lifetime of m frames (Section 1): compare "
         "it with a tolerance", "with dt = 1/24 s the age 5 × dt is one unit of round-off below "
         "5/24 s: treat an age within a few units of round-off of the lifetime as reached, as "
         "particles.reached does (age ≥ L (1 − 4ε))"):
            spread((ages < life).astype(float)) if var == 0 else None,
        ("a particle whose age has reached its lifetime is deleted before the count",
         "with fixed lifetimes S(a) = 1 while a < L, and 0 from a = L on (not a <= L)"):
            spread((ages <= life).astype(float)) if var == 0 else None,
        ("the lifetime is not a whole number of frames: do not round it",
         "a particle is counted at every age m·dt below its lifetime, however close the "
         "lifetime is to a whole number of frames"):
            spread((ages < np.round(life / dt) * dt * (1 - 1e-12)).astype(float)) if var == 0 else None,
        ("a particle emitted in frame k has lived j - k + 1 steps when counted after frame j "
         "(it is stepped in its own frame)",
         "count ages (j - k + 1) dt: the convolution of the counts with S(dt), S(2 dt), ..., "
         "not S(0), S(dt), ..."): spread(particles.survival(ages - dt, life, var)),
        ("a particle is counted at the end of a frame, when it has lived a whole number of steps",
         "its ages when counted are dt, 2 dt, ...: not half a step less"):
            spread(particles.survival(ages - 0.5 * dt, life, var)),
        ("the lifetimes are spread over [L - V, L + V]: not every particle lives exactly L",
         "S(a), the chance that a lifetime exceeds a, falls linearly from 1 at a = L - V to 0 "
         "at a = L + V"):
            spread((ages < life).astype(float)) if var else None,
        ("nobody dies in your answer: the population only ever grows",
         "weight each past frame's count by the chance that its particles are still alive"):
            np.cumsum(mu),
        ("rate × mean lifetime is the long-run value for a constant rate, not the population "
         "of every frame", "convolve the counts with the survival function"):
            mu * life / dt,
        ("the long-run value, less half a frame, holds for a constant rate once it has settled, "
         "not for every frame", "convolve the counts with the survival function"):
            mu * (life / dt - 0.5),
        ("the lifetimes are spread uniformly over [L - V, L + V], 2V wide",
         "S(a) falls linearly from 1 at a = L - V to 0 at a = L + V"):
            spread(np.clip((life + var - ages) / var, 0, 1)) if var else None,
        ("the first frames come first: keep the head of the full convolution",
         "np.convolve(counts, S)[:frames]"):
            np.convolve(mu, particles.survival(ages, life, var))[n - 1:],
    }
    return {hint: wrong for hint, wrong in mistakes.items()
            if wrong is not None and not np.allclose(wrong, right, rtol=1e-9, atol=1e-9)}
