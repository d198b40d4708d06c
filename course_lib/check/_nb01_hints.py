"""Hints of notebook 01's checks (:mod:`course_lib.check.nb01`), each escalating: the
mistake named on a first wrong attempt, and after another one a number worked out on one of
the check's cases or the line of code to write (:func:`course_lib.check.tolerance.escalate`).

The field exercises' (1 and 2): shapes, rows taken for columns, a single position indexed like
a cloud, assignment into X, t used in a steady field, and the usual wrong formulas; exercise
3's (advect_step) on its worked example; exercise 4's (particle_frame) and 6's (cohesion)
that the case modules do not hold. Imports only :func:`escalate`.
"""

from __future__ import annotations

from .tolerance import escalate

# --- Exercises 1 and 2, the fields ---

NO_TIME_HINT = escalate(
    "this field does not depend on t; do not use t in the formula",
    "this case is X = (0.5, -1.5) at t = 0 and at t = 2.7 s, and the two answers must be equal "
    "(the vortex gives (1.5, 0.5) at both): build V from X[..., 0] and X[..., 1] only")
SHAPE_HINT = (
    "return one velocity per position, an array of X's shape",
    "return one velocity per position, an array of X's shape: take the columns with "
    "X[..., 0] and X[..., 1] and join them with np.stack((vx, vy), axis=-1)",
)
ROWS_HINT = escalate(
    "X[0] and X[1] are the first two ROWS (particles) when X has shape (N, 2): take the "
    "columns, X[..., 0] and X[..., 1]",
    "with 3 particles X[0] is the first particle's (x, y), not the three x's: write "
    "x, y = X[..., 0], X[..., 1], which is right for (2,), (N, 2) and (n, n, 2) alike")
NEW_ARRAY_HINT = escalate(
    "compute a new array; do not assign into X",
    "X[..., 0] = ..., X *= ... or X += ... write into the caller's array (the notebook's "
    "particles change behind its back): build the result with np.stack((vx, vy), axis=-1), "
    "or start from X.copy()")
INDEX_HINT = escalate(
    "X may be one position of shape (2,), with a single axis: index the last axis, X[..., 0] "
    "and X[..., 1], which works for every shape",
    "X = np.array([3.0, -2.0]) has X.shape == (2,): X[:, 0] raises IndexError there, while "
    "X[..., 0] is 3.0 and X[..., 1] is -2.0")

# --- wrong vortices and whirlpools ---

NO_MINUS_HINT = escalate(
    "a minus sign is missing: V = (-y, x), not (y, x)",
    "at X = (0, 1) the vortex points left, (-1, 0); yours gives (1, 0): the "
    "x-component is -X[..., 1]")
NOT_SWAPPED_HINT = escalate(
    "the components are not swapped: V = (-y, x), not (-x, y)",
    "at X = (1, 0) the vortex points straight up, (0, 1); yours gives (-1, 0): "
    "the x-component comes from y (-X[..., 1]), the y-component from x "
    "(X[..., 0])")
RADIAL_HINT = escalate(
    "that is the radial field (x, y); the vortex swaps the components and "
    "negates the new x-component",
    "at X = (1, 0) yours points outwards, (1, 0); the vortex turns it up, "
    "(0, 1): V = np.stack((-X[..., 1], X[..., 0]), axis=-1)")
NO_VORTEX_HINT = escalate(
    "the vortex part (-y, x) is missing: a whirlpool turns while it pulls in",
    "at (1, 0) with k = 0.5 the whirlpool is (0, 1) - 0.5 (1, 0) = (-0.5, 1); "
    "yours gives (-0.5, 0): add the vortex (-X[..., 1], X[..., 0])")
NO_PULL_HINT = escalate(
    "the inward pull -k (x, y) is missing",
    "at (1, 0) with k = 0.5 the whirlpool is (0, 1) - 0.5 (1, 0) = (-0.5, 1); "
    "yours gives the vortex's (0, 1): subtract k * X")
X_ONLY_HINT = escalate(
    "your pull acts on x only: the pull -k (x, y) has a y-component too, -k y",
    "at (0, 1) with k = 0.5 the whirlpool is (-1, 0) - 0.5 (0, 1) = (-1, -0.5); "
    "yours gives (-1, 0): the y-component is x - k y")
