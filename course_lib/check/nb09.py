"""Checks for notebook 09, particle systems: the emit step, the expire step and the
expected population.

The emit check is statistical: it draws 4000 frames and tests the counts (range, mean,
spread) and the positions (on the disc, uniform by area, all directions, and radius and
angle *independent*: a 4 × 4 histogram of (r²/R², θ/2π), uniform on the unit square for a
disc sampled right, judged by a χ² test whose threshold a right answer exceeds once in a
million runs). No answer may call the library (``allow=()``): the exercise is to write
Reeves' rules, not to call :func:`course_lib.particles.reeves_count`.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from .. import particles
from . import Checker, exercise

_SEED = 909


def _counts_and_points(func, mean, variance, radius, calls):
    rng = np.random.default_rng(_SEED)
    counts, points = [], []
    for _ in range(calls):
        p = np.asarray(func(mean, variance, radius, rng), dtype=float)
        if p.ndim != 2 or p.shape[1:] != (2,):
            raise ValueError(f"expected positions of shape (k, 2), got shape {p.shape}")
        counts.append(p.shape[0])
        points.append(p)
    return np.array(counts), np.concatenate(points)


#: χ² threshold of the independence test: exceeded by a right answer with probability 1e-6.
_CHI2_LIMIT = float(chi2.isf(1e-6, 15))


@exercise(allow=())
def emit(ck: Checker, func) -> None:
    """``func(mean, variance, radius, rng) -> (k, 2)``: this frame's new particles."""
    a = np.asarray(func(12.25, 6.0, 2.0, np.random.default_rng(1)), dtype=float)
    b = np.asarray(func(12.25, 6.0, 2.0, np.random.default_rng(1)), dtype=float)
    if not ck.expect(a.shape == b.shape and np.array_equal(a, b),
                     "the same seed gives the same particles",
                     "two generators with the same seed gave different results",
                     hint="draw every random number from the generator `rng` you are given "
                          "(rng.uniform, rng.random), not from np.random or random"):
        return
    mean, variance, radius, calls = 12.25, 6.0, 2.0, 4000
    counts, pts = _counts_and_points(func, mean, variance, radius, calls)
    lo, hi = int(np.floor(mean - variance)), int(np.ceil(mean + variance))
    ck.expect(counts.min() >= lo and counts.max() <= hi,
              f"every count lies in [{lo}, {hi}]", f"counts ranged over [{counts.min()}, {counts.max()}]",
              hint=("Reeves' count is never outside [mean - variance, mean + variance]: is your "
                    "random number bounded?",
                    "Reeves' count is mean + variance × U(-1, 1) with U uniform (rng.uniform(-1, 1)), "
                    "not a normal draw: it never leaves [mean - variance, mean + variance]"))
    se = np.sqrt((variance**2 / 3 + 0.25) / calls)
    got = counts.mean()
    hint = None
    if abs(got - (mean + variance / 2)) < 4 * se:
        hint = "rng.random() is uniform on [0, 1); the spread must be symmetric: U(-1, 1)"
    elif abs(got - (mean - 0.5)) < 4 * se:
        hint = ("int() truncates and loses half a particle per frame on average",
                "int() truncates and loses half a particle per frame on average: round "
                "instead (round(y), or at random with floor(y + rng.random()))")
    ck.expect(abs(got - mean) < 4 * se, f"the mean count over {calls} frames is {mean}",
              f"it was {got:.3f}", hint=hint)
    spread, uniform = counts.std(), variance / np.sqrt(3)
    hint = None
    if spread < 0.3 * uniform:
        hint = ("the count hardly varies: is a new random number drawn every frame?",
                "draw a new count every frame: mean + variance × rng.uniform(-1, 1)")
    elif abs(spread / uniform - 0.5) < 0.1:
        hint = "rng.random() spans [0, 1), half of U(-1, 1): the spread is halved"
    elif spread > uniform:
        hint = "the spread is uniform, variance × U(-1, 1), with standard deviation variance/√3"
    ck.expect(abs(spread / uniform - 1) < 0.1, "the count varies from frame to frame as Reeves' rule says",
              f"its standard deviation was {spread:.2f}; mean + variance × U(-1, 1) gives "
              f"variance/√3 = {uniform:.2f}", hint=hint)
    r = np.linalg.norm(pts, axis=1)
    if not ck.expect(r.max() <= radius * (1 + 1e-12), f"every particle lies on the disc of radius {radius:g}",
                     f"the farthest was at {r.max():.3f}",
                     hint=("x and y drawn independently fill a square, not a disc",
                           "x and y drawn independently fill a square; draw a radius and an angle")):
        return
    inner = np.mean(r < radius / 2)
    se = np.sqrt(0.25 * 0.75 / r.size)
    hint = None
    if abs(inner - 0.5) < 4 * np.sqrt(0.25 / r.size):
        hint = ("r = R u crowds the centre: how does the area within radius r grow with r?",
                "r = R u crowds the centre: the area within r grows as r², so draw r = R √u "
                "to give equal areas equal numbers of particles")
    elif inner < 0.01:
        hint = ("the particles sit on the rim: that is a ring, not a disc",
                "the particles sit on the rim: that is a ring, not a disc; draw r = R √u")
    ck.expect(abs(inner - 0.25) < 4 * se, "a quarter of the particles lie within R/2 (uniform by area)",
              f"the fraction was {inner:.3f}", hint=hint)
    quadrants = np.array([np.mean((pts[:, 0] > 0) & (pts[:, 1] > 0)),
                          np.mean((pts[:, 0] < 0) & (pts[:, 1] < 0))])
    ck.expect(np.all(np.abs(quadrants - 0.25) < 4 * se), "all directions are equally likely",
              f"fractions in the first and third quadrants: {quadrants.round(3)}",
              hint=("the angle does not cover a full turn evenly",
                    "draw the angle uniformly over a full turn, rng.uniform(0, 2π)"))
    # radius and angle independent: (r²/R², θ/2π) uniform on the unit square
    theta = np.mod(np.arctan2(pts[:, 1], pts[:, 0]), 2 * np.pi) / (2 * np.pi)
    grid, _, _ = np.histogram2d(np.clip((r / radius) ** 2, 0, 1), theta, bins=4, range=[[0, 1], [0, 1]])
    stat = float(np.sum((grid - r.size / 16) ** 2 / (r.size / 16)))
    ck.expect(stat < _CHI2_LIMIT, "radius and angle are independent (a χ² test on a 4 × 4 histogram)",
              f"χ² = {stat:.0f} with 15 degrees of freedom; a uniform disc stays below "
              f"{_CHI2_LIMIT:.0f} in all but one run in a million",
              hint=("the radius and the angle move together: are they drawn from the same "
                    "random numbers?",
                    "draw the radii and the angles from separate calls to rng: one u used for "
                    "both r = R√u and θ = 2πu puts every particle on one spiral"))


