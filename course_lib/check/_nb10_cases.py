"""Case data of notebook 10's check of the uniform-grid neighbour search, and how the
check measures an answer's cost.

- :func:`grid_cases`: point sets that break the usual shortcuts of a grid (pairs at exactly
  the radius in diagonal cells, coincident points, clusters) and four of the same density on
  which the cost is measured (2000 points in a square, the same number in a long narrow band
  each way round, 8000 in a square), and :func:`cost_verdict`, which judges that cost;
- :func:`scatter` and :func:`roundoff_bound`: the separation rule's per-boid sums and the
  round-off they may carry; :func:`ring_mistakes`: the usual wrong radii of Exercise 2, and
  :func:`ring_hints`, which names the one the evidence of every case points to;
- :func:`measured`: runs an answer and returns its result, the peak memory it held and the
  bytes it allocated in all (tracemalloc, sampled at every line of the answer's own code),
  stopping it after :func:`line_limit` lines.

Imports NumPy, the standard library and :func:`~course_lib.check.tolerance.escalate`.
"""

from __future__ import annotations

import sys
import tracemalloc

import numpy as np

from .tolerance import escalate

#: Lines of Python an answer may run on a case of N points: max(LINES_AT_LEAST, LINES_PER_POINT N).
#: A grid that loops in Python over the occupied cells runs about 25 lines per point (180,000
#: for 8000 points); one that loops over every point's candidates too, about 70 (550,000 for
#: 8000 points, 72,000 for 300 points in two tight clusters). Testing all pairs one by one in
#: Python runs three lines per pair, N²/2 pairs (6 × 10⁶ for 2000 points), and is stopped.
LINES_PER_POINT, LINES_AT_LEAST = 100, 250_000


def line_limit(n: int) -> int:
    """Lines of Python an answer may run on ``n`` points."""
    return max(LINES_AT_LEAST, LINES_PER_POINT * n)


class TooLong(BaseException):
    """Raised in an answer that runs more than :func:`line_limit` lines (a BaseException,
    so that the answer's own ``except Exception`` does not swallow it)."""


class TooCostly(BaseException):
    """Raised in an answer whose memory, sampled at a line of its code, passes the limit
    :func:`measured` was given. Raised inside the answer, it is what the grader's worker
    records and replays (the grader never measures the answer itself), so the grader's
    check takes the same path as the notebook's; its message explains itself."""


#: The names the grader's replay gives the two stops (it rebuilds them as plain Exceptions).
STOPS = ("TooLong", "TooCostly")


#: Lines of the answer between two tallies of :func:`measured` (and at every return of one of
#: its frames): the samples wait in a list, so that a line costs one tracemalloc reading.
BATCH = 200
#: Bytes a line may take above what was held at the last tally before :func:`measured` tallies
#: at once (so that a loop of large arrays is stopped at its cap as soon as it passes it).
CHUNK = 1 << 20


def measured(func, *args, held_limit: float = np.inf, total_limit: float = np.inf
             ) -> tuple[object, int, int]:
    """``func(*args)``, the peak memory it held (bytes) and the bytes it allocated in
    total, sampled at every line of the answer's own code: the peak since the previous
    line, above what was held then, summed. Byte counts, not seconds: the same verdict on
    every machine. Stops the answer after :func:`line_limit` lines (:class:`TooLong`), or
    once it has held more than ``held_limit`` bytes at once or allocated more than
    ``total_limit`` in all (:class:`TooCostly`).

    Under tracemalloc every object allocated costs about a microsecond, so a line's sample,
    ``(current, peak)``, is kept as tracemalloc returns it (in one of :data:`BATCH` slots, the
    tuple it replaces freed) and summed at a tally: every :data:`BATCH` lines and whenever one
    of the answer's frames returns, so a stop is still raised inside the answer, and at once
    when a line takes more than :data:`CHUNK` above what was held at the last tally (the held
    limit is tested at every line). About 4 μs a line instead of 6 when each line was summed."""
    limit, get, reset = line_limit(len(args[0])), tracemalloc.get_traced_memory, tracemalloc.reset_peak
    samples: list = [None] * (BATCH + 1)
    k = lines = total = peak_all = held = 0
    bar = min(CHUNK, held_limit)       # a sample's peak above this: tally at once

    def tally():
        nonlocal k, lines, total, peak_all, held, bar
        samples[k] = get()           # closes the interval since the last line's sample
        got = np.array(samples[:k + 1], dtype=np.int64)    # NumPy sums: no Python int a line
        total += int(got[:, 1].sum() - got[:-1, 0].sum()) - held
        peak_all = max(peak_all, int(got[:, 1].max()))
        lines, k = lines + k, 0
        if lines > limit:
            raise TooLong(f"your function ran more than {limit:,} lines of Python")
        if peak_all > held_limit:
            raise TooCostly(f"your function held more than {held_limit / 1e6:.0f} MB at once")
        if total > total_limit:
            raise TooCostly(f"your function allocated more than {total_limit / 1e6:.1f} MB in all")
        held = get()[0]              # after the tally's own objects are freed
        reset()
        bar = min(held + CHUNK, held_limit)

    def line(frame, event, arg):
        nonlocal k
        if event == "line":
            samples[k] = sample = get()
            reset()
            k += 1
            if k == BATCH or sample[1] > bar:
                tally()
        elif event == "return":
            tally()
        return line

    def calls(frame, event, arg):
        module = frame.f_globals.get("__name__", "") or ""
        return None if module.startswith(("numpy", "scipy", "course_lib", "importlib")) else line

    previous = sys.gettrace()
    tracemalloc.start()
    held = get()[0]
    sys.settrace(calls)
    try:
        out = func(*args)
    finally:
        sys.settrace(previous)
        peak = get()[1]
        tracemalloc.stop()
    return out, max(peak_all, peak), total + peak - held


