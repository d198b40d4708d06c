"""Checks for notebook 09, particle systems: the emit step, the expire step and the
expected population.

The emit check is statistical: it draws 4000 frames from each of two emitters (different
means, variances and radii, so that an answer that ignores its arguments fails) and tests
the counts (range, mean, spread), the mean count of a third emitter whose 2 × variance is
not whole (where only rounding at random keeps it exact; :mod:`._nb09_counts`) and the
positions: on the disc, uniform by area (the
fractions within R/2 and beyond 0.9 R), all directions, radius and angle *independent* of
each other, and the particles of one frame independent of each other. A hint names a wrong
count rule or radius law only when both emitters show it.
Independence is judged by χ² on a 4 × 4 table against the product of the table's own row
and column sums (so a wrong radius law alone does not look like dependence), at a
threshold independent variables exceed once in a million runs. The expire check runs the
answer with a budget of lines of Python (no loop over the particles) and names a mistake
only when the answer's arrays and count are exactly what that mistake gives. No answer may
call the library (``allow=()``). Case data: :mod:`course_lib.check._nb09_cases`.
"""

from __future__ import annotations

import numpy as np

from .. import particles
from . import Checker, Hint, exercise
from . import _nb09_cases as _cases
from . import _nb09_counts as _counts
from ._answers import call_analysis, close
from .tolerance import escalate

_SEED = 909


#: The two disc emitters the check draws from, (mean count, variance, radius in m): the
#: second catches an answer that ignores its arguments.
EMITTERS = ((12.25, 6.0, 2.0), (3.4, 2.0, 0.5))
_FRAMES = 4000


def _which(failed: list) -> str:
    """``" (with mean 3.4, variance 2, R = 0.5)"`` for the emitters in ``failed``."""
    return "; ".join(f"with mean {m:g}, variance {v:g}, R = {r:g}: {what}" for (m, v, r), what in failed)


def _radius_hint(draws) -> Hint:
    """Name a wrong radius law from the fractions within R/2 and beyond 0.9 R (a quarter and
    19 % when uniform by area)."""
    inner = [np.mean(np.hypot(*p.T) < r / 2) for (_, _, r), _, p in draws]
    outer = [np.mean(np.hypot(*p.T) > 0.9 * r) for (_, _, r), _, p in draws]
    if all(abs(i - 0.5) < 0.03 and abs(o - 0.1) < 0.02 for i, o in zip(inner, outer, strict=True)):
        return escalate("r = R u crowds the centre: how does the area within radius r grow with r?",
                        "it grows as r², so draw r = R √u to give equal areas equal numbers of "
                        "particles")
    if all(i < 0.01 for i in inner):
        return ("the particles sit on the rim: that is a ring, not a disc",
                "the particles sit on the rim: that is a ring, not a disc; draw r = R √u")
    if all(o < 0.01 for o in outer):
        return escalate("no particle reaches the rim: is the square root taken of the right thing?",
                        "r = R √u reaches R when u reaches 1; √(R u) stops at √R")
    return None


def _disc_hint(pts, radius) -> Hint:
    corners = np.all(np.abs(pts) <= radius * (1 + 1e-12), axis=1).all()
    if corners and abs(np.mean(np.hypot(*pts.T) > radius) - (1 - np.pi / 4)) < 0.02:
        return escalate("x and y drawn independently fill a square, not a disc",
                        "draw a radius and an angle")
    if radius < 1 and abs(np.hypot(*pts.T).max() - np.sqrt(radius)) < 0.01 * radius:
        return escalate(f"the farthest particle is at √R = {np.sqrt(radius):.3f}, not R = {radius:g}: is the "
                        "square root taken of R u instead of u?", "r = R √u reaches R when u reaches 1; "
                        "√(R u) reaches √R, beyond R when R < 1")
    return escalate("some particles land outside the disc: can your radius exceed `radius`?",
                    "draw the radius so that it never exceeds R (r = R √u with u = rng.random(k)) and "
                    "the angle over a full turn")