def _frame(rng, n, capacity):
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


def _reference(data, n):
    keep = data["age"][:n] < data["lifetime"][:n]
    return {k: v[:n][keep] for k, v in data.items()}


@exercise(allow=())
def expire(ck: Checker, func) -> None:
    """``func(data, n) -> m``: delete the expired among the first ``n`` rows, in place."""
    rng = np.random.default_rng(_SEED)
    cases = [("9 live of 12 rows, some exactly at their lifetime", 9, 12),
             ("200 live of 256 rows", 200, 256), ("no live particle", 0, 8)]
    data = _frame(rng, 6, 6)
    data["age"][:] = 0.0
    cases_data = [(what, _frame(rng, n, cap), n) for what, n, cap in cases]
    cases_data.append(("nobody expires", data, 6))
    for what, data, n in cases_data:
        expected = _reference(data, n)                  # before the student's code runs
        work = {k: v.copy() for k, v in data.items()}
        arrays = dict(work)
        m = func(work, n)
        if any(work[k] is not arrays[k] for k in arrays):
            ck.expect(False, what, "your function replaced arrays in `data` by new ones",
                      hint="write into the preallocated arrays (data[k][:m] = ...), which the "
                           "particle system keeps; do not rebind data[k]")
            continue
        if m is None or not np.isscalar(m) or int(m) != m:
            ck.expect(False, what, f"expected the new live count (an int), got {m!r}",
                      hint="return the number of survivors, m")
            continue
        m = int(m)
        if m != len(expected["age"]):
            hint = None
            if m == n:
                hint = "you returned n: count the survivors, age < lifetime"
            elif m == int(np.sum(data["age"][:n] <= data["lifetime"][:n])):
                hint = ("a particle whose age has reached its lifetime dies",
                        "a particle whose age has reached its lifetime dies: "
                        "keep age < lifetime, not age <= lifetime")
            elif m == n - len(expected["age"]):
                hint = "you kept the expired particles and deleted the living ones"
            elif m == int(np.sum(data["age"] < data["lifetime"])):
                hint = "only the first n rows are live; the rows beyond n are free slots"
            ck.expect(False, what, f"expected {len(expected['age'])} survivors, got {m}", hint=hint)
            continue
        wrong = [k for k in data if not np.array_equal(work[k][:m], expected[k])]
        if wrong:
            same_set = all(np.array_equal(np.sort(work[k][:m], axis=0), np.sort(expected[k], axis=0))
                           for k in wrong)
            untouched = all(np.array_equal(work[k], data[k]) for k in data)
            if untouched:
                hint = "move the survivors to the front of every array in `data` (in place)"
            elif same_set:
                hint = ("keep the survivors in their original order",
                        "keep the survivors in their original order (data[k][:m] = data[k][:n][alive])")
            else:
                hint = f"move the rows of every attribute, not only some: wrong in {wrong}"
            ck.expect(False, what, f"the first {m} rows of {wrong} are not the survivors", hint=hint)
            continue
        ck.expect(True, what)


