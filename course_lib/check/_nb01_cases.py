"""Case data of notebook 01's checks (:mod:`course_lib.check.nb01`): fields, frames, flocks.

:func:`particle_cases` holds the frames the check runs (one made by hand, one whose expired
particles are not the first rows, so that deleting from the front of a queue fails), and
:func:`frame_mistakes` what the usual mistakes make of one frame, each keyed by its hint.
:func:`cohesion_cases` holds the flocks of the cohesion check (one with a pair exactly
``radius`` apart, so that ``<=`` fails), :func:`cohesion_reference` the rule,
:func:`cohesion_mistakes` what the usual mistakes make of it, and :func:`cohesion_within`
the rule for a given neighbour mask (to recognise a mask built with ``<=``).
:func:`field_points` holds the positions the field checks try.
Imports NumPy and :func:`course_lib.check._answers.as_array`.
"""

from __future__ import annotations

import numpy as np

from ._answers import as_array
from .tolerance import escalate

_RNG_SEED = 2026


def field_points() -> list[tuple[str, np.ndarray]]:
    """Positions to test a field on: single points (2,), a cloud (N, 2), a grid (n, n, 2)."""
    rng = np.random.default_rng(_RNG_SEED)
    g = np.stack(np.meshgrid(np.linspace(-2.0, 2.0, 2), np.linspace(-2.0, 2.0, 2)), axis=-1)
    return [
        ("X = (1, 0)", np.array([1.0, 0.0])),
        ("X = (0, 1)", np.array([0.0, 1.0])),
        ("X = (3, -2)", np.array([3.0, -2.0])),
        ("3 particles, X of shape (3, 2)", rng.uniform(-2.0, 2.0, size=(3, 2))),
        ("a 2 x 2 grid, X of shape (2, 2, 2)", g),
    ]


def particle_cases() -> list:
    """Two frames: a hand-made one (one particle reaches its lifetime exactly), and one whose
    expired particles are not the first rows (a queue that deletes from the front fails it),
    with no newborns."""
    particles = {
        "X": np.array([[0.0, 0.0], [1.0, 1.0], [2.0, -1.0], [-1.0, 0.5]]),
        "age": np.array([0.0, 0.5, 1.5, 3.0]),
        "lifetime": np.array([2.0, 1.0, 1.75, 4.0]),
        "colour": np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5, 0.5]]),
    }
    V = np.array([[1.0, 0.0], [0.0, 2.0], [-1.0, -1.0], [0.5, 0.5]])
    newborn = {
        "X": np.array([[5.0, 5.0], [6.0, 6.0]]),
        "age": np.zeros(2),
        "lifetime": np.array([3.0, 2.5]),
        "colour": np.array([[0.2, 0.4, 0.6], [0.8, 0.6, 0.4]]),
    }
    rng = np.random.default_rng(_RNG_SEED)
    crowd = {
        "X": rng.uniform(-3.0, 3.0, size=(7, 2)),
        "age": np.array([2.9, 0.1, 1.0, 0.4, 4.0, 0.0, 2.3]),
        "lifetime": np.array([5.0, 0.3, 3.0, 0.6, 9.0, 1.0, 2.5]),
        "colour": rng.uniform(0.0, 1.0, size=(7, 3)),
    }
    none = {"X": np.zeros((0, 2)), "age": np.zeros(0), "lifetime": np.zeros(0),
            "colour": np.zeros((0, 3))}
    return [("frame 1 (4 particles, 2 newborns, dt = 0.5 s)", particles, V, 0.5, newborn),
            ("frame 2 (7 particles, the 2nd, 4th and 7th expire, none born, dt = 0.25 s)",
             crowd, rng.uniform(-1.0, 1.0, size=(7, 2)), 0.25, none)]