@exercise(allow=())
def emit(ck: Checker, func) -> None:
    """``func(mean, variance, radius, rng) -> (k, 2)``: this frame's new particles, judged
    statistically over 4000 frames of each of the two :data:`EMITTERS`."""
    a = np.asarray(func(*EMITTERS[0], np.random.default_rng(1)), dtype=float)
    b = np.asarray(func(*EMITTERS[0], np.random.default_rng(1)), dtype=float)
    if not ck.expect(a.shape == b.shape and np.array_equal(a, b),
                     "the same seed gives the same particles",
                     "two generators with the same seed gave different results",
                     hint="draw every random number from the generator `rng` you are given "
                          "(rng.uniform, rng.random), not from np.random or random"):
        return
    draws = [(e, *_cases.counts_and_points(func, *e, _FRAMES, _SEED)) for e in EMITTERS]
    (e1, _, _), (e2, c2, p2) = draws
    far2 = float(np.hypot(*p2.T).max()) if p2.size else 0.0
    fixed = [name for name, same in (
        ("the count", abs(c2.mean() - e1[0]) < 4 * np.sqrt((e1[1] ** 2 / 3 + 0.25) / _FRAMES)),
        ("the radius", abs(far2 - e1[2]) < 0.01 * e1[2])) if same]
    if not ck.expect(not fixed, "the counts and the disc follow the arguments",
                     f"with mean {e2[0]:g}, variance {e2[1]:g} and radius {e2[2]:g}, {' and '.join(fixed)} "
                     f"came out as for mean {e1[0]:g}, variance {e1[1]:g} and radius {e1[2]:g} (mean "
                     f"count {c2.mean():.2f}, farthest particle at {far2:.3f})",
                     hint="use the arguments mean, variance and radius: the check calls your "
                          "function for two different emitters"):
        return
    names = " and ".join(f"{m:g} ± {v:g}" for m, v, _ in EMITTERS)
    outside = [(e, c) for e, c, _ in draws
               if c.min() < np.floor(e[0] - e[1]) or c.max() > np.ceil(e[0] + e[1])]
    ck.expect(not outside, f"every count lies in [mean - variance, mean + variance] ({names})",
              _which([(e, f"counts ranged over [{c.min()}, {c.max()}]") for e, c in outside]),
              hint=_counts.range_hint([c for _, c in outside]))
    se = [np.sqrt((v**2 / 3 + 0.25) / _FRAMES) for _, v, _ in EMITTERS]
    bad = [(e, f"it was {c.mean():.3f}") for (e, c, _), s in zip(draws, se, strict=True)
           if abs(c.mean() - e[0]) >= 4 * s]
    hint = None
    if all(abs(c.mean() - (m + v / 2)) < 4 * s for ((m, v, _), c, _), s in zip(draws, se, strict=True)):
        hint = "rng.random() is uniform on [0, 1); the spread must be symmetric: U(-1, 1)"
    elif rule := _counts.rounding_rule([c.mean() for _, c, _ in draws], EMITTERS, se):
        hint = _counts.ROUNDING_HINTS[rule]
    ck.expect(not bad, f"the mean count over {_FRAMES} frames is the mean asked for ({names})",
              _which(bad), hint=hint)
    ok, detail, rule = _counts.rounding_case(
        _cases.counts_and_points(func, *_counts.ROUNDING_EMITTER, _FRAMES, _SEED)[0])
    whole = _counts.ROUNDING_HINTS.get(rule, None if bad else _counts.ROUNDING_GENERIC)
    ck.expect(ok, "the mean count stays exact when 2 × variance is not whole ({:g} ± {:g})".format(
              *_counts.ROUNDING_EMITTER), detail, hint=None if bad and whole == hint else whole)
    bad = [(e, f"its standard deviation was {c.std():.2f}; mean + variance × U(-1, 1), rounded, "
               f"gives {np.sqrt(e[1]**2 / 3 + 1 / 8):.2f}") for e, c, _ in draws
           if abs(c.std() / np.sqrt(e[1] ** 2 / 3 + 1 / 8) - 1) >= 0.08]
    ck.expect(not bad, "the count varies from frame to frame as Reeves' rule says", _which(bad),
              hint=_counts.count_variance_hint(draws))
    far = [(e, f"the farthest was at {np.hypot(*p.T).max():.3f}", p) for e, _, p in draws
           if np.hypot(*p.T).max() > e[2] * (1 + 1e-12)]
    radii = " and ".join(f"{e[2]:g}" for e in EMITTERS)
    if not ck.expect(not far, f"every particle lies on the disc (R = {radii})",
                     _which([(e, what) for e, what, _ in far]),
                     hint=_disc_hint(far[0][2], far[0][0][2]) if far else None):
        return
    pooled = [(np.linalg.norm(p, axis=1) / e[2], c, p) for e, c, p in draws]
    area = np.concatenate([(r**2) for r, _, _ in pooled])   # uniform on [0, 1] if sampled right
    turn = np.concatenate([np.mod(np.arctan2(p[:, 1], p[:, 0]), 2 * np.pi) / (2 * np.pi)
                           for _, _, p in pooled])
    counts = np.concatenate([c for _, c, _ in pooled])
    first = _cases.pairs_within_frames(counts)
    within = max(_cases.dependence(area[first], area[first + 1]),
                 _cases.dependence(turn[first], turn[first + 1]))
    apart = ck.expect(within < _cases.CHI2_LIMIT,
                      f"the particles of a frame are independent of each other ({first.size} pairs)",
                      f"χ² = {within:.0f} on a 4 × 4 table of the radii (or angles) of neighbours in "
                      f"a frame; independent particles stay below {_cases.CHI2_LIMIT:.0f} in all but "
                      "one run in a million",
                      hint=escalate("the particles of one frame depend on each other: does each particle get "
                                    "its own random numbers?",
                                    "draw the k radii and the k angles at once (rng.random(k)), one of "
                                    "each per particle; do not share, sort or space them out"))
    n_pts = area.size
    se = np.sqrt(0.25 * 0.75 / n_pts)
    inner, outer = np.mean(area < 0.25), np.mean(area > 0.81)
    hint = _radius_hint(draws)
    ck.expect(abs(inner - 0.25) < 4 * se, "a quarter of the particles lie within R/2 (uniform by area)",
              f"the fraction was {inner:.3f}", hint=hint)
    ck.expect(abs(outer - 0.19) < 4 * np.sqrt(0.19 * 0.81 / n_pts),
              "19 % of the particles lie beyond 0.9 R (uniform by area)", f"the fraction was {outer:.3f}",
              hint=hint)
    quadrants = np.array([np.mean((turn > 0) & (turn < 0.25)), np.mean((turn > 0.5) & (turn < 0.75))])
    ck.expect(np.all(np.abs(quadrants - 0.25) < 4 * se), "all directions are equally likely",
              f"fractions in the first and third quadrants: {quadrants.round(3)}",
              hint=escalate("the angle does not cover a full turn evenly",
                            "draw the angle uniformly over a full turn, rng.uniform(0, 2π)"))
    stat = _cases.dependence(area, turn)
    ck.expect(stat < _cases.CHI2_LIMIT, "radius and angle are independent (χ² on a 4 × 4 table)",
              f"χ² = {stat:.0f} on the table of r²/R² against the angle, with 9 degrees of freedom; "
              f"independent ones stay below {_cases.CHI2_LIMIT:.0f} in all but one run in a million",
              hint=None if not apart else
              escalate("the radius and the angle move together: are they drawn from the same random numbers?",
                       "draw the radii and the angles from separate calls to rng: one u used for "
                       "both r = R√u and θ = 2πu puts every particle on one spiral"))


