"""Notebook 10's exercise checks against the mistakes a fourth blind read planted: a loop
over the pairs in the separation rule ("Vectorize"), a sweep along one axis written as a
loop over the points in the grid search, and two ring mistakes that give the same radius
for one n. Each answer is written the way a notebook cell writes it."""

import numpy as np
import pytest
from test_nb10_flocking import _SWEEP, _grid_source

from course_lib.check import FAILURES, evaluate
from course_lib.check import _nb10_cases as cases
from course_lib.check import nb10 as check
from course_lib.lessons import nb10_flocking as lesson


def answer(source: str, name: str):
    """A function defined the way a notebook cell defines it (module ``__main__``)."""
    namespace = {"__name__": "__main__", "np": np}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


def judged(check_fn, func, attempt: int = 0) -> tuple[str, list[str]]:
    """(status, failure messages) of ``func``, as after ``attempt`` wrong tries."""
    FAILURES.pop(check_fn.key, None)
    if attempt:
        FAILURES[check_fn.key] = attempt
    try:
        verdict = evaluate(check_fn, func)
    finally:
        FAILURES.pop(check_fn.key, None)
    return verdict["status"], verdict["failed_cases"]


_FIRST_VERDICTS: dict[str, tuple[str, list[str]]] = {}


def judged_source(check_fn, source: str, name: str) -> tuple[str, list[str]]:
    """:func:`judged` of the answer ``source`` defines, at the first try, once per module:
    two tests below read the same verdict of one slow answer."""
    key = f"{check_fn.key}\n{source}"
    if key not in _FIRST_VERDICTS:
        _FIRST_VERDICTS[key] = judged(check_fn, answer(source, name))
    status, failed = _FIRST_VERDICTS[key]
    return status, list(failed)


# --- Exercise 1: "Vectorize" is checked --------------------------------------------------

SEPARATION = {
    "np.add.at": ("""
def separation(i, j, d, n):
    S = np.zeros((n, 2))
    np.add.at(S, i, -d / np.einsum("pk,pk->p", d, d)[:, None])
    return S
""", "correct"),
    "np.bincount, a loop over the two columns": ("""
def separation(i, j, d, n):
    w = d / (d ** 2).sum(axis=1)[:, None]
    S = np.zeros((n, 2))
    for k in range(2):
        S[:, k] = -np.bincount(i, w[:, k], minlength=n)
    return S
""", "correct"),
    "a loop over the pairs": ("""
def separation(i, j, d, n):
    S = np.zeros((n, 2))
    for p in range(len(i)):
        S[i[p]] -= d[p] / (d[p] @ d[p])
    return S
""", "incorrect"),
    "a loop over the boids": ("""
def separation(i, j, d, n):
    w = d / (d ** 2).sum(axis=1)[:, None]
    S = np.zeros((n, 2))
    for b in range(n):
        S[b] = -w[i == b].sum(axis=0)
    return S
""", "incorrect"),
    "a loop over zip(i, d), accumulating in a list": ("""
def separation(i, j, d, n):
    S = [[0.0, 0.0] for _ in range(n)]
    for a, (dx, dy) in zip(i.tolist(), d.tolist()):
        r2 = dx * dx + dy * dy
        S[a][0] -= dx / r2
        S[a][1] -= dy / r2
    return np.array(S)
""", "incorrect"),
}


@pytest.mark.parametrize("name", sorted(SEPARATION))
def test_separation_refuses_a_python_loop(name):
    source, status = SEPARATION[name]
    got, failed = judged(check.separation, answer(source, "separation"))
    assert got == status, (name, failed)
    if status == "incorrect":        # every case fails for the loop and says how to vectorize
        assert len(failed) == 2 and all("lines of Python" in f for f in failed), failed
        assert all("loops over the pairs" in f and "np.add.at or np.bincount" in f
                   for f in failed), failed
        more = judged(check.separation, answer(source, "separation"), attempt=1)[1]
        assert all("np.add.at(S, i, -w)" in f for f in more), more


def test_separation_budget_separates_a_loop_from_a_formula():
    """The budget lies between what a vectorized answer runs (a handful of lines, ten with
    a loop over the two columns) and what a loop over the fewest pairs or boids of any case
    runs (two lines per iteration)."""
    rng = np.random.default_rng(check._SEED)
    i = check._case(30, 8.0, rng, True)[3]
    assert 10 < check.SEPARATION_LINES < 2 * min(len(i), 30)


