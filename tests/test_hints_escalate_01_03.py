"""Hints of notebooks 01-03 escalate: the same wrong answer gets the nudge on a first attempt
and, after another failure in the same kernel, a fuller hint that adds something concrete (a
number worked out for one of the check's cases, or the line of code to write), never the same
text again (blind review 2026-11-28, sixth read: 01 Ex 3, 4 and 6, 02 Ex 1 and 4, 03 Ex 1 and 3
repeated their text). Each mistake is planted twice, as the review's answer and as one of our
own of the same class; a last test reads the check modules and fails on any mistake hint
written as a plain string."""

from __future__ import annotations

import ast
import inspect
import math

import numpy as np
import pytest

from course_lib.check import FAILURES, _nb01_cases, _nb02_cases, _nb03_cases, evaluate, nb01, nb02, nb03
from tests.planted import define


def _hints(module, exercise: str, source: str, attempt: int) -> list[str]:
    """The hint lines a planted answer gets after ``attempt`` earlier wrong attempts."""
    check = getattr(module, exercise)
    FAILURES.pop(check.key, None)
    if attempt:
        FAILURES[check.key] = attempt
    try:
        verdict = evaluate(check, define(source, exercise))
    finally:
        FAILURES.pop(check.key, None)
    assert verdict["status"] == "incorrect", (exercise, verdict["failed_cases"])
    return [line.split("hint: ", 1)[1] for case in verdict["failed_cases"]
            for line in case.splitlines() if "hint: " in line]


def _escalates(module, exercise, source, nudge, more) -> None:
    """First attempt: a hint holding ``nudge`` and none of ``more``; second: that hint
    again (the mistake named) followed by every one of ``more``, and no hint repeated as is."""
    first, second = (_hints(module, exercise, source, a) for a in (0, 1))
    assert any(nudge in h for h in first), (exercise, first)
    assert not any(m in h for h in first for m in more), (exercise, first)
    fuller = [h for h in second if nudge in h]
    assert fuller and all(m in fuller[0] for m in more), (exercise, second)
    assert set(first).isdisjoint(second), (exercise, first, second)
    assert len(fuller[0]) > len(next(h for h in first if nudge in h)) + 40


def _f(body: str, name: str = "f", args: str = "t, X") -> str:
    return f"def {name}({args}):\n" + "".join(f"    {line}\n" for line in body.split("\n"))


