"""Checks for notebook 01, "Particles in vector fields".

Each check compares the student's function with the reference in :mod:`course_lib`
(:mod:`course_lib.fields`, :func:`course_lib.integrate`) on a few cases, and names the
usual mistake when the answer matches it. Every reference value and every "usual mistake"
is computed from pristine copies of the inputs *before* the student's function runs, and
the student's function gets its own copies: a function that changes its input is told
so, without being compared with values its own scribbling corrupted. Answers computed in
float32 are judged at float32 precision.
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import integrate
from . import Checker, Hint, exercise
from . import _nb01_hints as hints
from ._answers import as_array, call, call_analysis, rtol_for
from ._answers import close as _close
from ._answers import mistake_hint as _mistake_hint
from ._nb01_cases import (
    COHESION_LINE_BUDGET,
    FRAME_ORDER_HINT,
    GRID_HINT,
    NEWBORN_HINT,
    OUTWARD_HINT,
    cohesion_cases,
    cohesion_mistakes,
    cohesion_reference,
    field_points,
    newborns_changed,
)
from ._nb01_cases import frame_mistakes as _frame_mistakes
from ._nb01_cases import particle_cases as _particle_cases
from .tolerance import escalate

_RNG_SEED = 2026


def _index_hint(exc: Exception) -> Hint:
    """The hint for an answer that indexes a single position ``(2,)`` like a cloud ``(N, 2)``."""
    if isinstance(exc, IndexError):
        return hints.INDEX_HINT
    return None


def _all_mistakes(reference, mistakes_of, X) -> dict:
    """The usual mistakes at positions ``X``: the exercise's own, and the shape slips."""
    expected, mistakes = reference(0.0, X.copy()), mistakes_of(X.copy())
    if X.ndim > 1:
        mistakes[hints.ROWS_HINT] = reference(0.0, X[:2].T.copy()).T
    mistakes[("the two components go on the LAST axis of the result, as in X",
              "the two components go on the LAST axis of the result, as in X: "
              "np.stack((vx, vy), axis=-1), not np.array([vx, vy])")] = np.moveaxis(expected, -1, 0)
    return mistakes


def _diagnosis(answer, reference, mistakes_of) -> Hint:
    """The mistake the answer makes at three generic positions (no coordinate zero), or None.

    At a special point two mistakes can give the same value (a pull on x alone and no pull
    at all agree at X = (0, 1)); at generic points they do not, so the mistake found there
    names a failure anywhere."""
    X = field_points()[3][1]
    try:
        got = answer(0.0, X.copy())
    except NotImplementedError:
        raise
    except Exception:  # the cases themselves report it
        return None
    return _mistake_hint(got, _all_mistakes(reference, mistakes_of, X))


def _field_cases(ck: Checker, answer, reference, mistakes_of, name: str, points=None,
                 time_check: bool = True, formula: Hint = None) -> None:
    untouched, cloud_right = True, False
    diagnosis = _diagnosis(answer, reference, mistakes_of)
    for what, X in (field_points() if points is None else points):
        expected, mistakes = reference(0.0, X.copy()), _all_mistakes(reference, mistakes_of, X)
        X_student = X.copy()
        ok, got = call(ck, f"{name} at {what}", answer, 0.0, X_student,
                       error_hint=_index_hint if X.ndim == 1 else None)
        untouched = untouched and np.array_equal(X_student, X)
        if not ok:
            continue
        shape_ok = np.shape(got) == X.shape
        hint = diagnosis or _mistake_hint(got, mistakes, formula if shape_ok else hints.SHAPE_HINT)
        if X.ndim > 2 and cloud_right:  # right on (N, 2), wrong on (n, n, 2): the axis
            hint = GRID_HINT
        right = _close(ck, got, expected, f"{name} at {what}", hint=hint)
        cloud_right = cloud_right or (X.ndim == 2 and right)
    ck.expect(untouched, f"{name} leaves X unchanged",
              "your function modified the positions it was given", hints.NEW_ARRAY_HINT)
    if time_check:
        X = np.array([0.5, -1.5])
        expected_0, expected_t = reference(0.0, X.copy()), reference(2.7, X.copy())
        ok0, at_0 = call(ck, f"{name} at t = 0", answer, 0.0, X.copy())
        ok, got = call(ck, f"{name} at t = 2.7 s (time-independent)", answer, 2.7, X.copy())
        if ok0 and ok:
            a0 = as_array(at_0)
            right_at_0 = a0 is not None and a0.shape == X.shape and np.allclose(
                a0, expected_0, rtol=rtol_for(a0, 1e-9))
            _close(ck, got, expected_t, f"{name} at t = 2.7 s (time-independent)",
                   hint=hints.NO_TIME_HINT if right_at_0 else diagnosis or formula)