# --- Exercise 2: the hint the evidence of every case points to ---------------------------

def _mistake_answer(k: int):
    """An answer that makes ring mistake ``k`` in every case (the right radius where that
    mistake is undefined), its radii worked out beforehand (an answer may not call the
    library)."""
    table = {}
    for n, ws, wc in check.RING_CASES:
        r = lesson.ring_radius(n, ws, wc)
        wrong = cases.ring_mistakes(n, ws, wc, r)[k][1]
        table[n, ws, wc] = r if wrong is None else float(wrong)
    return lambda n, w_s, w_c: table[n, w_s, w_c]


MISTAKES = range(len(cases.ring_mistakes(3, 0.3, 1.0, 1.0)))


@pytest.mark.parametrize("k", MISTAKES)
def test_each_ring_mistake_gets_its_own_hint_in_every_case(k):
    """The class of the n = 3 misdiagnosis: whichever mistake an answer makes, every case it
    fails names that mistake, even where another mistake gives the same radius."""
    nudge, more = (h for h in cases.ring_mistakes(3, 0.3, 1.0, 1.0)[k][0])
    status, failed = judged(check.ring_radius, _mistake_answer(k))
    assert status == "incorrect" and failed
    assert all(nudge in f for f in failed), (k, failed)
    assert all(more in f for f in judged(check.ring_radius, _mistake_answer(k), attempt=1)[1])


def test_cohesion_to_the_centre_of_all_n_is_named_on_three_boids():
    """The reviewer's case: for n = 3 that mistake gives √(w_s/w_c), the pair's spacing, and
    the check called it a chord; the other four cases say what it is."""
    source = "def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * (n - 1) / (2 * w_c))"
    assert np.isclose(np.sqrt(0.3 * 2 / 2), np.sqrt(0.3))             # the coincidence
    _, failed = judged(check.ring_radius, answer(source, "ring_radius"))
    (three,) = [f for f in failed if f.startswith("3 boids")]
    assert "centre of the *other* n - 1" in three and "circle" not in three
    assert len(failed) == 5 and all("centre of the *other* n - 1" in f for f in failed)
    # and the pair's spacing for every n is still told it is a distance, n = 3 included
    _, failed = judged(check.ring_radius, answer(
        "def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s / w_c)", "ring_radius"))
    assert all("distance between two boids" in f for f in failed), failed



def test_the_missing_half_is_named_on_two_boids_too():
    """Sixth read: r² = w_s (n - 1)²/(n w_c) (the radial part of each push taken as 1/r) gives
    on n = 2 the radius of cohesion towards all n, and the check said "leave the boid itself
    out of the mean". The other four cases show which mistake it is."""
    source = "def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * (n - 1) ** 2 / (n * w_c))"
    status, failed = judged(check.ring_radius, answer(source, "ring_radius"))
    assert status == "incorrect" and len(failed) == 5
    assert all("1/(2r), not 1/r" in f for f in failed), failed
    assert not any("centre of the *other* n - 1 boids, not of all n" in f for f in failed)
    _, failed = judged(check.ring_radius, answer(source, "ring_radius"), attempt=1)
    assert all("w_s (n - 1)/(2r) outwards" in f for f in failed), failed
    # and cohesion towards all n is still named on two boids
    source = "def ring_radius(n, w_s, w_c):\n    return np.sqrt(w_s * (n - 1) / (2 * w_c))"
    _, failed = judged(check.ring_radius, answer(source, "ring_radius"))
    (two,) = [f for f in failed if f.startswith("2 boids")]
    assert "centre of the *other* n - 1" in two and "1/(2r)" not in two


def test_two_boids_alone_get_a_hint_that_covers_both_mistakes():
    """Right for n >= 3 but √(w_s/(2 w_c)) for a pair: nothing tells the two mistakes apart,
    so the hint says what a pair balances (|d| = 2r), true whichever slip was made."""
    source = ("def ring_radius(n, w_s, w_c):\n"
              "    if n == 2:\n        return np.sqrt(w_s / (2 * w_c))\n"
              "    return np.sqrt(w_s * (n - 1) ** 2 / (2 * n * w_c))")
    status, failed = judged(check.ring_radius, answer(source, "ring_radius"))
    assert status == "incorrect" and len(failed) == 1 and failed[0].startswith("2 boids"), failed
    assert "push is w_s/|d| along the chord" in failed[0] and "|d| = 2r" in failed[0]
    assert "leave the boid itself out" not in failed[0] and "not 1/r" not in failed[0]
    _, failed = judged(check.ring_radius, answer(source, "ring_radius"), attempt=1)
    assert "√2 times that" in failed[0]