#: A band of the same area as the 2000-point square (2500 m²), 2.5 m by 1 km: a grid's
#: cells hold as many points as in the square, so it costs the same (0.87 times measured);
#: a sweep along the band's width compares each point with a strip 1 km long instead of
#: 50 m (6 times the bytes for a sweep that loops over the points, 16 for a vectorized one).
BAND = (2.5, 1000.0)
#: Largest ratio of the bytes allocated on a band to those on the square (a grid: about 1).
SHAPE_LIMIT = 2.0
#: For four times the points at the same density a grid allocates about four times the
#: memory in total (a neighbourhood of the same size per point; 3.7 to 4.0 measured); all
#: pairs, even a row at a time, sixteen times; a vectorized sweep eight (a sweep that loops
#: over the points, 5.3: its per-point overhead hides the strip; the bands catch it). The
#: geometric mean of a grid's 4 and a sweep's 8:
GROWTH_LIMIT = float(np.sqrt(32.0))


def grid_cases(seed: int):
    """``(what, x, radius, role)``: point sets that break the usual shortcuts of a grid
    search (radius in m; role ``"edge"``), then four of the same density on which the cost
    is measured: 2000 points in a square (``"base"``), 2000 in a band :data:`BAND` each way
    round (``"band"``: the search's cost must not depend on the region's shape) and 8000 in a
    square (``"growth"``: it must grow as N)."""
    rng = np.random.default_rng(seed)
    yield "3-4-5: a pair at exactly the radius (5 m) in diagonal cells, one just beyond", \
        np.array([[0.0, 0.0], [3.0, 4.0], [3.0, np.nextafter(4.0, 5.0) + 1e-9], [-3.0, -4.0]]), 5.0, "edge"
    yield "a row of points exactly one radius apart", np.column_stack((0.5 * np.arange(12.0),
                                                                        np.zeros(12))), 0.5, "edge"
    yield "coincident points and negative coordinates", np.array(
        [[-1.2, -0.3], [-1.2, -0.3], [-0.3, -1.1], [0.4, 0.2], [-2.9, -2.9], [-2.2, -2.1]]), 1.0, "edge"
    yield "one point", np.array([[1.0, 2.0]]), 1.0, "edge"
    yield "no pair at all", np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]), 1.0, "edge"
    yield "300 points in two tight clusters and a sparse cloud", np.concatenate((
        rng.normal(0.0, 0.3, (120, 2)), rng.normal(5.0, 0.2, (80, 2)),
        rng.uniform(-10.0, 15.0, (100, 2)))), 0.7, "edge"
    yield "2000 points in a 50 m square, radius 1 m", rng.uniform(0.0, 50.0, (2000, 2)), 1.0, "base"
    band = rng.uniform(0.0, 1.0, (2000, 2)) * BAND
    yield "2000 points in a band 2.5 m wide and 1 km long in y, radius 1 m", band, 1.0, "band"
    yield "2000 points in a band 2.5 m wide and 1 km long in x, radius 1 m", band[:, ::-1].copy(), 1.0, "band"
    yield "8000 points in a 100 m square, radius 1 m", rng.uniform(0.0, 100.0, (8000, 2)), 1.0, "growth"


#: The hint for a search that is right on a few points but too costly, shared by the verdicts.
GRID_MORE = ("with cells of side radius a point has about 9ρR² candidates whatever N and whatever "
             "the region's shape (ρ the density): compare each point only with the points of its "
             "own and the 8 neighbouring cells")