# --- the expected population -------------------------------------------------------------


def _population_cases():
    """Schedules that break shortcuts: a burst (the survival function itself), a constant
    rate (Little's law less half a frame), a ramp that stops (never steady), fixed
    lifetimes of exactly six frames (is the last frame counted?) and of 5.6 frames, and
    lifetimes spread down to zero. Steps of 1/8 and 1/16 s are exact in binary."""
    burst = np.zeros(12)
    burst[0] = 1000.0
    ramp = np.concatenate((np.arange(40.0), np.zeros(30)))
    yield "a burst of 1000 in the first frame, lifetimes 0.5 ± 0.25 s, dt = 1/8 s", burst, 0.125, 0.5, 0.25
    yield "40 per frame, lifetimes 2.5 ± 0.5 s, dt = 1/30 s", np.full(150, 40.0), 1 / 30, 2.5, 0.5
    yield ("a ramp 0, 1, ..., 39 per frame, then none; lifetimes 1 ± 0.4 s, dt = 1/16 s",
           ramp, 0.0625, 1.0, 0.4)
    yield "5 per frame, every lifetime 0.75 s (6 frames), dt = 1/8 s", np.full(20, 5.0), 0.125, 0.75, 0.0
    yield "5 per frame, every lifetime 0.7 s (5.6 frames), dt = 1/8 s", np.full(20, 5.0), 0.125, 0.7, 0.0
    yield "12 per frame, lifetimes 0.5 ± 0.5 s, dt = 1/16 s", np.full(30, 12.0), 0.0625, 0.5, 0.5


def _wrong_populations(mu, dt, life, var):
    """What the usual mistakes return for one case, with the hint each deserves."""
    n = mu.size
    ages = np.arange(1, n + 1) * dt

    def spread(s):
        return np.convolve(mu, s)[:n]

    uniform = (life + var - ages) / (2 * var) if var else None
    return {  # first match wins: with V = 0, "<=" and "ages from 0" give the same numbers
        ("a particle whose age has reached its lifetime is deleted before the count",
         "with fixed lifetimes S(a) = 1 while a < L, and 0 from a = L on (not a <= L)"):
            spread((ages <= life).astype(float)) if var == 0 else None,
        ("a particle emitted in frame k has lived j - k + 1 steps when counted after frame j "
         "(it is stepped in its own frame)",
         "count ages (j - k + 1) dt: the convolution of the counts with S(dt), S(2 dt), ..., "
         "not S(0), S(dt), ..."): spread(particles.survival(ages - dt, life, var)),
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
         "S(a) falls linearly from 1 at a = L - V to 0 at a = L + V: "
         "clip((L + V - a) / (2V), 0, 1)"):
            spread(np.clip(uniform * 2, 0, 1)) if var else None,
        ("the first frames come first: keep the head of the full convolution",
         "np.convolve(counts, S)[:frames]"):
            np.convolve(mu, particles.survival(ages, life, var))[n - 1:],
    }


@exercise(allow=())
def expected_population(ck: Checker, func) -> None:
    """``func(mean_counts, dt, lifetime, lifetime_variance) -> (frames,)``: E[live count]
    after each frame of emit → step → expire."""
    for what, mu, dt, life, var in _population_cases():
        expected = particles.expected_population(mu, dt, life, var)
        mistakes = {h: w for h, w in _wrong_populations(mu, dt, life, var).items() if w is not None}
        got = func(mu.copy(), dt, life, var)
        ck.close(got, expected, what, rtol=1e-9, atol=1e-9, mistakes=mistakes,
                 hint=("check the survival function at a few ages by hand",
                       "E[N_j] = sum over k <= j of counts[k] × S((j - k + 1) dt), with "
                       "S(a) = clip((L + V - a) / (2V), 0, 1), or 1 while a < L when V = 0"))