@pytest.mark.parametrize("ws, wc", [(0.3, 1.0), (2.0, 0.5), (0.05, 3.0)])
def test_ring_hints_decide_a_pair_by_the_other_cases(ws, wc):
    """The class, on weights of our own: a pair's radius √(w_s/(2 w_c)) is read as the
    mistake the other cases show, and as both only when they show neither."""
    pair = np.sqrt(ws / (2 * wc))
    r = {n: lesson.ring_radius(n, ws, wc) for n in (2, 4, 7)}
    no_half = {n: np.sqrt(ws * (n - 1) ** 2 / (n * wc)) for n in (4, 7)}
    all_n = {n: np.sqrt(ws * (n - 1) / (2 * wc)) for n in (4, 7)}
    assert np.isclose(pair, np.sqrt(ws * 1 ** 2 / (2 * wc)))           # both slips, n = 2
    for others, hint in ((no_half, cases.NO_HALF_HINT), (all_n, cases.ALL_N_HINT),
                         ({n: None for n in (4, 7)}, cases.TWO_BOIDS_HINT)):
        got = cases.ring_hints([(2, ws, wc, r[2], pair)]
                               + [(n, ws, wc, r[n], others[n]) for n in (4, 7)])
        assert got[0] == hint


# --- Exercise 3: a sweep fails however it is written --------------------------------------

#: Sort by x, then compare each point with the points less than R to its right, in a
#: Python loop over the points (the reviewer's sweep that passed 8/8).
SWEEP_LOOP = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    order = np.argsort(x[:, {axis}])
    xs = x[order]
    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]
    for a in range(len(xs)):
        hi = np.searchsorted(xs[:, {axis}], xs[a, {axis}] + radius, "right")
        d = xs[a + 1:hi] - xs[a]
        near = np.flatnonzero((d ** 2).sum(axis=1) <= radius ** 2) + a + 1
        i_all.append(np.full(near.size, a))
        j_all.append(near)
    i, j = order[np.concatenate(i_all)], order[np.concatenate(j_all)]
    return np.minimum(i, j), np.maximum(i, j)
"""

#: The same sweep, its pairs collected one by one in lists.
SWEEP_LISTS = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    order = np.argsort(x[:, 0])
    xs = x[order]
    i, j = [], []
    for a in range(len(xs)):
        hi = np.searchsorted(xs[:, 0], xs[a, 0] + radius, "right")
        d = xs[a + 1:hi] - xs[a]
        for b in np.flatnonzero((d ** 2).sum(axis=1) <= radius ** 2):
            i.append(order[a])
            j.append(order[a + 1 + b])
    i, j = np.array(i, dtype=int), np.array(j, dtype=int)
    return np.minimum(i, j), np.maximum(i, j)
"""

#: The same sweep in pure Python (a while loop along the strip).
SWEEP_PURE = """
def neighbour_pairs(x, radius):
    order = np.argsort(np.asarray(x)[:, 0])
    xs = np.asarray(x, dtype=float)[order].tolist()
    i, j = [], []
    for a in range(len(xs)):
        b = a + 1
        while b < len(xs) and xs[b][0] - xs[a][0] <= radius:
            if (xs[b][0] - xs[a][0]) ** 2 + (xs[b][1] - xs[a][1]) ** 2 <= radius ** 2:
                i.append(order[a])
                j.append(order[b])
            b += 1
    i, j = np.array(i, dtype=int), np.array(j, dtype=int)
    return np.minimum(i, j), np.maximum(i, j)
"""

#: A grid that loops in Python over every point and looks up its 3 × 3 cells in a dict.
GRID_POINT_LOOP = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, dtype=float)
    cells = {}
    keys = [tuple(c) for c in np.floor(x / radius).astype(int).tolist()]
    for k, c in enumerate(keys):
        cells.setdefault(c, []).append(k)
    i, j = [], []
    for k, (cx, cy) in enumerate(keys):
        near = [m for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                for m in cells.get((cx + dx, cy + dy), ()) if m > k]
        i.extend([k] * len(near))
        j.extend(near)
    i, j = np.array(i, dtype=int), np.array(j, dtype=int)
    d = x[j] - x[i]
    keep = (d ** 2).sum(axis=1) <= radius ** 2
    return i[keep], j[keep]