# --- the expire step ---------------------------------------------------------------------

#: Lines of Python an answer may run per case: a mask and one gather per array take about
#: ten; a loop over the particles takes at least one per particle (200 in the second case).
_EXPIRE_LINES = 60


def _same_rows(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` holds the rows of ``b`` in some order (the same multiset of rows)."""
    a, b = a.reshape(len(a), -1), b.reshape(len(b), -1)
    if a.shape != b.shape:
        return False
    return bool(np.array_equal(a[np.lexsort(a.T[::-1])], b[np.lexsort(b.T[::-1])]))


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
    if not found and m == survivors and wrong and all(
            _same_rows(work[k][:survivors], expected[k]) for k in data):
        return escalate("keep the survivors in their original order",
                        f"every survivor is there, but the rows of {wrong} are in another order: gather "
                        "them with the boolean mask, which keeps the order of the rows it selects")
    if not found and m == survivors and len(wrong) < len(data):
        return f"move the rows of every attribute, not only some: wrong in {wrong}"
    return None


@exercise(allow=())
def expire(ck: Checker, func) -> None:
    """``func(data, n) -> m``: delete the expired among the first ``n`` rows, in place,
    with no loop over the particles (at most :data:`_EXPIRE_LINES` lines of Python run).
    Ages are counted (``steps × dt``), so one that has reached its lifetime may lie a unit
    of round-off below it: the reference is :func:`course_lib.particles.reached`."""
    rng = np.random.default_rng(_SEED)
    cases = [("9 live of 12 rows at 24 frames per second, some exactly at their lifetime", 9, 12),
             ("200 live of 256 rows", 200, 256), ("no live particle", 0, 8)]
    data = _cases.expire_frame(rng, 6, 6)
    data["age"][:] = 0.0
    cases_data = [(what, _cases.expire_frame(rng, n, cap), n) for what, n, cap in cases]
    cases_data.append(("nobody expires", data, 6))
    for what, data, n in cases_data:
        keep = ~particles.reached(data["age"][:n], data["lifetime"][:n])
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
                      hint=escalate("no loop over particles: one boolean mask of the survivors, then one "
                                    "gather per array",
                                    "build the mask of the survivors once; then, for every array in data, "
                                    "copy the rows where the mask is True to the front in one operation"))
            continue
        if any(work[k] is not arrays[k] for k in arrays):
            ck.expect(False, what, "your function replaced arrays in `data` by new ones",
                      hint="write into the preallocated arrays (data[k][:m] = ...), which the "
                           "particle system keeps; do not rebind data[k]")
            continue
        if m is None or not np.isscalar(m) or int(m) != m:
            shown = (f"an array of shape {np.shape(m)}" if np.ndim(m) else repr(m))[:80]
            ck.expect(False, what, f"expected the new live count (an int), got {shown}",
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
    spread_right, at_lifetime = True, False
    for what, mu, dt, life, var in _cases.population_cases():
        expected = particles.expected_population(mu, dt, life, var)
        got = func(mu.copy(), dt, life, var)
        # the fine points of fixed lifetimes are named only once spread lifetimes come out
        # right: a wrong answer can match one of their mistakes on a fixed lifetime by chance
        named = var > 0 or spread_right
        right = close(ck, got, expected, what, rtol=1e-9, atol=1e-9,
                      mistakes=_cases.wrong_populations(mu, dt, life, var, at_lifetime) if named else None,
                      hint=None if not named else
                      escalate("check the survival function at a few ages by hand",
                               "write S(a), the chance that a particle is still alive at age a (for V > 0 "
                               "and for V = 0); then add up, for every earlier frame, its count times S "
                               "at the age its particles have when they are counted"))
        spread_right = spread_right and (right or var == 0)
        # a case that counting the age L itself (a <= L) alone explains names it first in the
        # later cases, where summed ages would give the same numbers
        at_lifetime = at_lifetime or _cases.shows_at_lifetime(got, expected, mu, dt, life, var)
