"""Checks for notebook 01, "Particles in vector fields".

Each check compares the student's function with the reference in :mod:`course_lib`
(:mod:`course_lib.fields`, :func:`course_lib.integrate`) on a few cases, and names the
usual mistake when the answer matches it.
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import integrate
from . import Checker, exercise

_RNG_SEED = 2026

# Hints shared by the field exercises.
_SHAPE_HINT = (
    "return one velocity per position, an array of X's shape: take the columns with "
    "X[..., 0] and X[..., 1] (not X[0] and X[1], which are rows when X is (N, 2)) and "
    "join them with np.stack((vx, vy), axis=-1)"
)


def _points() -> list[tuple[str, np.ndarray]]:
    """Positions to test a field on: single points (2,), a cloud (N, 2), a grid (n, n, 2)."""
    rng = np.random.default_rng(_RNG_SEED)
    g = np.stack(fields.grid(extent=2.0, n=2), axis=-1)
    return [
        ("X = (1, 0)", np.array([1.0, 0.0])),
        ("X = (0, 1)", np.array([0.0, 1.0])),
        ("X = (3, -2)", np.array([3.0, -2.0])),
        ("3 particles, X of shape (3, 2)", rng.uniform(-2.0, 2.0, size=(3, 2))),
        ("a 2 x 2 grid, X of shape (2, 2, 2)", g),
    ]


def _mistake_hint(actual, mistakes: dict[str, object], default: str | None = None) -> str | None:
    """The hint of the first typical mistake ``actual`` matches (any shape), else ``default``.

    ``Checker.close`` only compares mistakes of the expected shape; a wrong shape gets
    :data:`_SHAPE_HINT` unless it matches a listed mistake exactly.
    """
    try:
        a = np.asarray(actual, dtype=float)
    except (TypeError, ValueError):
        return default
    for hint, wrong in mistakes.items():
        w = np.asarray(wrong, dtype=float)
        if w.shape == a.shape and np.allclose(a, w, rtol=1e-9, atol=1e-12):
            return hint
    return default


def _field_cases(ck: Checker, answer, reference, mistakes_of, name: str, points=None,
                 time_check: bool = True, formula: str | None = None) -> None:
    untouched = True
    for what, X in (_points() if points is None else points):
        X_before = X.copy()
        got = answer(0.0, X)
        untouched = untouched and np.array_equal(X, X_before)
        shape_ok = np.shape(got) == X.shape
        hint = _mistake_hint(got, mistakes_of(X), formula if shape_ok else _SHAPE_HINT)
        ck.close(got, reference(0.0, X), f"{name} at {what}", hint=hint)
    ck.expect(untouched, f"{name} leaves X unchanged",
              "your function modified the positions it was given",
              "compute a new array; do not assign into X")
    if time_check:
        X = np.array([0.5, -1.5])
        right_at_0 = np.allclose(np.asarray(answer(0.0, X), dtype=float), reference(0.0, X))
        ck.close(answer(2.7, X), reference(2.7, X), f"{name} at t = 2.7 s (time-independent)",
                 hint="this field does not depend on t; do not use t in the formula"
                 if right_at_0 else formula)


@exercise
def vortex_field(ck: Checker, vortex_field) -> None:
    """The rotational vortex V = (-y, x), compared with ``course_lib.fields.vortex``."""

    def mistakes(X):
        x, y = X[..., 0], X[..., 1]
        return {
            "that is the clockwise vortex (y, -x): the x-component is -y and the "
            "y-component is +x, so that (1, 0) moves up, towards (0, 1)": np.stack((y, -x), -1),
            "a minus sign is missing: V = (-y, x), not (y, x)": np.stack((y, x), -1),
            "the components are not swapped: V = (-y, x), not (-x, y)": np.stack((-x, y), -1),
            "that is the radial field (x, y); the vortex swaps the components and negates "
            "the new x-component": X,
        }

    _field_cases(ck, vortex_field, fields.vortex, mistakes, "vortex_field(t, X)",
                 formula="V = (-y, x): the x-component is -y and the y-component is x")


def whirlpool_reference(t: float, X, k: float = 0.5) -> np.ndarray:
    """Vortex plus an inward pull of strength ``k``: ``(-y, x) - k (x, y)``, from course_lib."""
    return fields.compose(fields.vortex, fields.scaled(fields.radial, -k))(t, X)


@exercise
def whirlpool(ck: Checker, whirlpool) -> None:
    """The whirlpool V = (-y, x) - k (x, y), against ``compose(vortex, scaled(radial, -k))``."""
    for k, points in ((0.5, None), (2.0, _points()[3:4])):

        def reference(t, X, k=k):
            return whirlpool_reference(t, X, k)

        def answer(t, X, k=k):
            return whirlpool(t, X, k=k)

        def mistakes(X, k=k):
            out = {
                "the pull points outwards: subtract k (x, y) so that particles move "
                "towards the origin": whirlpool_reference(0.0, X, -k),
                "the vortex part (-y, x) is missing: a whirlpool turns while it pulls in":
                    -k * np.asarray(X, dtype=float),
                "the inward pull -k (x, y) is missing": fields.vortex(0.0, X),
            }
            if k != 0.5:
                out[f"use the argument k: this case calls whirlpool(t, X, k={k:g}), but your "
                    "answer is the one for k = 0.5"] = whirlpool_reference(0.0, X, 0.5)
            return out

        _field_cases(ck, answer, reference, mistakes, f"whirlpool(t, X, k={k:g})", points,
                     time_check=points is None,
                     formula="V = (-y, x) - k (x, y), that is (-y - k x, x - k y)")


@exercise
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
        X_before, V_before = X.copy(), V.copy()
        # The exact answer: V is constant over the step, so the displacement is dt * V.
        wind = fields.constant_wind(V) if V.ndim == 1 else (lambda t, Y, V=V: V)
        expected = integrate(wind, X, (0.0, dt), dt).y[-1]
        got = advect_step(X, V, dt)
        ck.close(got, expected, what, mistakes={
            "you moved against the velocity: the new position is X + dt V, not X - dt V":
                X - dt * V,
            "dt is missing (or taken as 1): in dt seconds a particle moves dt * V, "
            "not V": X + V,
            "you returned the displacement dt V; return the new position X + dt V": dt * V,
            "you used dt / 2: a step of dt moves the particle by the whole dt * V":
                X + 0.5 * dt * V,
        }, hint="the new position is X + dt * V")
        ck.expect(
            np.array_equal(X, X_before) and np.array_equal(V, V_before),
            f"advect_step leaves X and V unchanged ({what})",
            "your function modified its inputs (X += ... changes the caller's array)",
            "return X + dt * V as a new array instead of updating X in place",
        )


def particle_frame_reference(particles: dict, V, dt: float, newborn: dict) -> dict:
    """Update (move by dt V, age by dt), delete (age >= lifetime), create (append newborn)."""
    moved = dict(particles)
    moved["X"] = np.asarray(particles["X"], dtype=float) + dt * np.asarray(V, dtype=float)
    moved["age"] = np.asarray(particles["age"], dtype=float) + dt
    alive = moved["age"] < moved["lifetime"]
    return {key: np.concatenate([np.asarray(moved[key])[alive], np.asarray(newborn[key])])
            for key in moved}


def _particle_case():
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
    return particles, V, 0.5, newborn


@exercise
def particle_frame(ck: Checker, particle_frame) -> None:
    """One frame of a particle system: move and age, delete the expired, append newborns."""
    particles, V, dt, newborn = _particle_case()
    before = {key: val.copy() for key, val in particles.items()}
    got = particle_frame(particles, V, dt, newborn)
    expected = particle_frame_reference(particles, V, dt, newborn)
    if not isinstance(got, dict):
        ck.expect(False, "particle_frame returns a dict of attribute arrays",
                  f"got {type(got).__name__}", "return a dict with the same keys as particles")
        return
    missing = sorted(set(expected) - set(got))
    ck.expect(not missing, "every attribute is kept (X, age, lifetime and colour)",
              f"missing keys {missing}",
              "build the result from every key of particles, not only X, age and lifetime "
              "(e.g. {key: ... for key in particles})")

    # What the usual mistakes produce, frame by frame.
    n = len(particles["age"])

    def variant(age_new, alive, move=True):
        X = particles["X"] + (dt * V if move else 0.0)
        return {
            "X": np.concatenate([X[alive], newborn["X"]]),
            "age": np.concatenate([age_new[alive], newborn["age"]]),
        }

    aged = particles["age"] + dt
    life = particles["lifetime"]
    mistakes = {
        "a particle dies when its age reaches its lifetime: keep age < lifetime, "
        "so one whose age equals its lifetime is deleted": variant(aged, aged <= life),
        "no particle was deleted: after ageing, delete every particle whose new age "
        "has reached its lifetime (age >= lifetime)": variant(aged, np.ones(n, dtype=bool)),
        "age every particle by dt this frame (age + dt), then compare with the lifetime":
            variant(particles["age"], particles["age"] < life),
        "move every surviving particle by dt * V": variant(aged, aged < life, move=False),
    }
    for key, unit in (("X", "positions"), ("age", "ages")):
        if key not in got:
            continue
        hint = _mistake_hint(got[key], {h: m[key] for h, m in mistakes.items()},
                             "update, then delete, then create: survivors first, newborns "
                             "appended at the end")
        ck.close(got[key], expected[key], f"the {unit} after one frame (dt = 0.5 s)", hint=hint)
    for key in ("lifetime", "colour"):
        if key in got:
            ck.close(got[key], expected[key], f"the {key} of the survivors and the newborns",
                     hint="every attribute must be filtered with the same alive mask "
                          "and then extended with the newborns'")
    ck.expect(all(np.array_equal(particles[k], before[k]) for k in before),
              "particle_frame leaves its input unchanged",
              "your function modified the particles dict it was given",
              "build and return a new dict")