"""

#: A vectorized grid: points sorted by cell, each neighbouring cell found by searchsorted
#: (the right answer that test_nb10_flocking varies one mistake at a time).
GRID_VECTORIZED = _grid_source()

NEIGHBOURS = {
    "a sweep along x, a loop over the points": (SWEEP_LOOP.format(axis=0), "sweep along x"),
    "a sweep along y, a loop over the points": (SWEEP_LOOP.format(axis=1), "sweep along y"),
    "a sweep along x, pairs appended one by one": (SWEEP_LISTS, "sweep along x"),
    "a sweep along x in pure Python": (SWEEP_PURE, "sweep along x"),
    "a grid that loops over every point": (GRID_POINT_LOOP, None),
    "a vectorized grid": (GRID_VECTORIZED, None),
}


@pytest.mark.parametrize("name", sorted(NEIGHBOURS))
def test_a_sweep_fails_the_grid_exercise_however_written(name):
    source, nudge = NEIGHBOURS[name]
    status, failed = judged_source(check.neighbour_pairs, source, "neighbour_pairs")
    if nudge is None:                      # a grid passes, a loop over the points included
        assert status == "correct", (name, failed)
        return
    assert status == "incorrect" and any(nudge in f for f in failed), (name, failed)
    # the right pairs: only the cost fails, on a band or (after a band) on 8000 points, and
    # every failure names the sweep, never all pairs
    assert all("band" in f or "points to a sweep along one axis" in f for f in failed), failed
    assert any("band" in f for f in failed) and not any("all pairs" in f for f in failed), failed


def test_band_cost_separates_grid_and_sweep_with_margin():
    """The bytes allocated on a band over those on the square: a grid's about 1, a looped
    sweep's about 6 (its per-point overhead dilutes the strip's 20-fold growth); the limit
    lies a factor of 1.5 or more from both (a grid that loops over the points passes the
    check above)."""
    x = {role: pts for _, pts, _, role in cases.grid_cases(check._SEED + 3) if role in ("base", "band")}
    square = x["base"]
    band = [pts for _, pts, _, role in cases.grid_cases(check._SEED + 3) if role == "band"]
    assert len(band) == 2 and np.allclose(band[0], band[1][:, ::-1])
    assert np.ptp(band[0], axis=0) == pytest.approx(cases.BAND, rel=0.01)
    assert np.prod(cases.BAND) == pytest.approx(np.ptp(square, axis=0).prod(), rel=0.01)  # same density

    def ratio(source, pts):
        func = answer(source, "neighbour_pairs")
        return cases.measured(func, pts, 1.0)[2] / cases.measured(func, square, 1.0)[2]

    assert max(ratio(GRID_VECTORIZED, pts) for pts in band) < cases.SHAPE_LIMIT / 1.5   # 0.87
    assert ratio(SWEEP_LOOP.format(axis=0), band[0]) > 2 * cases.SHAPE_LIMIT
    assert ratio(SWEEP_LOOP.format(axis=1), band[1]) > 2 * cases.SHAPE_LIMIT


# --- the twins at 35 s: a bound that holds for any rounding -------------------------------

@pytest.mark.roundoff
def test_twins_within_a_tenth_of_a_millimetre_after_35_s_under_any_rounding():
    """Cell 20 quotes the twins of seed 0 "within 0.1 mm after 35 s". Another machine rounds
    differently, so its twins are other draws of the same round-off: here the notebook's
    reversed numbering, five random numberings and one-ulp nudges of three boids. Their
    distances at 35 s spread (1.3e-6 to 4.2e-6 m for the numberings, 1.4e-10 to 8.8e-10 m
    for the nudges); the worst, 4.2e-6 m, times e² (two e-foldings, 4 to 6 s of growth)
    stays below 0.1 mm, while the 10 μm once quoted would leave a factor of 2.4, less than
    one e-folding."""
    from course_lib import boids
    from course_lib.lessons import nb10_studies as studies
    rules = boids.Rules(box=studies.BOX)
    x, v = boids.random_flock(studies.N_BOIDS, studies.BOX, 1.0, np.random.default_rng(0))
    steps = round(35 / studies.DT)
    rng = np.random.default_rng(35)
    twins = [np.arange(len(x))[::-1]] + [rng.permutation(len(x)) for _ in range(5)]
    starts = [(x[p].copy(), v[p].copy(), np.argsort(p)) for p in twins]
    for b in (0, 50, 100):
        nudged = x.copy()
        nudged[b, 1] = np.nextafter(nudged[b, 1], np.inf)
        starts.append((nudged, v.copy(), slice(None)))
    xa, va = x, v
    states = [(xb, vb) for xb, vb, _ in starts]
    for _ in range(steps):
        xa, va = boids.step(xa, va, studies.DT, rules)
        states = [boids.step(xb, vb, studies.DT, rules) for xb, vb in states]
    distance = np.array([studies.rms_distance(xa, xb[back], studies.BOX)
                         for (xb, _), (_, _, back) in zip(states, starts, strict=True)])
    assert distance.max() * np.e**2 < 1e-4                       # "within 0.1 mm after 35 s"
    assert distance[:6].min() > 1e-8                            # the numberings have diverged
    t, d, _ = studies.divergence(0, steps, "order")             # the notebook's own twin
    assert d[-1] == pytest.approx(distance[0], rel=1e-6) and t[-1] == pytest.approx(35.0)


# --- the grader replays the same path ----------------------------------------------------

TABLE = """
def neighbour_pairs(x, radius):
    d2 = ((x[None, :, :] - x[:, None, :]) ** 2).sum(axis=-1)
    near = np.triu(d2 <= radius ** 2, 1)
    i, j = np.nonzero(near)
    return i, j