CASES = [
    # --- 01 Ex 1/2, the fields --------------------------------------------------------------
    (nb01, "vortex_field", _f("X = np.asarray(X, float)\nreturn np.stack((X[..., 1], X[..., 0]), -1)",
                              "vortex_field"), "a minus sign is missing", ["(1, 0)", "-X[..., 1]"]),
    (nb01, "vortex_field", _f("X = np.asarray(X, float)\nreturn np.stack((-X[..., 0], X[..., 1]), -1)",
                              "vortex_field"), "the components are not swapped",
     ["(-1, 0)", "X[..., 0]"]),
    (nb01, "vortex_field", _f("return np.array(X, float)", "vortex_field"),
     "that is the radial field", ["(1, 0)", "np.stack((-X[..., 1], X[..., 0]), axis=-1)"]),
    (nb01, "vortex_field", _f("X[..., 0], X[..., 1] = -X[..., 1].copy(), X[..., 0].copy()\n"
                              "return X", "vortex_field"), "do not assign into X",
     ["np.stack((vx, vy), axis=-1)", "X.copy()"]),
    (nb01, "vortex_field", _f("X = np.asarray(X, float)\n"
                              "return np.stack((-X[..., 1], X[..., 0]), -1) * np.cos(t)",
                              "vortex_field"), "does not depend on t",
     ["(0.5, -1.5)", "(1.5, 0.5)"]),
    (nb01, "vortex_field", _f("X = np.asarray(X, float)\nreturn np.array([-X[1], X[0]])",
                              "vortex_field"), "are the first two ROWS",
     ["x, y = X[..., 0], X[..., 1]"]),
    (nb01, "vortex_field", _f("return np.array([-X[:, 1], X[:, 0]]).T", "vortex_field"),
     "X may be one position of shape (2,)", ["X.shape == (2,)", "IndexError"]),
    (nb01, "vortex_field", _f("if X.ndim == 1:\n    return np.array([-X[1], X[0]])\n"
                              "return np.stack((-X[:, 1], X[:, 0]), axis=1)", "vortex_field"),
     "right for a cloud of shape (N, 2)", ["the four y's", "np.stack((vx, vy), axis=-1)"]),
    (nb01, "whirlpool", _f("return -k * np.asarray(X, float)", "whirlpool", "t, X, k=0.5"),
     "the vortex part (-y, x) is missing", ["(-0.5, 1)", "(-0.5, 0)"]),
    (nb01, "whirlpool", _f("X = np.asarray(X, float)\nreturn np.stack((-X[..., 1], X[..., 0]), -1)",
                           "whirlpool", "t, X, k=0.5"), "the inward pull -k (x, y) is missing",
     ["(-0.5, 1)", "subtract k * X"]),
    (nb01, "whirlpool", _f("X = np.asarray(X, float)\n"
                           "return np.stack((-X[..., 1] - k * X[..., 0], X[..., 0]), -1)",
                           "whirlpool", "t, X, k=0.5"), "your pull acts on x only",
     ["(-1, -0.5)", "x - k y"]),
    (nb01, "whirlpool", _f("X = np.asarray(X, float)\n"
                           "return np.stack((-X[..., 1], X[..., 0] - k * X[..., 1]), -1)",
                           "whirlpool", "t, X, k=0.5"), "your pull acts on y only",
     ["(-0.5, 1)", "-y - k x"]),
    (nb01, "whirlpool", _f("X = np.asarray(X, float)\n"
                           "return np.stack((-X[..., 1] - 0.5 * X[..., 0], "
                           "X[..., 0] - 0.5 * X[..., 1]), -1)", "whirlpool", "t, X, k=0.5"),
     "use the argument k", ["(-2, 1)", "replace the number 0.5"]),
    # --- 01 Ex 3, advect_step (the review's "no dt") ------------------------------------------
    (nb01, "advect_step", _f("return X + V", "advect_step", "X, V, dt"), "dt is missing",
     ["(0.5, 1.5)", "(0, 1)", "return X + dt * V"]),
    (nb01, "advect_step", _f("step = np.asarray(V, float)\nnew = np.asarray(X, float) + step\n"
                             "return new", "advect_step", "X, V, dt"), "dt is missing",
     ["(-0.5, -0.5)", "return X + dt * V"]),
    (nb01, "advect_step", _f("return X - dt * V", "advect_step", "X, V, dt"),
     "you moved against the velocity", ["(1.5, 2.5)", "X + dt * V"]),
    (nb01, "advect_step", _f("return dt * V", "advect_step", "X, V, dt"),
     "you returned the displacement", ["(0.5, 1.5)", "add X"]),
    (nb01, "advect_step", _f("return X + dt * V / 2", "advect_step", "X, V, dt"),
     "you used dt / 2", ["(0.75, 1.75)"]),
    (nb01, "advect_step", _f("X += dt * V\nreturn X", "advect_step", "X, V, dt"),
     "instead of updating X in place", ["moves them twice", "the caller's particles"]),
    (nb01, "advect_step", _f("if X.ndim == 1:\n    return X + dt * V\n"
                             "return np.array([X[0] + dt * V[0], X[1] + dt * V[1]])",
                             "advect_step", "X, V, dt"), "are the first two PARTICLES",
     ["X[0] is particle 0's (x, y)", "return X + dt * V"]),
]


_FRAME = ("def particle_frame(particles, V, dt, newborn):\n"
          "    X = particles['X'] + dt * V\n    age = particles['age'] + dt\n"
          "    alive = {alive}\n"
          "    out = {{k: np.concatenate([particles[k][alive], newborn[k]]) for k in particles}}\n"
          "    out['X'] = np.concatenate([{X}, newborn['X']])\n"
          "    out['age'] = np.concatenate([{age}, newborn['age']])\n    return out\n")


def _frame(alive="age < particles['lifetime']", X="X[alive]", age="age[alive]"):
    return _FRAME.format(alive=alive, X=X, age=age)


_COHESION = ("def cohesion(X, radius):\n    X = np.asarray(X, float)\n"
             "    D = X[None, :, :] - X[:, None, :]\n"
             "    near = (D ** 2).sum(axis=-1) {cmp} radius ** 2\n{diag}"
             "    count = near.sum(axis=1, keepdims=True)\n"
             "    return {ret}\n")


def _cohesion(cmp="<", diag="    np.fill_diagonal(near, False)\n",
              ret="np.einsum('ij,ijk->ik', near, D) / np.maximum(count, 1)"):
    return _COHESION.format(cmp=cmp, diag=diag, ret=ret)


