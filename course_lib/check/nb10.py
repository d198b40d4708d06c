"""Checks for notebook 10, flocking: the separation rule, which weight breaks the flock,
and a neighbour search with a uniform grid.

No answer may call the library (``allow=()``); the neighbour search may not call
``scipy.spatial`` either (the exercise is the grid, not the k-d tree). Its check compares
with the all-pairs reference :func:`course_lib.neighbors.all_pairs` on data that breaks the
usual shortcuts (pairs in diagonal cells, at exactly the radius, coincident points, points
far apart in one wide cell) and measures the memory an answer holds at once, which tells
a grid from an N × N table; on four times the points at the same density it measures the
memory allocated in all (bytes, the same on every machine), which grows fourfold for a grid
and sixteenfold for all pairs tested a row at a time. Case data and the measurement:
:mod:`course_lib.check._nb10_cases`.
"""

from __future__ import annotations

import inspect

import numpy as np

from .. import boids, neighbors
from . import Checker, exercise
from . import _nb10_cases as _cases
from .policy import name_chains

_SEED = 1010


def _case(n, box, rng, isolated=False):
    rules = boids.Rules(box=box)
    x, v = boids.random_flock(n, box, 1.5, rng)
    if isolated:                     # the last boid far from everybody: no neighbour, no push
        x[-1] = x[:-1].mean(axis=0) + box / 2    # (last: an answer sized i.max() + 1 is short)
        x[:-1] = np.mod(x[-1] + box / 2 + rng.uniform(-2.0, 2.0, (n - 1, 2)), box)
    i, j, d = boids.tree_pairs(x, v, rules, sort=False)
    return x, v, rules, i, j, d


def _scatter(index, w, n):
    return np.stack([np.bincount(index, w[:, k], minlength=n) for k in range(w.shape[1])], axis=1)


def _close_rows(ck: Checker, got, expected, what, mistakes) -> None:
    """Like ``Checker.close`` for an (n, 2) answer, but report only the worst boid."""
    if got.shape != expected.shape:
        ck.expect(False, what, f"expected shape {expected.shape}, got {got.shape}")
        return
    if np.allclose(got, expected, rtol=1e-10, atol=1e-12):
        ck.expect(True, what)
        return
    hint = next((h for h, wrong in mistakes.items()
                 if np.allclose(got, wrong, rtol=1e-10, atol=1e-12)), None)
    k = int(np.argmax(np.abs(got - expected).max(axis=1)))
    ck.expect(False, what, f"boid {k}: expected {expected[k].round(6)}, got {got[k].round(6)} "
              f"({int(np.sum(~np.isclose(got, expected).all(axis=1)))} of {len(got)} boids wrong)",
              hint=hint)


@exercise(allow=())
def separation(ck: Checker, func) -> None:
    """``func(i, j, d, n) -> (n, 2)``: ``S_i = −Σ d_ij / |d_ij|²`` over the pairs of ``i``."""
    rng = np.random.default_rng(_SEED)
    cases = [("30 boids, one without neighbours", 30, 8.0, True),
             ("200 boids in a 12 m box", 200, 12.0, False)]
    for what, n, box, isolated in cases:
        x, v, rules, i, j, d = _case(n, box, rng, isolated)
        expected = boids.steering(x, v, rules)[0]               # before the student's code runs
        r2 = np.einsum("pk,pk->p", d, d)
        w = d / r2[:, None]
        count = np.maximum(np.bincount(i, minlength=n), 1)[:, None]
        last = np.zeros((n, 2))
        last[i] = -w                                             # what S[i] -= w keeps
        mistakes = {
            ("sign: separation pushes boid i away from j", "sign: separation pushes boid i "
             "away from j, along -d_ij (d_ij = x_j - x_i)"): -expected,
            ("the push must grow as two boids close in: what is its size at distance |d|?",
             "divide by |d|², not |d|: d/|d|² is a push of size 1/|d|"):
                -_scatter(i, d / np.sqrt(r2)[:, None], n),
            ("d/|d|³ is a push of size 1/|d|²; the rule's push has size 1/|d|",
             "the rule is d/|d|², a push of size 1/|d|"): -_scatter(i, d / (r2 ** 1.5)[:, None], n),
            ("sum over the neighbours, do not average: more crowding must push harder",
             "sum over the neighbours, do not average: more crowding must push harder"):
                expected / count,
            ("with repeated indices in i, S[i] -= w applies each index only once (NumPy "
             "buffers fancy-index updates)", "use np.add.at(S, i, -w) or np.bincount(i, weights) "
             "per column: both add every pair"): last,
            ("accumulate at i, the boid that sees its neighbour j, not at j",
             "accumulate at i, the boid that sees its neighbour j, not at j"): -_scatter(j, w, n),
        }
        args = (i.copy(), j.copy(), d.copy(), n)
        got = func(*args)
        if not (np.array_equal(args[0], i) and np.array_equal(args[2], d)):
            ck.expect(False, what, "your function changed its input arrays",
                      hint="build a new array for S instead of updating i, j or d in place")
            continue
        got = np.asarray(got, dtype=float)
        if got.ndim == 2 and got.shape[1:] == (2,) and got.shape[0] == i.max() + 1 < n:
            ck.expect(False, what, f"expected one row per boid, shape ({n}, 2), got {got.shape}",
                      hint=("the last boids may appear in no pair: size S by n, not by i",
                            "np.zeros((n, 2)): a boid without neighbours still has a row (of zeros)"))
            continue
        if got.shape == d.shape and d.shape != (n, 2):
            ck.expect(False, what, f"expected one row per boid, shape ({n}, 2), got {got.shape}",
                      hint="scatter the pair terms onto the boids: one row per boid, not per pair")
            continue
        _close_rows(ck, got, expected, what, mistakes)
        if isolated and got.shape == (n, 2):
            ck.expect(np.array_equal(got[-1], [0.0, 0.0]), "a boid without neighbours feels no push",
                      f"got {got[-1]}", hint="rows of boids that appear in no pair must stay zero")