"""

ROWS = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, float)
    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]
    for k in range(len(x) - 1):
        d = x[k + 1:] - x[k]
        near = np.flatnonzero(d[:, 0] ** 2 + d[:, 1] ** 2 <= radius ** 2)
        i_all.append(np.full(near.size, k))
        j_all.append(near + k + 1)
    return np.concatenate(i_all), np.concatenate(j_all)
"""

#: the sweep of test_nb10_flocking's planted answers, one source for both files
VECTORIZED_SWEEP = _SWEEP


@pytest.mark.parametrize("name, source, hint", [
    ("a vectorized grid", GRID_VECTORIZED, None),
    # a sweep, vectorized: its band stop is raised inside the answer as a looped sweep's is
    ("a vectorized sweep", VECTORIZED_SWEEP, "sweep along x"),
    ("an N × N table", TABLE, "N × N table"),
    ("all pairs, a row at a time", ROWS, "all pairs"),
])
def test_the_grader_replays_the_cost_verdicts(name, source, hint):
    """The grader replays recorded answers and cannot measure them; the cost verdicts reach
    it as the stops raised inside the answer, so its check takes the notebook's path (a path
    that depended on bytes counted after the answer returned read as tampering) and fails
    what the notebook fails."""
    import contextlib
    import io
    import json

    from course_lib.instructor.recorder import Recorder
    from course_lib.instructor.verdicts import judge

    recorder = Recorder(answer(source, "neighbour_pairs"), 8 << 20)
    with contextlib.redirect_stdout(io.StringIO()):
        notebook = evaluate(check.neighbour_pairs, recorder)
    record = json.loads(json.dumps({"calls": recorder.calls}))
    status, message, details = judge(check.neighbour_pairs, record, 60)
    if hint is None:
        assert notebook["status"] == status == "correct", (name, message)
        return
    assert notebook["status"] == "incorrect" and status in ("incorrect", "error"), (name, status, message)
    assert any(hint in f for f in notebook["failed_cases"]), notebook["failed_cases"]
    assert status == "error" or any(hint in f for f in details["failed_cases"]), (status, message)


# --- the prompts say what the checks do ---------------------------------------------------

def test_prompts_quote_the_checks_and_the_known_values():
    """Cell 36 quotes the separation budget, cell 41 the band and the sizes the grid check
    uses, cell 14 calls the random flock's values known (the polarization's is a central
    limit), and cell 20 quotes the twins' 35 s bound that test above asserts."""
    import nbformat
    from notebook_helpers import ROOT
    cells = [c.source for c in nbformat.read(ROOT / "solutions" / "10_flocking.ipynb", as_version=4).cells]
    text = " ".join(" ".join(c.split()) for c in cells)
    ex1 = " ".join(next(c for c in cells if "### Exercise 1" in c).split())
    ex3 = " ".join(next(c for c in cells if "### Exercise 3" in c).split())
    assert f"at most {check.SEPARATION_LINES} lines of Python per case" in ex1
    assert cases.BAND == (2.5, 1000.0) and "a band 2.5 m wide and 1 km long, each way round" in ex3
    sizes = [len(x) for _, x, _, role in cases.grid_cases(check._SEED + 3) if role != "edge"]
    assert sizes == [2000, 2000, 2000, 8000] and "from 2000 to 8000 points" in ex3
    assert "would take 32 MB" in ex3 and 2000**2 * 8 == 32e6 and "eight times" not in ex3
    assert "Both have known values" in text and "exact values for boids" not in text
    assert "within 0.1 mm after 35 s" in text and "10 μm" not in text


