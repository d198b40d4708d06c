"""Checks for notebook 10, flocking: the separation rule, where separation and cohesion
balance on a ring of boids, and a neighbour search with a uniform grid.

No answer may call the library (``allow=()``); the neighbour search may not call
``scipy.spatial`` either (the exercise is the grid, not the k-d tree). The separation rule
is judged per boid against a round-off bound derived from the answer's own precision (a
sum of m terms, each rounded by a few units of round-off), so the verdict, the count of
boids wrong and the message use one tolerance. The ring's radius is tried for several boid
counts and weights (an answer that ignores its arguments fails). The grid search is
compared with the all-pairs reference :func:`course_lib.neighbors.all_pairs` on data that
breaks the usual shortcuts (pairs in diagonal cells, at exactly the radius, coincident
points, points far apart in one wide cell); the memory it holds at once tells a grid from
an N × N table; the memory it allocates in all (bytes, the same on every machine) is about
the same for 2000 points in a square and in a long narrow band at the same density for a
grid, but several times more in the band for a sweep along one axis, looped or vectorized;
and on four times the points it grows about fourfold for a grid and sixteenfold for all
pairs tested a row at a time (that 8000-point case is skipped once a band has stopped a
sweep: the verdict is decided, and a looped sweep would take seconds more). The separation
rule may run at most :data:`SEPARATION_LINES` lines of Python (no loop over the pairs). Case
data and the measurement: :mod:`course_lib.check._nb10_cases`.
"""

from __future__ import annotations

import inspect

import numpy as np

from .. import boids, neighbors
from ..lessons import nb10_flocking as _lesson
from . import Checker, apart, exercise
from . import _nb10_cases as _cases
from ._answers import as_scalar, call_analysis, one_number, rtol_for
from ._nb10_cases import GROWTH_LIMIT, SHAPE_LIMIT, roundoff_bound
from .policy import name_chains
from .tolerance import escalate

_SEED = 1010
#: Lines of Python the separation rule may run per case: a vectorized answer runs about five
#: (a loop over the two columns, ten); a loop over the 295 pairs of the first case, or over
#: its 30 boids, runs more than 60.
SEPARATION_LINES = 40


def _case(n, box, rng, isolated=False):
    rules = boids.Rules(box=box)
    x, v = boids.random_flock(n, box, 1.5, rng)
    if isolated:                     # the last boid far from everybody: no neighbour, no push
        x[-1] = x[:-1].mean(axis=0) + box / 2    # (last: an answer sized i.max() + 1 is short)
        x[:-1] = np.mod(x[-1] + box / 2 + rng.uniform(-2.0, 2.0, (n - 1, 2)), box)
    i, j, d = boids.tree_pairs(x, v, rules, sort=False)
    return x, v, rules, i, j, d