TABLE_HINT = escalate("that is an N × N table: bin the points into cells instead",
                      "an N × N table of distances grows as N²: bin the points into cells of side radius "
                      "and compare each point only with the points of its own and the neighbouring cells")


def _sweep_hint(x: np.ndarray) -> tuple[str, str]:
    axis = "x" if np.ptp(x[:, 1]) > np.ptp(x[:, 0]) else "y"     # the band is long across x
    return (f"that is a sweep along {axis} (whether a loop or vectorized): each point is compared "
            "with a strip across the whole region, and across this band the strip is 1 km long; "
            "a grid's cells do not care about the region's shape", GRID_MORE)


def cost_verdict(what: str, x: np.ndarray, role: str, total: int, base: int):
    """``(ok, what, detail, hint)`` for an answer that allocated ``total`` bytes in all on
    the points ``x`` of a ``"band"`` or ``"growth"`` case, and ``base`` bytes on the
    2000-point square of the same density."""
    ratio = total / max(base, 1)
    if role == "band":
        return (ratio <= SHAPE_LIMIT, f"{what}: the cost does not depend on the region's shape",
                f"your function allocated {base / 1e6:.1f} MB in all for 2000 points in a 50 m "
                f"square and {total / 1e6:.1f} MB for 2000 at the same density in this band: "
                f"{ratio:.1f} times as much (a grid: about 1, its cells hold as many points)",
                _sweep_hint(x))
    return (ratio <= GROWTH_LIMIT, f"{what}: the cost grows as N",
            f"your function allocated {base / 1e6:.1f} MB in all for 2000 points and "
            f"{total / 1e6:.1f} MB for {len(x)} at the same density: {ratio:.1f} times as much "
            "for 4 times the points (a grid: about 4; all pairs, even a row at a time: 16)",
            ("that grows as N^1.5, like a sweep along one axis: each point meets a strip across "
             "the whole domain, whose length grows with N; a grid's cells do not", GRID_MORE)
            if ratio < 2 * GROWTH_LIMIT else ("that is all pairs, a row at a time: bin the points "
                                              "into cells", GRID_MORE))


def stop_verdict(what: str, x: np.ndarray, role: str, stop: BaseException, swept: bool):
    """``(False, what, detail, hint)`` for an answer :func:`measured` stopped (``stop``, a
    :class:`TooLong` or :class:`TooCostly`, or the grader's replay of one) on a case of
    ``role``; ``swept`` says a band has already found a sweep."""
    if role == "band":
        return False, f"{what}: the cost does not depend on the region's shape", \
            f"{stop} on 2000 points in this band, at least {SHAPE_LIMIT:g} times what it allocated " \
            "for 2000 in the 50 m square (the measurement stopped at that cap; a grid: about the " \
            "same)", _sweep_hint(x)
    swept_hint = ("like the bands, this points to a sweep along one axis: bin the points into "
                  "cells instead", GRID_MORE)
    if type(stop).__name__ == "TooLong":
        return False, what, f"{stop} on {len(x)} points", swept_hint if swept else \
            ("testing every pair in Python takes N²/2 steps: bin the points into cells instead",)
    if role == "base":
        return False, f"{what}: memory held at once", f"{stop} for {len(x)} points", TABLE_HINT
    return False, f"{what}: the cost grows as N", \
        f"{stop} for {len(x)} points, at least {GROWTH_LIMIT:.1f} times what it allocated for 2000 " \
        "(the measurement stopped at that cap)", \
        swept_hint if swept else ("that grows faster than N, like all pairs tested a row at a time "
                                  "(16 times as much for 4 times the points) or a sweep along one "
                                  "axis (8); a grid allocates about 4", GRID_MORE)


# --- the separation rule and the ring ------------------------------------------------------


def scatter(index, w, n):
    """Sum the rows of ``w`` onto ``n`` boids by ``index`` (a pair's term onto its boid)."""
    return np.stack([np.bincount(index, w[:, k], minlength=n) for k in range(w.shape[1])], axis=1)


def roundoff_bound(i, d, n: int, eps: float) -> np.ndarray:
    """A bound (1/m, shape ``(n, 2)``) on the round-off of ``S_i = −Σ d/|d|²``: each term is
    rounded by a few units ``eps`` of its size (|d|² is a sum of two squares, then a
    division), and a sum of ``m`` terms by ``(m − 1) eps`` of the sum of their sizes; four
    times ``(m + 4) eps Σ|term|`` covers any order of summation."""
    size = scatter(i, np.abs(d) / np.einsum("pk,pk->p", d, d)[:, None], n)
    m = np.bincount(i, minlength=n)[:, None]
    return 4.0 * (m + 4) * eps * size