@exercise(allow=())
def vortex_field(ck: Checker, vortex_field) -> None:
    """The rotational vortex V = (-y, x), compared with ``course_lib.fields.vortex``."""

    def mistakes(X):
        x, y = X[..., 0], X[..., 1]
        return {
            escalate("that is the clockwise vortex (y, -x): the x-component is -y and the "
                     "y-component is +x, so that (1, 0) moves up, towards (0, 1)",
                     "check one point by hand: at X = (1, 0) your V must be (0, 1) (up) and at "
                     "(0, 1) it must be (-1, 0) (left); yours gives (0, -1) and (1, 0)"):
                np.stack((y, -x), -1),
            hints.NO_MINUS_HINT: np.stack((y, x), -1),
            hints.NOT_SWAPPED_HINT: np.stack((-x, y), -1),
            hints.RADIAL_HINT: X,
        }

    _field_cases(ck, vortex_field, fields.vortex, mistakes, "vortex_field(t, X)",
                 formula=("check your formula on two points: the vortex moves (1, 0) straight "
                          "up, towards (0, 1), and (0, 1) to the left",
                          "V = (-y, x): the x-component is -y and the y-component is x"))


def whirlpool_reference(t: float, X, k: float = 0.5) -> np.ndarray:
    """Vortex plus an inward pull of strength ``k``: ``(-y, x) - k (x, y)``, from course_lib."""
    return fields.compose(fields.vortex, fields.scaled(fields.radial, -k))(t, X)


@exercise(allow=("course_lib.fields.vortex", "course_lib.fields.radial"))
def whirlpool(ck: Checker, whirlpool) -> None:
    """The whirlpool V = (-y, x) - k (x, y), against ``compose(vortex, scaled(radial, -k))``.

    The prompt hands over the vortex and the radial field; ``compose`` and ``scaled`` would
    build the answer, so they count as the reference."""
    for k, points in ((0.5, None), (2.0, field_points()[3:4])):

        def reference(t, X, k=k):
            return whirlpool_reference(t, X, k)

        def answer(t, X, k=k):
            return whirlpool(t, X, k=k)

        def mistakes(X, k=k):
            out = {
                OUTWARD_HINT: whirlpool_reference(0.0, X, -k),
                hints.NO_VORTEX_HINT:
                    -k * np.asarray(X, dtype=float),
                hints.NO_PULL_HINT: fields.vortex(0.0, X),
                hints.X_ONLY_HINT:
                    fields.vortex(0.0, X) - k * np.asarray(X, dtype=float) * [1.0, 0.0],
                hints.Y_ONLY_HINT:
                    fields.vortex(0.0, X) - k * np.asarray(X, dtype=float) * [0.0, 1.0],
            }
            if k != 0.5:
                out[hints.k_hint(k)] = whirlpool_reference(0.0, X, 0.5)
            return out

        _field_cases(ck, answer, reference, mistakes, f"whirlpool(t, X, k={k:g})", points,
                     time_check=points is None,
                     formula=("the whirlpool is the vortex plus a pull towards the centre of "
                              "strength k: check each part on its own (k = 0 is the vortex)",
                              "V = (-y, x) - k (x, y), that is (-y - k x, x - k y)"))


