"""Checks for notebook 09, particle systems: the emit step, the expire step and the
expected population.

The emit check is statistical: it draws 4000 frames and tests the counts (range, mean,
spread) and the positions: on the disc, uniform by area, all directions, radius and angle
*independent* of each other, and the particles of one frame independent of each other.
Independence is judged by χ² on a 4 × 4 table against the product of the table's own row
and column sums (so a wrong radius law alone does not look like dependence), at a
threshold independent variables exceed once in a million runs. The expire check runs the
answer with a budget of lines of Python (no loop over the particles) and names a mistake
only when the answer's arrays and count are exactly what that mistake gives. No answer may
call the library (``allow=()``). Case data: :mod:`course_lib.check._nb09_cases`.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from .. import particles
from . import Checker, Hint, exercise
from . import _nb09_cases as _cases
from ._answers import call_analysis, close

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


#: χ² threshold of a test of independence on a 4 × 4 table (9 degrees of freedom):
#: exceeded by independent variables with probability 1e-6.
_CHI2_LIMIT = float(chi2.isf(1e-6, 9))


def _dependence(a, b) -> float:
    """χ² of the 4 × 4 table of ``a`` against ``b`` (each in [0, 1]) against the product of
    its own row and column sums: large only when the two depend on each other, whatever
    their separate distributions (a wrong radius law alone does not raise it)."""
    table, _, _ = np.histogram2d(np.clip(a, 0, 1), np.clip(b, 0, 1), bins=4, range=[[0, 1], [0, 1]])
    expected = table.sum(axis=1, keepdims=True) * table.sum(axis=0, keepdims=True) / max(table.sum(), 1)
    seen = expected > 0
    return float(np.sum((table - expected)[seen] ** 2 / expected[seen]))


def _pairs_within_frames(counts) -> np.ndarray:
    """Index of the first particle of the pairs (0, 1), (2, 3), ... of every frame."""
    start = np.repeat(np.cumsum(counts) - counts, counts)
    place = np.arange(counts.sum()) - start
    return np.flatnonzero((place % 2 == 0) & (place + 1 < np.repeat(counts, counts)))


def _disc_hint(pts, radius) -> Hint:
    corners = np.all(np.abs(pts) <= radius * (1 + 1e-12), axis=1).all()
    if corners and abs(np.mean(np.hypot(*pts.T) > radius) - (1 - np.pi / 4)) < 0.02:
        return ("x and y drawn independently fill a square, not a disc",
                "x and y drawn independently fill a square; draw a radius and an angle")
    return ("some particles land outside the disc: can your radius exceed `radius`?",
            "draw the radius so that it never exceeds R (r = R √u with u = rng.random(k)) and "
            "the angle over a full turn")


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
                     f"the farthest was at {r.max():.3f}", hint=_disc_hint(pts, radius)):
        return
    area = (r / radius) ** 2                       # uniform on [0, 1] for a disc sampled right
    turn = np.mod(np.arctan2(pts[:, 1], pts[:, 0]), 2 * np.pi) / (2 * np.pi)
    first = _pairs_within_frames(counts)
    within = max(_dependence(area[first], area[first + 1]), _dependence(turn[first], turn[first + 1]))
    apart = ck.expect(within < _CHI2_LIMIT,
                      f"the particles of a frame are independent of each other ({first.size} pairs)",
                      f"χ² = {within:.0f} on a 4 × 4 table of the radii (or angles) of neighbours in "
                      f"a frame; independent particles stay below {_CHI2_LIMIT:.0f} in all but one run "
                      "in a million",
                      hint=("the particles of one frame depend on each other: does each particle get "
                            "its own random numbers?",
                            "draw the k radii and the k angles at once (rng.random(k)), one of each per "
                            "particle; do not share, sort or space them out"))
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
    stat = _dependence(area, turn)
    ck.expect(stat < _CHI2_LIMIT, "radius and angle are independent (χ² on a 4 × 4 table)",
              f"χ² = {stat:.0f} on the table of r²/R² against the angle, with 9 degrees of freedom; "
              f"independent ones stay below {_CHI2_LIMIT:.0f} in all but one run in a million",
              hint=None if not apart else
              ("the radius and the angle move together: are they drawn from the same random numbers?",
               "draw the radii and the angles from separate calls to rng: one u used for "
               "both r = R√u and θ = 2πu puts every particle on one spiral"))


# --- the expire step ---------------------------------------------------------------------

#: Lines of Python an answer may run per case: a mask and one gather per array take about
#: ten; a loop over the particles takes at least one per particle (200 in the second case).
_EXPIRE_LINES = 60


def _expire_hint(data: dict, n: int, work: dict, m: int, expected: dict) -> Hint:
    """The hint for a wrong answer: the one usual mistake whose arrays and count it
    reproduces exactly (none if several do, as when nobody expires)."""
    survivors = len(expected["age"])
    if all(np.array_equal(work[k], data[k]) for k in data) and m == survivors:
        return "move the survivors to the front of every array in `data` (in place)"
    found = set()
    for mistake, hint in _cases.EXPIRE_MISTAKES:
        copy = {k: v.copy() for k, v in data.items()}
        if mistake(copy, n) == m and all(np.array_equal(copy[k], work[k]) for k in data):
            found.add(hint)
    if len(found) == 1:
        return found.pop()
    wrong = [k for k in data if not np.array_equal(work[k][:survivors], expected[k])]
    if not found and m == survivors and len(wrong) < len(data):
        return f"move the rows of every attribute, not only some: wrong in {wrong}"
    return None


@exercise(allow=())
def expire(ck: Checker, func) -> None:
    """``func(data, n) -> m``: delete the expired among the first ``n`` rows, in place,
    with no loop over the particles (at most :data:`_EXPIRE_LINES` lines of Python run)."""
    rng = np.random.default_rng(_SEED)
    cases = [("9 live of 12 rows, some exactly at their lifetime", 9, 12),
             ("200 live of 256 rows", 200, 256), ("no live particle", 0, 8)]
    data = _cases.expire_frame(rng, 6, 6)
    data["age"][:] = 0.0
    cases_data = [(what, _cases.expire_frame(rng, n, cap), n) for what, n, cap in cases]
    cases_data.append(("nobody expires", data, 6))
    for what, data, n in cases_data:
        keep = data["age"][:n] < data["lifetime"][:n]
        expected = {k: v[:n][keep] for k, v in data.items()}   # before the student's code runs
        work = {k: v.copy() for k, v in data.items()}
        arrays = dict(work)
        probe = Checker(ck.name, attempt=ck.attempt)
        ok, m = call_analysis(probe, what, _EXPIRE_LINES, None, func, work, n)
        if not ok:
            if probe.failed and "your function raised" in probe.failed[-1]:
                ck.failed.extend(probe.failed)
                continue
            ck.expect(False, what, f"your function ran more than {_EXPIRE_LINES} lines of Python "
                      f"on {n} particles: it loops over the particles",
                      hint=("no loop over particles: one boolean mask of the survivors, then one "
                            "gather per array",
                            "alive = data['age'][:n] < data['lifetime'][:n], then for every array "
                            "a[:m] = a[:n][alive]"))
            continue
        if any(work[k] is not arrays[k] for k in arrays):
            ck.expect(False, what, "your function replaced arrays in `data` by new ones",
                      hint="write into the preallocated arrays (data[k][:m] = ...), which the "
                           "particle system keeps; do not rebind data[k]")
            continue
        if m is None or not np.isscalar(m) or int(m) != m:
            ck.expect(False, what, f"expected the new live count (an int), got {m!r}",
                      hint="return the number of survivors, m")
            continue
        m, survivors = int(m), len(expected["age"])
        wrong = [k for k in data if not np.array_equal(work[k][:survivors], expected[k])]
        if m == survivors and not wrong:
            ck.expect(True, what)
            continue
        detail = (f"expected {survivors} survivors, got {m}" if m != survivors else
                  f"the first {m} rows of {wrong} are not the survivors")
        ck.expect(False, what, detail, hint=_expire_hint(data, n, work, m, expected))


# --- the expected population -------------------------------------------------------------


@exercise(allow=())
def expected_population(ck: Checker, func) -> None:
    """``func(mean_counts, dt, lifetime, lifetime_variance) -> (frames,)``: E[live count]
    after each frame of emit → step → expire."""
    spread_right = True
    for what, mu, dt, life, var in _cases.population_cases():
        expected = particles.expected_population(mu, dt, life, var)
        got = func(mu.copy(), dt, life, var)
        # the fine points of fixed lifetimes are named only once spread lifetimes come out
        # right: a wrong answer can match one of their mistakes on a fixed lifetime by chance
        named = var > 0 or spread_right
        right = close(ck, got, expected, what, rtol=1e-9, atol=1e-9,
                      mistakes=_cases.wrong_populations(mu, dt, life, var) if named else None,
                      hint=None if not named else
                      ("check the survival function at a few ages by hand",
                       "write S(a), the chance that a particle is still alive at age a (for V > 0 "
                       "and for V = 0); then add up, for every earlier frame, its count times S "
                       "at the age its particles have when they are counted"))
        spread_right = spread_right and (right or var == 0)