Y_ONLY_HINT = escalate(
    "your pull acts on y only: the pull -k (x, y) has an x-component too, -k x",
    "at (1, 0) with k = 0.5 the whirlpool is (0, 1) - 0.5 (1, 0) = (-0.5, 1); "
    "yours gives (0, 1): the x-component is -y - k x")


def k_hint(k: float) -> tuple[str, str]:
    """Exercise 2: an answer that ignores the argument ``k`` and uses 0.5 (case ``k``)."""
    return escalate(
        f"use the argument k: this case calls whirlpool(t, X, k={k:g}), but "
        "your answer is the one for k = 0.5",
        f"at (1, 0) with k = {k:g} the whirlpool is (0, 1) - {k:g} (1, 0) = "
        f"({-k:g}, 1); yours gives (-0.5, 1): replace the number 0.5 in "
        "your formula by k")


# --- Exercise 3, advect_step ---

#: Exercise 3's mistakes; the fuller hint works the worked example X = (1, 2), V = (-1, -1),
#: dt = 0.5 s, whose answer is (0.5, 1.5).
_WORKED_3 = "on the worked example X = (1, 2), V = (-1, -1), dt = 0.5 s"
BY_ROWS_HINT = escalate(
    "X[0] and X[1] are the first two PARTICLES when X has shape (N, 2): update the whole arrays "
    "at once, without indexing",
    "with 4 particles X[0] is particle 0's (x, y) and X[1] particle 1's; X + dt * V adds "
    "row by row by itself, for one particle (2,) or N (N, 2): write return X + dt * V")
AGAINST_HINT = escalate(
    "you moved against the velocity: the new position is X + dt V, not X - dt V",
    f"{_WORKED_3} the particle moves to (1, 2) + 0.5 (-1, -1) = (0.5, 1.5); yours went to "
    "(1.5, 2.5): change the minus to a plus, X + dt * V")
NO_DT_HINT = escalate(
    "dt is missing (or taken as 1): in dt seconds a particle moves dt * V, not V",
    f"{_WORKED_3} the particle moves by 0.5 (-1, -1) = (-0.5, -0.5) to (0.5, 1.5); X + V gives "
    "(0, 1), a whole second's travel: write return X + dt * V")
DISPLACEMENT_HINT = escalate(
    "you returned the displacement dt V; return the new position X + dt V",
    f"{_WORKED_3} the displacement is (-0.5, -0.5) and the new position (1, 2) + (-0.5, -0.5) "
    "= (0.5, 1.5): add X, return X + dt * V")
HALF_DT_HINT = escalate(
    "you used dt / 2: a step of dt moves the particle by the whole dt * V",
    f"{_WORKED_3} the particle moves to (0.5, 1.5); half the step gives (0.75, 1.75): drop the "
    "0.5 (or / 2), X + dt * V")


# --- Exercises 4 and 6, particle_frame and cohesion ---

DICT_HINT = escalate(

    "return a dict with the same keys as particles",
    "particle_frame must return a dict such as {'X': ..., 'age': ..., "
    "'lifetime': ..., 'colour': ...}: one array per key of particles")
ATTRIBUTES_HINT = escalate(

    "every attribute must be filtered with the same alive mask and then "
    "extended with the newborns'",
    "for every key, including lifetime and colour: np.concatenate("
    "[particles[key][alive], newborn[key]]), with the one mask alive = "
    "new age < lifetime")
NEW_DICT_HINT = escalate(

    "build and return a new dict",
    "particles['age'] += dt (or particles['X'] = ...) changes the caller's dict: "
    "start from out = {} and store new arrays, e.g. out['age'] = "
    "particles['age'] + dt")
LOOP_HINT = escalate(

    "write it without a Python loop over the boids: the offsets of every pair by "
    "broadcasting, a boolean mask of neighbours, and masked means",
    "D = X[None, :, :] - X[:, None, :] holds every offset X_j - X_i at once, shape "
    "(N, N, 2); a boolean near of shape (N, N) marks the neighbours, and near.sum(axis=1) "
    "counts them")
NO_NEIGHBOUR_HINT = escalate(

    "a boid with no neighbour has no pull: return 0 for it (your mean divided 0 by 0)",
    "two boids 3 m apart with radius 1 m have no neighbour each: count 0, sum (0, 0), "
    "and 0/0 is NaN. Divide by np.maximum(count, 1) so that their pull is (0, 0)")