WEIGHTS = ("separation", "alignment", "cohesion")
REASONS = {
    "A": "without it the headings never agree, so the boids keep crossing each other's paths "
         "and collide",
    "B": "alignment gives neighbours the same velocity, and boids with the same velocity end "
         "up at the same place",
    "C": "it is the only rule that pushes neighbours apart, and its push grows without bound as "
         "they close in; cohesion keeps pulling each boid to its neighbours' centre, so without "
         "it nothing stops a group contracting",
    "D": "it pushes harder than cohesion pulls at every distance, so without it cohesion wins",
}
#: The right reason; the others are misconceptions that the notebook's runs refute.
RIGHT_REASON = "c"


@exercise(allow=())
def flock_breaker(ck: Checker, func) -> None:
    """``func() -> (weight, reason)``: the weight whose absence piles boids up, and why."""
    answer = func()
    if not (isinstance(answer, tuple | list) and len(answer) == 2):
        ck.expect(False, "answer format", f"expected (weight, letter), got {answer!r}",
                  hint='return a pair such as ("cohesion", "B")')
        return
    weight, reason = (str(a).strip().lower() for a in answer)
    hints = {
        "alignment": "without alignment the headings never agree, but nothing pulls harder: "
                     "which rule, missing, leaves the pull of the others unopposed?",
        "cohesion": "without cohesion nothing pulls the boids together: how could they pile up?",
    }
    if not ck.expect(weight in WEIGHTS, "the weight is one of the three",
                     f"got {weight!r}", hint=f"answer one of {', '.join(WEIGHTS)}"):
        return
    ck.expect(weight == "separation", "the weight whose absence piles the boids up",
              f"you chose {weight}", hint=hints.get(weight))
    why = {
        "a": "disorder does not pile boids up: with random headings (alignment 0) they keep "
             "their distance, and without separation the flock still orders",
        "b": "two boids with the same velocity keep the offset between them: parallel flight "
             "never closes a gap",
        "d": "if separation won at every distance, no group would ever form: the push, of size "
             "w_s/|d| per neighbour, and the pull, which grows with |d|, balance at a spacing",
    }
    ck.expect(reason == RIGHT_REASON, "the reason", f"you chose {reason.upper()!r}",
              hint=why.get(reason, "answer one of the letters A, B, C, D"))


# --- a neighbour search with a uniform grid ---------------------------------------------

#: Memory (bytes) an answer may hold at once for the 2000-point case: a grid needs well
#: under a megabyte; one N × N table of float64 needs 32 MB.
MEMORY_LIMIT = 12_000_000
#: For four times the points at the same density a grid allocates about four times the
#: memory in total (a neighbourhood of the same size per point); all pairs, even a row at
#: a time, sixteen times. Between the two:
GROWTH_LIMIT = 8.0


def _pair_set(i, j):
    return set(zip(np.asarray(i).tolist(), np.asarray(j).tolist(), strict=True))


def _imports_inside(func, prefix: str) -> list[str]:
    """Dotted paths under ``prefix`` that ``func`` imports inside its body. The shared rule
    (``forbid=``) reads names bound outside the function and watches calls of Python code;
    a C class imported inside the body (``from scipy.spatial import cKDTree``) reaches
    neither, so this check reads those imports from the bytecode too."""
    code = getattr(inspect.unwrap(func), "__code__", None)
    if code is None:
        return []
    return sorted({head for kind, head, _ in name_chains(code)
                   if kind == "path" and (head == prefix or head.startswith(prefix + "."))})


def _missing_hint(later) -> tuple[str, ...]:
    """The hint for missing pairs, from the evidence of every case: only when every missing
    pair lies at exactly the radius is the comparison to blame; else the stencil is."""
    if all(at_radius for _, _, at_radius in later):
        return ("a pair exactly `radius` apart counts: |d| <= radius", "compare |d|² <= radius², not <")
    return ("pairs in neighbouring cells are missing",
            "with cells of side radius, a point's neighbours can lie in any of the 3 × 3 cells "
            "around its own (all nine, not half of them); cells smaller than the radius need more")