@exercise(allow=())
def advect_step(ck: Checker, advect_step) -> None:
    """One step ``X + dt V``: the worked example X = (1, 2), V = (-1, -1), dt = 0.5."""
    rng = np.random.default_rng(_RNG_SEED)
    cases = [
        ("worked example X = (1, 2), V = (-1, -1), dt = 0.5",
         np.array([1.0, 2.0]), np.array([-1.0, -1.0]), 0.5),
        ("X = (0, 0), wind V = (7, 2), dt = 0.1", np.array([0.0, 0.0]), np.array([7.0, 2.0]), 0.1),
        ("4 particles, X and V of shape (4, 2), dt = 0.25",
         rng.uniform(-2.0, 2.0, size=(4, 2)), rng.uniform(-1.0, 1.0, size=(4, 2)), 0.25),
    ]
    for what, X, V, dt in cases:
        # The exact answer: V is constant over the step, so the displacement is dt * V.
        wind = fields.constant_wind(V) if V.ndim == 1 else (lambda t, Y, V=V: V)
        expected = integrate(wind, X, (0.0, dt), dt).y[-1]
        X_student, V_student = X.copy(), V.copy()
        ok, got = call(ck, what, advect_step, X_student, V_student, dt)
        if not ok:
            continue
        by_rows = np.array([X[0] + dt * V[0], X[1] + dt * V[1]]) if X.ndim == 2 else None
        _close(ck, got, expected, what, mistakes={
            **({hints.BY_ROWS_HINT: by_rows} if by_rows is not None else {}),
            hints.AGAINST_HINT: X - dt * V,
            hints.NO_DT_HINT: X + V,
            hints.DISPLACEMENT_HINT: dt * V,
            hints.HALF_DT_HINT: X + 0.5 * dt * V,
        }, hint=("in dt seconds each particle moves along its own velocity",
                 "the new position is X + dt * V"))
        ck.expect(
            np.array_equal(X_student, X) and np.array_equal(V_student, V),
            f"advect_step leaves X and V unchanged ({what})",
            "your function modified its inputs (X += ... changes the caller's array)",
            escalate("return X + dt * V as a new array instead of updating X in place",
                     "X += dt * V moves the caller's particles as well, so a notebook that keeps "
                     "X and also stores the result moves them twice: write return X + dt * V"),
        )


def particle_frame_reference(particles: dict, V, dt: float, newborn: dict) -> dict:
    """Update (move by dt V, age by dt), delete (age >= lifetime), create (append newborn)."""
    moved = dict(particles)
    moved["X"] = np.asarray(particles["X"], dtype=float) + dt * np.asarray(V, dtype=float)
    moved["age"] = np.asarray(particles["age"], dtype=float) + dt
    alive = moved["age"] < moved["lifetime"]
    return {key: np.concatenate([np.asarray(moved[key])[alive], np.asarray(newborn[key])])
            for key in moved}


@exercise(allow=())
def particle_frame(ck: Checker, particle_frame) -> None:
    """One frame of a particle system: move and age, delete the expired, append newborns."""
    for what, particles, V, dt, newborn in _particle_cases():
        _one_frame(ck, particle_frame, what, particles, V, dt, newborn)