CASES += [
    # --- 01 Ex 4, particle_frame (the review's "age <= lifetime") -----------------------------
    (nb01, "particle_frame", _frame(alive="age <= particles['lifetime']"),
     "a particle dies when its age reaches its lifetime",
     ["0.5 s old with a lifetime of 1 s", "alive = age < lifetime"]),
    (nb01, "particle_frame", _frame(alive="~(age > particles['lifetime'])"),
     "a particle dies when its age reaches its lifetime", ["1.0 s, equal to its lifetime"]),
    (nb01, "particle_frame", _frame(alive="np.ones(len(age), bool)"), "no particle was deleted",
     ["1.75 s", "particles[key][alive]"]),
    (nb01, "particle_frame", _frame(alive="particles['age'] < particles['lifetime']",
                                    age="particles['age'][alive]"),
     "age every particle by dt", ["its old age 0.5 s", "particles['age'] + dt"]),
    (nb01, "particle_frame", _frame(X="particles['X'][alive]"),
     "move every surviving particle", ["(0.5, 0)", "particles['X'] + dt * V"]),
    (nb01, "particle_frame", _frame(alive="np.arange(len(age)) >= np.sum(age >= "
                                    "particles['lifetime'])"),
     "the expired particles are not always the first rows", ["2nd, 4th and 7th", "X[3:]"]),
    (nb01, "particle_frame", _frame(X="np.concatenate([X, newborn['X']])[:len(X)][alive]"
                                    "[:0] if False else X[alive] + 0 * dt",
                                    age="age[alive]").replace(
                                        "newborn['age']])", "newborn['age'] + dt])"),
     "the newborns were moved or aged", ["(5, 5) and (6, 6)"]),
    (nb01, "particle_frame", _frame().replace("    return out\n",
                                              "    out['colour'] = particles['colour']\n"
                                              "    return out\n"),
     "every attribute must be filtered", ["np.concatenate([particles[key][alive]"]),
    (nb01, "particle_frame", _frame().replace("    X = particles['X'] + dt * V\n",
                                              "    particles['X'] += dt * V\n"
                                              "    X = particles['X']\n"),
     "build and return a new dict", ["out = {}"]),
    # --- 01 Ex 6, cohesion (the review's "includes self") -------------------------------------
    (nb01, "cohesion", _cohesion(diag=""), "a boid is not its own neighbour",
     ["(0.25, 0)", "np.fill_diagonal(near, False)"]),
    (nb01, "cohesion", _cohesion(diag="", ret="(near[..., None] * D).sum(axis=1) / count"),
     "a boid is not its own neighbour", ["(5.5, 5)", "(0.5, 0)"]),
    (nb01, "cohesion", _cohesion(cmp="<="), "a boid exactly `radius` away",
     ["(0.75, 0.5)", "dist2 < radius**2"]),
    (nb01, "cohesion", _cohesion(ret="-np.einsum('ij,ijk->ik', near, D) / np.maximum(count, 1)"),
     "your pull points away", ["(-0.5, 0)", "X[None, :, :] - X[:, None, :]"]),
    (nb01, "cohesion", _cohesion(ret="np.where(count > 0, np.einsum('ij,ijk->ik', near, D) / "
                                 "np.maximum(count, 1) + X, 0.0)"),
     "not the centre itself", ["(5.5, 5) - (5, 5)"]),
    (nb01, "cohesion", _cohesion(ret="X.mean(axis=0) - X"), "not of the whole flock",
     ["(2.3, 2.2)", "(-2.7, -2.8)"]),
    (nb01, "cohesion", _cohesion(ret="np.einsum('ij,ijk->ik', near, D) / count").replace(
        "    return", "    with np.errstate(invalid='ignore'):\n        return"),
     "a boid with no neighbour has no pull", ["np.maximum(count, 1)", "3 m apart"]),
    (nb01, "cohesion", "def cohesion(X, radius):\n    X = np.asarray(X, float)\n"
     "    out = np.zeros_like(X)\n    for i in range(len(X)):\n"
     "        d = X - X[i]\n        near = (d ** 2).sum(1) < radius ** 2\n"
     "        near[i] = False\n        if near.any():\n"
     "            out[i] = d[near].mean(axis=0)\n    return out\n",
     "without a Python loop over the boids", ["X[None, :, :] - X[:, None, :]", "(N, N, 2)"]),
]


@pytest.mark.parametrize("module, exercise, source, nudge, more", CASES,
                         ids=[f"{c[1]}: {c[3][:30]}" for c in CASES])
def test_repeated_mistake_gets_a_fuller_hint(module, exercise, source, nudge, more):
    _escalates(module, exercise, source, nudge, more)