def frame_mistakes(particles, V, dt, newborn) -> dict:
    """What the usual mistakes make of the positions and ages in one frame."""
    n = len(particles["age"])

    def variant(age_new, alive, move=True):
        X = particles["X"] + (dt * V if move else 0.0)
        return {"X": np.concatenate([X[alive], newborn["X"]]),
                "age": np.concatenate([age_new[alive], newborn["age"]])}

    aged = particles["age"] + dt
    life = particles["lifetime"]
    front = np.arange(n) >= int(np.sum(aged >= life))  # delete as many rows, from the front
    return {
        escalate("a particle dies when its age reaches its lifetime: keep age < lifetime, "
                 "so one whose age equals its lifetime is deleted",
                 "in frame 1 the second particle is 0.5 s old with a lifetime of 1 s: after "
                 "dt = 0.5 s its age is 1.0 s, equal to its lifetime, so it is deleted; your "
                 "<= kept it. Write alive = age < lifetime"): variant(aged, aged <= life),
        escalate("no particle was deleted: after ageing, delete every particle whose new age "
                 "has reached its lifetime (age >= lifetime)",
                 "in frame 1 the third particle is 1.5 + 0.5 = 2.0 s old with a lifetime of "
                 "1.75 s and must go: alive = age < lifetime, then particles[key][alive] for "
                 "every key"): variant(aged, np.ones(n, dtype=bool)),
        escalate("age every particle by dt this frame (age + dt), then compare with the "
                 "lifetime",
                 "in frame 1 the second particle is 0.5 s old with a lifetime of 1 s: after "
                 "the frame it is 1.0 s old and dies, but its old age 0.5 s keeps it alive. "
                 "Compute age = particles['age'] + dt first, then the mask from it"):
            variant(particles["age"], particles["age"] < life),
        escalate("move every surviving particle by dt * V",
                 "in frame 1 the first particle starts at (0, 0) with V = (1, 0): after "
                 "dt = 0.5 s it is at (0.5, 0). Write X = particles['X'] + dt * V before "
                 "filtering"): variant(aged, aged < life, move=False),
        escalate("the expired particles are not always the first rows (lifetimes differ): "
                 "select the survivors with a boolean mask, age < lifetime, row by row",
                 "in frame 2 the 2nd, 4th and 7th particles expire, not the first three: "
                 "X[alive] with alive = age < lifetime keeps rows 1, 3, 5 and 6 (counting "
                 "from 1), where X[3:] keeps rows 4 to 7"): variant(aged, front),
    }


#: Lines of Python an answer may run per flock: broadcasting needs a handful, a loop over
#: 200 boids at least 200.
COHESION_LINE_BUDGET = 100


def cohesion_cases() -> list:
    """The flocks of the cohesion check: by hand (one with a pair exactly ``radius`` apart),
    two boids out of sight of each other, and two random flocks."""
    rng = np.random.default_rng(_RNG_SEED)
    by_hand = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [5.0, 5.0], [5.5, 5.0]])
    at_radius = np.array([[0.0, 0.0], [1.5, 0.0], [0.0, 1.0], [3.0, 3.0]])
    return [
        ("5 boids by hand, radius 1.2 m", by_hand, 1.2),
        ("4 boids by hand, radius 1.5 m: the first two exactly 1.5 m apart (not neighbours)",
         at_radius, 1.5),
        ("2 boids 3 m apart, radius 1 m (no neighbours)", np.array([[0.0, 0.0], [3.0, 0.0]]), 1.0),
        ("200 boids in a 10 m square, radius 1.5 m", rng.uniform(0.0, 10.0, size=(200, 2)), 1.5),
        ("60 boids in a 3 m square, radius 0.8 m", rng.uniform(0.0, 3.0, size=(60, 2)), 0.8),
    ]


def cohesion_within(X, D, within) -> np.ndarray:
    """The rule with neighbours ``within`` (a boolean (N, N) mask; the boid itself left out)."""
    others = within & ~np.eye(len(X), dtype=bool)
    return np.einsum("ij,ijk->ik", others, D) / np.maximum(others.sum(axis=1, keepdims=True), 1)


def cohesion_reference(X, radius: float) -> np.ndarray:
    """For each boid, the mean position of the *other* boids closer than ``radius`` minus
    its own position (m), shape ``(N, 2)``; zero for a boid with no neighbour."""
    X = np.asarray(X, dtype=float)
    D = X[None, :, :] - X[:, None, :]                  # D[i, j] = X_j - X_i
    near = np.einsum("ijk,ijk->ij", D, D) < radius**2
    np.fill_diagonal(near, False)
    count = near.sum(axis=1, keepdims=True)
    return np.einsum("ij,ijk->ik", near, D) / np.maximum(count, 1)


#: Where the fuller cohesion hints work a number: a boid of the first flock by hand.
_AT_55 = "in the first flock (radius 1.2 m) the boid at (5, 5):"