def _close_rows(ck: Checker, got, expected, bound, what, mistakes) -> None:
    """Judge an (n, 2) answer boid by boid against ``bound`` (the round-off it may carry):
    the verdict, the count of boids wrong and the worst boid shown all use that bound."""
    if got.shape != expected.shape:
        ck.expect(False, what, f"expected shape {expected.shape}, got {got.shape}")
        return
    off = np.abs(got - expected)
    beyond = ~np.all(off <= bound, axis=1)
    if not beyond.any():
        ck.expect(True, what)
        return
    hint = next((h for h, wrong in mistakes.items()
                 if np.allclose(got, wrong, rtol=1e-9, atol=1e-12)), None)
    excess = np.where(bound > 0, off / np.maximum(bound, 1e-300), np.where(off > 0, np.inf, 0.0)).max(axis=1)
    k = int(np.argmax(excess))
    scale = np.abs(expected).max()
    relative = off.max() / scale
    if hint is None and relative < 1e-6:        # right to many digits, not to round-off
        hint = escalate(f"your pushes agree with the rule to {relative:.0e} of the largest, but round-off "
                        f"leaves them within {bound.max() / scale:.0e}: is something added to |d|², such as "
                        "a guard ε against a division by zero?",
                        "a boid at the same point as another is not its neighbour (Section 1), so no pair "
                        "has d = 0 and the rule needs no guard; a guard such as |d|² + 1e-12 changes "
                        "every push (np.maximum(|d|², 1e-300) would leave real pairs untouched)")
    ck.expect(False, what, f"boid {k}: expected {expected[k].round(6)}, got {got[k].round(6)}, off by "
              f"{off[k].max():.1e} where round-off allows {bound[k].max():.0e} "
              f"({int(beyond.sum())} of {len(got)} boids beyond round-off)", hint=hint)


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
            escalate("the push must grow as two boids close in: what is its size at distance |d|?",
                     "divide by |d|², not |d|: d/|d|² is a push of size 1/|d|"):
                -_cases.scatter(i, d / np.sqrt(r2)[:, None], n),
            escalate("d/|d|³ is a push of size 1/|d|²; the rule's push has size 1/|d|",
                     "the rule is d/|d|², a push of size 1/|d|"):
                -_cases.scatter(i, d / (r2 ** 1.5)[:, None], n),
            ("sum over the neighbours, do not average: more crowding must push harder",
             "sum over the neighbours, do not average: more crowding must push harder"):
                expected / count,
            escalate("with repeated indices in i, S[i] -= w applies each index only once (NumPy "
                     "buffers fancy-index updates)", "use np.add.at(S, i, -w) or np.bincount(i, weights) "
                     "per column: both add every pair"): last,
            ("accumulate at i, the boid that sees its neighbour j, not at j",
             "accumulate at i, the boid that sees its neighbour j, not at j"): -_cases.scatter(j, w, n),
        }
        args = (i.copy(), j.copy(), d.copy(), n)
        ok, got = call_analysis(ck, what, SEPARATION_LINES, escalate(
            "vectorize: many pairs share the same i, so add their terms all at once with "
            "np.add.at or np.bincount instead of a Python loop",
            "np.add.at(S, i, -w) adds every row of w to the row of its boid, repeated i "
            "included; np.bincount(i, weights, minlength=n) does the same for one column"),
            func, *args, why="it loops over the pairs (or the boids) in Python")
        if not ok:
            continue
        if not (np.array_equal(args[0], i) and np.array_equal(args[2], d)):
            ck.expect(False, what, "your function changed its input arrays",
                      hint="build a new array for S instead of updating i, j or d in place")
            continue
        raw = np.asarray(got)                     # round-off at the answer's own precision
        eps = max(float(np.finfo(raw.dtype).eps) if np.issubdtype(raw.dtype, np.floating) else 0.0,
                  float(np.finfo(float).eps))
        got = np.asarray(got, dtype=float)
        if got.ndim == 2 and got.shape[1:] == (2,) and got.shape[0] == i.max() + 1 < n:
            ck.expect(False, what, f"expected one row per boid, shape ({n}, 2), got {got.shape}",
                      hint=escalate("the last boids may appear in no pair: size S by n, not by i",
                                    "np.zeros((n, 2)): a boid without neighbours still has a row (of zeros)"))
            continue
        if got.shape == d.shape and d.shape != (n, 2):
            ck.expect(False, what, f"expected one row per boid, shape ({n}, 2), got {got.shape}",
                      hint="scatter the pair terms onto the boids: one row per boid, not per pair")
            continue
        _close_rows(ck, got, expected, roundoff_bound(i, d, n, eps), what, mistakes)
        if isolated and got.shape == (n, 2):
            ck.expect(np.array_equal(got[-1], [0.0, 0.0]), "a boid without neighbours feels no push",
                      f"got {got[-1]}", hint="rows of boids that appear in no pair must stay zero")


# --- where separation and cohesion balance ------------------------------------------------

#: (boids on the ring, w_s in m²/s², w_c in 1/s²): the notebook's weights and others, so that
#: an answer that ignores its arguments fails.
RING_CASES = ((2, 0.3, 1.0), (3, 0.3, 1.0), (6, 0.3, 1.0), (5, 2.0, 0.5), (12, 0.05, 3.0))


@exercise(allow=())
def ring_radius(ck: Checker, func) -> None:
    """``func(n, w_s, w_c) -> r``: the radius (m) of the ring of ``n`` boids, flying side by
    side and all in view of each other, on which separation and cohesion cancel."""
    answers = [(n, ws, wc, _lesson.ring_radius(n, ws, wc), func(n, ws, wc)) for n, ws, wc in RING_CASES]
    right = [as_scalar(got) is not None and np.isclose(as_scalar(got), r, rtol=rtol_for(got, 1e-9), atol=0.0)
             for n, ws, wc, r, got in answers]      # the closed form is exact to round-off
    hints = _cases.ring_hints([(n, ws, wc, r, None if ok else as_scalar(got))
                               for (n, ws, wc, r, got), ok in zip(answers, right, strict=True)])
    for (n, ws, wc, expected, got), ok, hint in zip(answers, right, hints, strict=True):
        what = f"{n} boids, w_s = {ws:g} m²/s², w_c = {wc:g} 1/s²"
        value = one_number(ck, what, got, "a radius in m")
        if value is None:
            continue
        if ok:
            ck.expect(True, what)
            continue
        if hint is None and np.isclose(value, expected, rtol=1e-6):
            hint = "close, but not to round-off: if you solve for r numerically, converge to 1e-10"
        ck.expect(False, what, "expected {} m, got {} m".format(*apart(float(expected), value)),
                  hint=hint or escalate("start from a pair: w_s/d = w_c d, with d = 2r; then add neighbours "
                                        "one at a time and keep only what points along the radius",
                                        "by symmetry only radial parts survive: each neighbour pushes "
                                        "outwards with the radial part of d/|d|², and cohesion pulls "
                                        "inwards towards the centre of the other n - 1 boids"))


# --- a neighbour search with a uniform grid ---------------------------------------------