#: Cohesion towards the centre of all n boids, the boid itself included.
ALL_N_HINT = escalate(
    "cohesion points to the centre of the *other* n - 1 boids, not of all n: how far is that "
    "from the boid?", "leave the boid itself out of the mean: the centre of the other n - 1 "
    "lies n/(n - 1) r from it, so cohesion pulls with w_c r n/(n - 1)")
#: Each push's radial part taken as 1/r, not 1/(2r): r² = w_s (n - 1)²/(n w_c).
NO_HALF_HINT = escalate(
    "the radial part of each push d/|d|² is 1/(2r), not 1/r: a chord of length |d| points only "
    "|d|/(2r) of its length towards the centre", "the n - 1 pushes, each 1/(2r) along the "
    "radius, add to w_s (n - 1)/(2r) outwards; set that against cohesion's pull towards the "
    "centre of the other n - 1 boids")
#: For two boids the two mistakes above give the same radius, √(w_s/(2 w_c)): when the
#: other cases do not tell them apart, a hint that holds for both.
TWO_BOIDS_HINT = escalate(
    "with two boids the push is w_s/|d| along the chord and cohesion pulls towards the other "
    "boid, w_c |d|: they balance at |d| = 2r",
    "w_s/|d| = w_c |d| gives |d| = √(w_s/w_c), so r = |d|/2; your radius is √2 times that, "
    "which both a cohesion towards the centre of all n and a radial part 1/r of each push "
    "(instead of 1/(2r)) give")


def ring_mistakes(n: int, ws: float, wc: float, r: float) -> list:
    """The usual wrong radii for the ring of ``n`` boids whose right radius is ``r``, each
    with its hint (nudge, then more)."""
    pair = np.sqrt(ws / wc) / 2
    chords = np.sum(1.0 / (2.0 * np.sin(np.pi * np.arange(1, n) / n)))   # Σ r/|d| over neighbours
    return [
        (escalate("that is the pair's radius for every n: with n boids each one feels n - 1 pushes, and "
                  "cohesion pulls towards the centre of the other n - 1",
                  "add up the radial parts of the n - 1 pushes and set them against the pull of cohesion "
                  "towards the centre of the other n - 1 boids"), pair),
        (escalate("that is a distance between two boids: the exercise asks for the radius of their circle",
                  "return r, the circle's radius; neighbours are 2 r sin(π/n) apart"), 2 * pair),
        (escalate("that is the distance to the nearest neighbour: return the circle's radius",
                  "return r, the circle's radius; neighbours are 2 r sin(π/n) apart"),
         2 * r * np.sin(np.pi / n)),
        (ALL_N_HINT, np.sqrt(ws * (n - 1) / (2 * wc))),
        (NO_HALF_HINT, np.sqrt(ws * (n - 1) ** 2 / (n * wc))),
        (escalate("only the radial part of each push survives: the sideways parts cancel in pairs, so "
                  "adding the pushes' full sizes 1/|d| overcounts",
                  "a chord of length |d| points |d|/(2r) of its length towards the centre, so the radial "
                  "part of d/|d|² is 1/(2r), the same for every neighbour"),
         np.sqrt(ws * (n - 1) * chords / (n * wc)) if n > 2 else None),
        (escalate("check the units: w_s is in m²/s² and w_c in 1/s², and the radius in m",
                  "you returned r²: take the square root"), r * r),
    ]


def ring_hints(cases) -> list:
    """The hint for each of ``cases`` (``(n, w_s, w_c, r, value)``, ``value`` the answer's
    radius or None), from the evidence of every case: two usual mistakes may give the same
    radius for one n (for n = 3 cohesion towards the centre of all n gives √(w_s/w_c), the
    pair's spacing; for n = 2 cohesion towards all n and a radial part 1/r of each push give
    the same), so each case gets, of the mistakes it matches, the one that matches the most
    cases (on a tie, :data:`TWO_BOIDS_HINT` for those two at n = 2, else the first listed);
    None where it matches none."""
    matched = [[hint for hint, wrong in ring_mistakes(n, ws, wc, r)
                if value is not None and wrong is not None and np.isclose(value, wrong, rtol=1e-6)]
               for n, ws, wc, r, value in cases]
    count = {}
    for hints in matched:
        for hint in hints:
            count[hint] = count.get(hint, 0) + 1
    out = []
    for (n, *_), hints in zip(cases, matched, strict=True):
        best = max((count[h] for h in hints), default=0)
        tied = [h for h in hints if count[h] == best]
        out.append(TWO_BOIDS_HINT if n == 2 and {ALL_N_HINT, NO_HALF_HINT} <= set(tied)
                   else tied[0] if tied else None)
    return out
