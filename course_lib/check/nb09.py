"""Checks for notebook 09, particle systems: the emit step and the expire step."""

from __future__ import annotations

import numpy as np

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


@exercise
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
              hint="Reeves' count is mean + variance × U(-1, 1) with U uniform (rng.uniform(-1, 1)), "
                   "not a normal draw: it never leaves [mean - variance, mean + variance]")
    se = np.sqrt((variance**2 / 3 + 0.25) / calls)
    got = counts.mean()
    hint = None
    if abs(got - (mean + variance / 2)) < 4 * se:
        hint = "rng.random() is uniform on [0, 1); the spread must be symmetric: U(-1, 1)"
    elif abs(got - (mean - 0.5)) < 4 * se:
        hint = ("int() truncates and loses half a particle per frame on average: round "
                "instead (round(y), or at random with floor(y + rng.random()))")
    ck.expect(abs(got - mean) < 4 * se, f"the mean count over {calls} frames is {mean}",
              f"it was {got:.3f}", hint=hint)
    spread, uniform = counts.std(), variance / np.sqrt(3)
    hint = None
    if spread < 0.3 * uniform:
        hint = "draw a new count every frame: mean + variance × rng.uniform(-1, 1)"
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
                     hint="x and y drawn independently fill a square; draw a radius and an angle"):
        return
    inner = np.mean(r < radius / 2)
    se = np.sqrt(0.25 * 0.75 / r.size)
    hint = None
    if abs(inner - 0.5) < 4 * np.sqrt(0.25 / r.size):
        hint = ("r = R u crowds the centre: the area within r grows as r², so draw r = R √u "
                "to give equal areas equal numbers of particles")
    elif inner < 0.01:
        hint = "the particles sit on the rim: that is a ring, not a disc; draw r = R √u"
    ck.expect(abs(inner - 0.25) < 4 * se, "a quarter of the particles lie within R/2 (uniform by area)",
              f"the fraction was {inner:.3f}", hint=hint)
    quadrants = np.array([np.mean((pts[:, 0] > 0) & (pts[:, 1] > 0)),
                          np.mean((pts[:, 0] < 0) & (pts[:, 1] < 0))])
    ck.expect(np.all(np.abs(quadrants - 0.25) < 4 * se), "all directions are equally likely",
              f"fractions in the first and third quadrants: {quadrants.round(3)}",
              hint="draw the angle uniformly over a full turn, rng.uniform(0, 2π)")


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


@exercise
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
                hint = ("a particle whose age has reached its lifetime dies: "
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
                hint = "keep the survivors in their original order (data[k][:m] = data[k][:n][alive])"
            else:
                hint = f"move the rows of every attribute, not only some: wrong in {wrong}"
            ck.expect(False, what, f"the first {m} rows of {wrong} are not the survivors", hint=hint)
            continue
        ck.expect(True, what)