# --- a capped measurement is quoted as a lower bound ---------------------------------------

#: All pairs in blocks of 100 rows: never an N × N table, but N² work, so the 8000-point case
#: hits the growth cap (a case of this file's own, beside the reviewer's row-at-a-time loop).
BLOCKS = """
def neighbour_pairs(x, radius):
    x = np.asarray(x, float)
    i_all, j_all = [np.zeros(0, int)], [np.zeros(0, int)]
    for start in range(0, len(x), 100):
        d = x[None, :, :] - x[start:start + 100, None, :]
        a, b = np.nonzero((d ** 2).sum(axis=2) <= radius ** 2)
        a = a + start
        keep = a < b
        i_all.append(a[keep])
        j_all.append(b[keep])
    return np.concatenate(i_all), np.concatenate(j_all)
"""


@pytest.mark.parametrize("name, source", [
    ("all pairs in blocks of 100 rows", BLOCKS),
    ("a sweep looping over the points", SWEEP_LOOP.format(axis=0))])
def test_a_capped_cost_is_quoted_as_at_least(name, source):
    """The check stops measuring once an answer passes its cap, so the ratio it quotes is a
    lower bound: every quoted ratio says "at least" and that the measurement stopped. (All
    pairs a row at a time, the reviewer's loop, is asserted so in test_nb10_flocking's
    planted answers, which run the check on it anyway.)"""
    status, failed = judged_source(check.neighbour_pairs, source, "neighbour_pairs")
    assert status == "incorrect", (name, failed)
    quoted = [f for f in failed if "times what it allocated" in f]
    assert quoted, (name, failed)
    for f in quoted:
        assert "at least" in f and "stopped at that cap" in f, f


# --- the batched measurement: the same bytes, the stops still raised inside -----------------

def test_batched_measurement_counts_every_line_and_stops_inside_the_answer():
    """measured() sums its per-line samples in batches (and at every return): the last line
    before a return still counts (a one-line answer that calls a library was once measured
    as 0 bytes), a few-line answer over its total cap is stopped inside itself, so the
    answer's own ``except Exception`` cannot swallow it and a wrapper sees it raised, and
    a loop of a few hundred lines (longer than a batch) is summed whole."""
    def one_line(x, radius):
        return np.ones((len(x), 1000))                           # 8 MB on 1000 points

    x = np.zeros((1000, 2))
    _, peak, total = cases.measured(one_line, x, 1.0)
    assert 8.0e6 <= total < 8.2e6 and 8.0e6 <= peak < 8.2e6

    def few_lines(x, radius):
        try:
            a = np.ones((len(x), 1000))
            b = a + 1.0
            return b.sum()
        except Exception:
            return None

    with pytest.raises(cases.TooCostly, match=r"allocated more than 10\.0 MB"):
        cases.measured(few_lines, x, 1.0, total_limit=10e6)
    assert cases.measured(few_lines, x, 1.0, total_limit=20e6)[2] > 16e6

    def looped(x, radius):
        out = []
        for _ in range(3 * cases.BATCH):
            out.append(np.ones(1000))                            # 8 kB a line, kept
        return out

    _, _, total = cases.measured(looped, x, 1.0)
    assert 3 * cases.BATCH * 8000 <= total < 3 * cases.BATCH * 9000           # 8112 B an array, the list
    with pytest.raises(cases.TooCostly):
        cases.measured(looped, x, 1.0, total_limit=cases.BATCH * 8000 / 2)

    done = []

    def large(x, radius):
        for step in range(100):
            np.ones(250_000).sum()                               # 2 MB a line, freed
            done.append(step)

    with pytest.raises(cases.TooCostly):
        cases.measured(large, x, 1.0, total_limit=10e6)
    assert len(done) <= 6                                        # stopped at the cap, not 100 lines on