#: Memory (bytes) an answer may hold at once for the 2000-point case: a grid needs well
#: under a megabyte; one N × N table of float64 needs 32 MB.
MEMORY_LIMIT = 12_000_000


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
        return escalate("a pair exactly `radius` apart counts: |d| <= radius",
                        "compare |d|² <= radius², not <")
    return escalate("pairs in neighbouring cells are missing",
                    "with cells of side radius, a point's neighbours can lie in any of the 3 × 3 "
                    "cells around its own: visit all nine, or a half stencil (own, +x, +y, +x+y, "
                    "+x−y) that covers each pair once; cells smaller than the radius need more")


@exercise(allow=(), forbid=("scipy.spatial",))
def neighbour_pairs(ck: Checker, func) -> None:
    """``func(x, radius) -> (i, j)``: every pair ``i < j`` with ``|x_i − x_j| <= radius``,
    each once, ``x`` of shape ``(N, 2)`` in open space."""
    if found := _imports_inside(func, "scipy.spatial"):
        ck.expect(False, f"uses the reference: your function imports {', '.join(found)}",
                  "this exercise asks for a grid of your own; scipy.spatial's trees are refused",
                  hint=("bin the points into cells of side radius with np.floor(x / radius)",))
        return
    # The path through the cases depends only on the pairs returned and on the stops raised
    # inside the answer (which the grader's worker records and replays), never on a byte count
    # taken after it returned: the grader replays answers and cannot measure them.
    later, base, swept, stopped = [], None, False, False   # missing pairs: judged once all are in
    for what, x, radius, role in _cases.grid_cases(_SEED + 3):
        if role in ("band", "growth") and base is None:
            break                          # the cost is measured only on a search that works
        if role == "growth" and stopped:
            break                          # a band stopped a sweep: decisive; 8000 points spared
        ref = neighbors.all_pairs(x, radius) if role in ("edge", "base") else neighbors.pairs(x, radius)
        expected = _pair_set(ref.i, ref.j)
        limit = {"base": {"held_limit": MEMORY_LIMIT}, "band": {"total_limit": SHAPE_LIMIT * (base or 0)},
                 "growth": {"total_limit": GROWTH_LIMIT * (base or 0)}}.get(role, {})
        try:
            got, peak, total = _cases.measured(func, x.copy(), radius, **limit)
        except (_cases.TooLong, _cases.TooCostly, Exception) as stop:
            if type(stop).__name__ not in _cases.STOPS:
                raise
            swept |= role == "band"
            stopped |= role == "band"
            ck.expect(*_cases.stop_verdict(what, x, role, stop, swept))
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
        unordered = [(min(a, b), max(a, b)) for a, b in pairs]
        found = set(unordered)
        selves = sum(a == b for a, b in pairs)
        reversed_ = any(a > b for a, b in pairs)
        repeated = len(unordered) - len(found)         # a pair listed again, in either order
        wrong = []
        if selves and reversed_:
            wrong.append(("each pair once, with i < j: that drops both a point paired with itself "
                          "and the copy (j, i) of every pair (i, j)",))
        elif selves:
            wrong.append(escalate("a point is paired with itself",
                                  "a point is not its own neighbour: keep pairs with i != j"))
        elif reversed_ and not repeated:
            wrong.append(escalate("each pair once, with i < j", "return each pair as (i, j) with i < j"))
        elif reversed_:
            wrong.append(escalate("each pair once, with i < j", "keep the pairs with i < j: (i, j) and "
                                  "(j, i) are the same pair"))
        elif repeated:
            wrong.append(escalate("some pairs appear twice: each pair once",
                                  "a pair met from both of its cells is listed twice: keep i < j, or "
                                  "visit only half of the neighbouring cells"))
        missing, extra = expected - found, found - expected
        if not wrong and extra:
            wrong.append(escalate("some pairs you return are farther apart than the radius",
                                  "a shared or neighbouring cell is not enough: test |d|² <= radius² "
                                  "for every candidate pair"))
        detail = (f"{len(found & expected)} of {len(expected)} pairs found, {len(extra)} not pairs"
                  f"{f' (a point with itself: {selves})' if selves else ''}, {repeated} repeated")
        if wrong:
            ck.expect(False, what, detail, hint=wrong[0])
        elif missing:
            at_radius = all(np.isclose(ref.distance[np.flatnonzero((ref.i == a) & (ref.j == b))[0]],
                                       radius, rtol=1e-12) for a, b in missing)
            later.append((what, detail, at_radius))
        elif role == "base" and peak > MEMORY_LIMIT:    # the table made in its last line
            ck.expect(False, f"{what}: memory held at once",
                      f"your function held {peak / 1e6:.0f} MB at once for {len(x)} points",
                      hint=_cases.TABLE_HINT)
            base = total
        elif role in ("band", "growth"):
            swept |= not ck.expect(*_cases.cost_verdict(what, x, role, total, base)) and role == "band"
        else:
            ck.expect(True, what)
            if role == "base":
                base = total
    for what, detail, _ in later:
        ck.expect(False, what, detail, hint=_missing_hint(later))