@exercise(allow=(), forbid=("scipy.spatial",))
def neighbour_pairs(ck: Checker, func) -> None:
    """``func(x, radius) -> (i, j)``: every pair ``i < j`` with ``|x_i − x_j| <= radius``,
    each once, ``x`` of shape ``(N, 2)`` in open space."""
    if found := _imports_inside(func, "scipy.spatial"):
        ck.expect(False, f"uses the reference: your function imports {', '.join(found)}",
                  "this exercise asks for a grid of your own; scipy.spatial's trees are refused",
                  hint=("bin the points into cells of side radius with np.floor(x / radius)",))
        return
    later, allocated = [], {}              # missing pairs are judged once every case is in
    for what, x, radius in _cases.grid_cases(_SEED + 3):
        if len(x) > 2000 and not allocated:
            break                          # the cost is measured only on a search that works
        ref = neighbors.pairs(x, radius) if len(x) > 2000 else neighbors.all_pairs(x, radius)
        expected = _pair_set(ref.i, ref.j)
        try:
            got, peak, total = _cases.measured(func, x.copy(), radius)
        except _cases.TooLong:
            limit = _cases.line_limit(len(x))
            ck.expect(False, what, f"your function ran more than {limit:,} lines of Python on "
                      f"{len(x)} points", hint=("testing every pair in Python takes N²/2 steps: bin "
                                                "the points into cells instead",))
            continue
        try:
            i, j = (np.asarray(a).astype(int).ravel() for a in got)
        except (TypeError, ValueError):
            ck.expect(False, what, f"expected a pair of index arrays (i, j), got {type(got).__name__}",
                      hint=("return two arrays of the same length: i[p] and j[p] are pair p",))
            continue
        if i.shape != j.shape:
            ck.expect(False, what, f"i and j differ in length ({i.size} and {j.size})")
            continue
        pairs = list(zip(i.tolist(), j.tolist(), strict=True))
        found = set(pairs)
        wrong = []
        if any(a == b for a, b in pairs):
            wrong.append(("a point is paired with itself",
                          "a point is not its own neighbour: keep pairs with i != j"))
        elif any(a > b for a, b in pairs) and {(min(a, b), max(a, b)) for a, b in pairs} == expected:
            wrong.append(("each pair once, with i < j", "keep the pairs with i < j: (i, j) and "
                          "(j, i) are the same pair"))
        elif len(pairs) != len(found):
            wrong.append(("some pairs appear twice: each pair once",
                          "a pair met from both of its cells is listed twice: keep i < j, or "
                          "visit only half of the neighbouring cells"))
        missing, extra = expected - found, found - expected
        if not wrong and extra:
            wrong.append(("some pairs you return are farther apart than the radius",
                          "a shared or neighbouring cell is not enough: test |d|² <= radius² "
                          "for every candidate pair"))
        detail = (f"{len(found & expected)} of {len(expected)} pairs found, {len(extra)} not pairs, "
                  f"{len(pairs) - len(found)} repeated")
        if wrong:
            ck.expect(False, what, detail, hint=wrong[0])
        elif missing:
            at_radius = all(np.isclose(ref.distance[np.flatnonzero((ref.i == a) & (ref.j == b))[0]],
                                       radius, rtol=1e-12) for a, b in missing)
            later.append((what, detail, at_radius))
        elif len(x) == 2000 and peak > MEMORY_LIMIT:
            ck.expect(False, f"{what}: memory held at once",
                      f"your function held {peak / 1e6:.0f} MB at once for {len(x)} points",
                      hint=("that is an N × N table: bin the points into cells instead",
                            "an N × N table of distances grows as N²: bin the points into "
                            "cells of side radius and compare each point only with the "
                            "points of its own and the neighbouring cells"))
        elif len(x) > 2000:
            growth = total / max(allocated[2000], 1)
            ck.expect(growth <= GROWTH_LIMIT, f"{what}: the cost grows as N, not N²",
                      f"your function allocated {allocated[2000] / 1e6:.1f} MB in all for 2000 points "
                      f"and {total / 1e6:.1f} MB for {len(x)} at the same density: {growth:.0f} times "
                      "as much for 4 times the points (a grid: about 4; all pairs, even a row at a "
                      "time: 16)",
                      hint=("that is all pairs, a row at a time: bin the points into cells",
                            "with cells of side radius a point has about 9ρR² candidates whatever N "
                            "(ρ the density): compare each point only with the points of its own and "
                            "the 8 neighbouring cells"))
        else:
            ck.expect(True, what)
            if len(x) == 2000:
                allocated[2000] = total
    for what, detail, _ in later:
        ck.expect(False, what, detail, hint=_missing_hint(later))