def cohesion_mistakes(X, radius: float, expected) -> dict:
    """What the usual mistakes make of the cohesion rule on the flock ``X``, keyed by hint."""
    D = X[None, :, :] - X[:, None, :]
    dist2 = np.einsum("ijk,ijk->ij", D, D)
    within = dist2 < radius**2                          # includes the boid itself
    others = within & ~np.eye(len(X), dtype=bool)
    count = others.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return {
            escalate("a boid is not its own neighbour: leave it out of the mean (it pulls the "
                     "mean towards itself)",
                     f"{_AT_55} its only neighbour is (5.5, 5), so its pull is (0.5, 0); counting "
                     "itself averages in its own zero offset and gives (0.25, 0). Take the "
                     "diagonal out of the mask: np.fill_diagonal(near, False)"):
                np.einsum("ij,ijk->ik", within, D) / within.sum(1, keepdims=True),
            escalate("return the vector FROM the boid TO the local centre (centre - X_i), not "
                     "the centre itself",
                     f"{_AT_55} the local centre is (5.5, 5) and the pull (5.5, 5) - (5, 5) = "
                     "(0.5, 0); you returned (5.5, 5): subtract the boid's own position"):
                np.where(count > 0, expected + X, 0.0),
            escalate("your pull points away from the neighbours: return centre - X_i, not "
                     "X_i - centre",
                     f"{_AT_55} the pull is (0.5, 0), towards (5.5, 5); yours is (-0.5, 0). The "
                     "offsets are D[i, j] = X_j - X_i, i.e. X[None, :, :] - X[:, None, :]"):
                -expected,
            escalate("a boid exactly `radius` away is not a neighbour: the rule is "
                     "|X_j - X_i| < radius, strictly",
                     "in the flock with radius 1.5 m, (1.5, 0) is exactly 1.5 m from the boid "
                     "at (0, 0), so that boid's only neighbour is (0, 1) and its pull (0, 1); "
                     "with <= it gets (0.75, 0.5). Write dist2 < radius**2"):
                cohesion_within(X, D, dist2 <= radius**2),
            DIVIDE_BY_N_HINT:
                np.einsum("ij,ijk->ik", others, D) / len(X),
            escalate("the centre is the mean of the NEIGHBOURS within the radius, not of the "
                     "whole flock",
                     f"{_AT_55} only (5.5, 5) is within 1.2 m, so its pull is (0.5, 0); the "
                     "mean of all five boids, (2.3, 2.2), gives (-2.7, -2.8). Average the "
                     "offsets with the neighbour mask"): X.mean(axis=0) - X,
        }


#: Exercise 1 (and 2): an answer right on a cloud (N, 2) but wrong on a grid (n, n, 2).
GRID_HINT = escalate(
    "right for a cloud of shape (N, 2), wrong on a grid of shape (n, n, 2): there X[:, 1] is a "
    "row of points, not the y components (and axis=1 is not the last axis). Index the last "
    "axis, X[..., 0] and X[..., 1], which works for every shape",
    "on the 2 x 2 grid X[:, 1] is the second point of each grid row, (x, y) pairs, while "
    "X[..., 1] holds the four y's: write x, y = X[..., 0], X[..., 1] and join the result with "
    "np.stack((vx, vy), axis=-1)")


#: Exercise 4: an answer whose survivors are right but whose newborns are not as born.
NEWBORN_HINT = escalate(
    "the newborns were moved or aged: they appear exactly as born, appended after the "
    "survivors have been moved, aged and filtered",
    "in frame 1 the newborns are born at (5, 5) and (6, 6) with age 0, and the last two rows of "
    "X and age must be exactly those: np.concatenate([X[alive], newborn['X']]) after moving, "
    "not before")

#: Exercise 4: survivors wrong in no way the check knows: the order of the three stages.
FRAME_ORDER_HINT = escalate(
    "update, then delete, then create: survivors first, newborns appended at the end",
    "move and age every particle (X + dt * V, age + dt), then keep alive = age < lifetime, "
    "then append the newborns with np.concatenate([...[alive], newborn[key]])")


def newborns_changed(got, expected, born) -> bool:
    """Whether an answer has the survivors right but not the newborns as born (moved or aged
    in any way): its rows before the last ``len(born)`` are right, those rows are not."""
    a, n = as_array(got), len(born)
    if a is None or a.shape != np.shape(expected) or n == 0:
        return False
    m = len(a) - n
    return bool(np.allclose(a[:m], expected[:m]) and not np.allclose(a[m:], born))


#: Exercise 2: the pull -k (x, y) added with the wrong sign; the second time, one point by hand.
OUTWARD_HINT = escalate(
    "the pull points outwards: subtract k (x, y) so that particles move towards the origin",
    "check one point by hand: at (1, 0) with k = 0.5 the vortex gives (0, 1) and the pull must "
    "point to -x, so V = (-0.5, 1); yours gives (0.5, 1)")

#: Exercise 6: the neighbours' offsets summed and divided by the flock size N.
DIVIDE_BY_N_HINT = escalate(
    "average over the neighbours only: divide by their number, not by N",
    "a boid with 2 neighbours averages 2 offsets: divide each boid's sum by its own count, "
    "near.sum(axis=1, keepdims=True) of your neighbour mask, not by len(X)")