def _one_frame(ck: Checker, particle_frame, what, particles, V, dt, newborn) -> None:
    expected = particle_frame_reference(particles, V, dt, newborn)
    given = {key: val.copy() for key, val in particles.items()}
    ok, got = call(ck, f"particle_frame runs ({what})", particle_frame, given, V.copy(), dt,
                   {key: val.copy() for key, val in newborn.items()})
    if not ok:
        return
    if not isinstance(got, dict):
        ck.expect(False, "particle_frame returns a dict of attribute arrays",
                  f"got {type(got).__name__}", hints.DICT_HINT)
        return
    missing = sorted(set(expected) - set(got))
    ck.expect(not missing, f"{what}: every attribute is kept (X, age, lifetime and colour)",
              f"missing keys {missing}",
              ("build the result from every key of particles, not only X, age and lifetime",
               "build the result from every key of particles, not only X, age and lifetime "
               "(e.g. {key: ... for key in particles})"))
    mistakes = _frame_mistakes(particles, V, dt, newborn)
    for key, unit in (("X", "positions"), ("age", "ages")):
        if key not in got:
            continue
        hint = _mistake_hint(got[key], {h: m[key] for h, m in mistakes.items()},
                             NEWBORN_HINT if newborns_changed(got[key], expected[key],
                                                                newborn[key])
                             else FRAME_ORDER_HINT)
        _close(ck, got[key], expected[key], f"{what}: the {unit}", hint=hint)
    for key in ("lifetime", "colour"):
        if key in got:
            _close(ck, got[key], expected[key], f"{what}: the {key} of the survivors and the "
                   "newborns", hint=hints.ATTRIBUTES_HINT)
    ck.expect(all(np.array_equal(particles[k], given[k]) for k in particles),
              f"{what}: particle_frame leaves its input unchanged",
              "your function modified the particles dict it was given", hints.NEW_DICT_HINT)


# --- flocking: the cohesion rule ---------------------------------------------------------


@exercise(allow=())
def cohesion(ck: Checker, cohesion) -> None:
    """``cohesion(X, radius)``: vector to the local centre of the neighbours, vectorised.

    A mistake is named only if every flock the answer gets wrong shows it: on a flock whose
    boids have one neighbour each, counting the boid itself halves the offset, as any halving
    does, so that flock alone cannot tell the two apart."""
    runs = []
    for what, X, radius in cohesion_cases():
        expected = cohesion_reference(X, radius)
        X_student = X.copy()
        ok, got = call_analysis(ck, what, COHESION_LINE_BUDGET, hints.LOOP_HINT, cohesion,
            X_student, radius, why=(
                "a vectorised answer runs a handful of lines whatever the size of the flock, so "
                "yours loops in Python (over the boids, or their pairs)"))
        if not ok and ck.failed and "lines of Python" in ck.failed[-1]:
            break  # one such verdict says it all
        if ok:
            runs.append((what, X, radius, X_student, expected, got))
    wrong = [(got, cohesion_mistakes(X, radius, expected))
             for _, X, radius, _, expected, got in runs if not _right_or_nan(got, expected)]
    named = next((h for h in (wrong[0][1] if wrong else ()) if all(
        _mistake_hint(got, {h: m[h]}) for got, m in wrong)), None)
    for what, X, _, X_student, expected, got in runs:
        answer = as_array(got)
        if answer is not None and answer.shape == expected.shape and np.isnan(answer).any():
            ck.expect(False, what, "your answer contains NaN", hints.NO_NEIGHBOUR_HINT)
            continue
        # Offsets between positions of up to 10 m: 10 µm is far below anything a flock
        # shows, and admits an answer computed in float32 anywhere along the way.
        _close(ck, got, expected, what, rtol=1e-6, atol=1e-5, hint=named or (
            "for each boid: the mean offset to its neighbours, and 0 without one",
            "for each boid i: the mean of X_j - X_i over the other boids j with "
            "|X_j - X_i| < radius, and 0 if there is none"))
        ck.expect(np.array_equal(X_student, X), f"cohesion leaves X unchanged ({what})",
                  "your function modified the positions it was given", hints.NEW_ARRAY_HINT)


def _right_or_nan(got, expected) -> bool:
    """Whether a cohesion answer matches ``expected`` at the check's tolerance, or holds NaN
    (which is told so on its own, and names no other mistake)."""
    answer = as_array(got)
    return answer is not None and answer.shape == np.shape(expected) and bool(
        np.allclose(answer, expected, rtol=1e-6, atol=1e-5) or np.isnan(answer).any())
