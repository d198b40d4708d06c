"""Checks for notebook 10, flocking: the separation rule, and which weight breaks the flock."""

from __future__ import annotations

import numpy as np

from .. import boids
from . import Checker, exercise

_SEED = 1010


def _case(n, box, rng, isolated=False):
    rules = boids.Rules(box=box)
    x, v = boids.random_flock(n, box, 1.5, rng)
    if isolated:                     # one boid far from everybody: no neighbour, no push
        x[0] = x[1:].mean(axis=0) + box / 2
        x[1:] = np.mod(x[0] + box / 2 + rng.uniform(-2.0, 2.0, (n - 1, 2)), box)
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


@exercise
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
            "sign: separation pushes boid i away from j, along -d_ij (d_ij = x_j - x_i)":
                -expected,
            "divide by |d|², not |d|: the push must grow as two boids close in":
                -_scatter(i, d / np.sqrt(r2)[:, None], n),
            "d/|d|³ is a 1/r² push; the rule is d/|d|², a push of size 1/|d|":
                -_scatter(i, d / (r2 ** 1.5)[:, None], n),
            "sum over the neighbours, do not average: more crowding must push harder":
                expected / count,
            "S[i] -= w with repeated indices in i applies each index only once (NumPy "
            "buffers fancy-index updates): use np.add.at(S, i, -w) or np.bincount": last,
            "accumulate at i, the boid that sees its neighbour j, not at j":
                -_scatter(j, w, n),
        }
        args = (i.copy(), j.copy(), d.copy(), n)
        got = func(*args)
        if not (np.array_equal(args[0], i) and np.array_equal(args[2], d)):
            ck.expect(False, what, "your function changed its input arrays",
                      hint="build a new array for S instead of updating i, j or d in place")
            continue
        got = np.asarray(got, dtype=float)
        if got.shape == d.shape and d.shape != (n, 2):
            ck.expect(False, what, f"expected one row per boid, shape ({n}, 2), got {got.shape}",
                      hint="scatter the pair terms onto the boids: one row per boid, not per pair")
            continue
        _close_rows(ck, got, expected, what, mistakes)
        if isolated and got.shape == (n, 2):
            ck.expect(np.array_equal(got[0], [0.0, 0.0]), "a boid without neighbours feels no push",
                      f"got {got[0]}", hint="rows of boids that appear in no pair must stay zero")


WEIGHTS = ("separation", "alignment", "cohesion")
REASONS = {
    "A": "only separation pushes boids apart, harder the closer they are; cohesion pulls "
         "each boid to its neighbours' centre, and without a push back nothing keeps a spacing",
    "B": "without it boids fly in random directions and collide by chance",
    "C": "the speed limits stop the boids when the rule is missing, so they pile up",
    "D": "without it boids move in parallel, and parallel boids always converge",
}


@exercise
def flock_breaker(ck: Checker, func) -> None:
    """``func() -> (weight, reason)``: the weight whose absence piles boids up, and why."""
    answer = func()
    if not (isinstance(answer, tuple | list) and len(answer) == 2):
        ck.expect(False, "answer format", f"expected (weight, letter), got {answer!r}",
                  hint='return a pair such as ("cohesion", "B")')
        return
    weight, reason = (str(a).strip().lower() for a in answer)
    hints = {
        "alignment": "without alignment the headings stay random (polarization near 0.1), but "
                     "the boids keep their distance: nothing piles up",
        "cohesion": "without cohesion nothing pulls the boids together: their spacing grows "
                    "(1.2 m in the key states), the opposite of piling up",
    }
    if not ck.expect(weight in WEIGHTS, "the weight is one of the three",
                     f"got {weight!r}", hint=f"answer one of {', '.join(WEIGHTS)}"):
        return
    ck.expect(weight == "separation", "the weight whose absence piles the boids up",
              f"you chose {weight}", hint=hints.get(weight))
    why = {
        "b": "boids piling up on a few points is not chance: the same boids stay together "
             "in groups that fly aligned, which chance collisions would not do",
        "c": "the speed limits only clamp |v| to [1, 2] m/s: they never stop a boid",
        "d": "parallel boids keep their distance for ever; something must pull them together",
    }
    ck.expect(reason == "a", "the reason", f"you chose {reason.upper()!r}",
              hint=why.get(reason, "answer one of the letters A, B, C, D"))
