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

from course_lib.check import (
    FAILURES,
    _nb01_cases,
    _nb01_hints,
    _nb02_cases,
    _nb02_hints,
    _nb03_cases,
    evaluate,
    nb01,
    nb02,
    nb03,
)
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


# --- 02 ---------------------------------------------------------------------------------------

def _euler(body: str) -> str:
    return _f(body, "forward_euler_step", "f, t, y, dt")


_ORDER = ("def observed_order(step, f, y0, T, n):\n    ends = []\n"
          "    for m in (n, 2 * n, 4 * n):\n        y, dt = np.array(y0, float), {dt}\n"
          "        for k in {steps}:\n            y = step(f, {clock}, y, dt)\n"
          "        ends.append(y)\n    a, b, c = ends\n"
          "    return float({log}({num} / {den}))\n")


def _order(dt="T / m", steps="range(m)", clock="k * dt", log="np.log2",
           num="np.linalg.norm(a - b)", den="np.linalg.norm(b - c)") -> str:
    return _ORDER.format(dt=dt, steps=steps, clock=clock, log=log, num=num, den=den)


_RADIUS = "def radius_after(r0, dt, n, k=0.0):\n    return {}\n"
_BRENTQ = ("def drift_dt(tol):\n    from scipy.optimize import brentq\n"
           "    g = lambda dt: (np.pi / dt) * np.log1p(dt * dt) - np.log1p({tol})\n"
           "    return {ret}\n")

CASES += [
    # Ex 1, forward_euler_step (the review's "f at t + dt")
    (nb02, "forward_euler_step", _euler("return y + dt * f(t + dt, y)"),
     "the slope must be taken at the START", ["(0.705, 0.796)", "f(0.55, y) = (0.603, 1.023)",
                                               "return y + dt * f(t, y)"]),
    (nb02, "forward_euler_step", _euler("t_next = t + dt\nslope = f(t_next, y)\n"
                                        "return y + dt * slope"),
     "the slope must be taken at the START", ["END of the step", "(0.603, 1.023)"]),
    (nb02, "forward_euler_step", _euler("y_end = y + dt * f(t, y)\n"
                                        "return y + dt * f(t + dt, y_end)"),
     "the slope must be taken at the START", ["(-1, -0.5)", "(-0.5, 0.75)"]),
    (nb02, "forward_euler_step", _euler("return y + dt * f(0.0, y)"), "you evaluated it at t = 0",
     ["f(0, y) = (0.750, 0.500)", "(0.705, 0.796)"]),
    (nb02, "forward_euler_step", _euler("t0 = 0\nreturn y + dt * np.asarray(f(t0, y))"),
     "you evaluated it at t = 0", ["f(t, y), not f(0, y)"]),
    (nb02, "forward_euler_step", _euler("return y - dt * f(t, y)"), "wrong sign",
     ["(0.5, 1)", "(-0.5, 1)"]),
    (nb02, "forward_euler_step", _euler("return dt * f(t, y)"), "not only the change",
     ["(-0.5, 0)", "add y"]),
    (nb02, "forward_euler_step", _euler("return y + 0.5 * dt * f(t, y)"), "not dt/2",
     ["(-0.25, 1)"]),
    # Ex 2, radius_after
    (nb02, "radius_after", _RADIUS.format("r0 * (1 - k * dt) ** n * (1 + dt * dt) ** (n / 2)"),
     "the two parts of a step do not multiply", ["0.7906", "0.7731"]),
    (nb02, "radius_after", _RADIUS.format("r0 * max(1 - 2 * k * dt + dt * dt, 0) ** (n / 2)"),
     "(k dt)² is missing", ["0.5625", "((1 - k * dt) ** 2 + dt ** 2)"]),
    (nb02, "radius_after", _RADIUS.format("r0 * abs(1 - k * dt + dt) ** n"),
     "the per-step factor is", ["0.7906 |X|"]),
    (nb02, "radius_after", _RADIUS.format(
        "r0 * np.sqrt(max(1 + n * ((1 - k * dt) ** 2 + dt * dt - 1), 0))"),
     "compound it n times", ["0.625^10", "factor ** (n / 2)"]),
    (nb02, "radius_after", _RADIUS.format("((1 - k * dt) ** 2 + dt * dt) ** (n / 2)"),
     "multiply by the starting radius r0", ["0.0477", "return r0 * ..."]),
    (nb02, "radius_after", "def radius_after(r0, dt, n, k=0.0):\n"
     "    x, y = r0, 0.0\n    for _ in range(n):\n"
     "        x, y = x + dt * (-y - k * x), y + dt * (x - k * y)\n"
     "    return float(np.hypot(x, y))\n", "not a simulation step by step",
     ["n = 1 000 000", "factor ** n"]),
    # Ex 3, drift_dt
    (nb02, "drift_dt", _BRENTQ.format(tol="tol / 100", ret="brentq(g, 1e-9, 1.0)"),
     "tol is a fraction", ["1.01", "without multiplying or dividing"]),
    (nb02, "drift_dt", _BRENTQ.format(tol="tol", ret="brentq(g, 1e-6, 1.0, xtol=1e-5)"),
     "is your root finder converged", ["off by", "default xtol (2e-12)"]),
    (nb02, "drift_dt", "def drift_dt(tol):\n    best = 0.0\n"
     "    for dt in np.arange(3e-3, 0.04, 1e-6):\n"
     "        if (1 + dt * dt) ** (np.pi / dt) <= 1 + tol:\n            best = dt\n"
     "    return float(best)\n", "stops too far from the root",
     ["off by", "scipy.optimize.brentq(g, 1e-6, 1.0)"]),
    (nb02, "drift_dt", _BRENTQ.format(tol="tol", ret="0.9 * brentq(g, 1e-6, 1.0)"),
     "is not the LARGEST that does", ["less than the 1 % allowed", "exactly 1 + tol"]),
    # Ex 4, observed_order (the review's "t frozen at 0")
    (nb02, "observed_order", _order(clock="0.0"), "your t stayed at 0",
     ["y = step(f, k * dt, y, dt)", "cos 3t stays 1"]),
    (nb02, "observed_order", _order(clock="t").replace("        for k in",
                                                      "        t = 0.0\n        for k in"),
     "your t stayed at 0", ["t = 0 shape"]),
    (nb02, "observed_order", _order(clock="(k + 1) * dt"), "not at dt",
     ["one step ahead", "t = k * dt"]),
    (nb02, "observed_order", _order(dt="T / n"), "not the same dt",
     ["0.075, 0.0375 and 0.01875 s", "dt = T / m"]),
    (nb02, "observed_order", _order(steps="range(n)"), "not n steps of each size",
     ["40, 80 and 160 steps", "range(m)"]),
    (nb02, "observed_order", _order(num="abs(a - b)[0]", den="abs(b - c)[0]"),
     "not one component", ["(θ, ω)", "np.linalg.norm(X_n - X_2n)"]),
    (nb02, "observed_order", _order(num="np.abs(a - b).max()", den="np.abs(b - c).max()"),
     "not the largest component", ["(3e-4, 4e-4)", "np.linalg.norm(d)"]),
    (nb02, "observed_order", _order(num="abs(np.sum(a - b))", den="abs(np.sum(b - c))"),
     "summing the components", ["4.2e-4"]),
    (nb02, "observed_order", _order(steps="range(m - 1)"), "one step short",
     ["2.925 s", "not range(m - 1)"]),
    (nb02, "observed_order", _order(steps="range(m + 1)"), "one step too many",
     ["3.075 s", "not range(m + 1)"]),
    (nb02, "observed_order", _order(num="np.linalg.norm(a - c)"), "compare neighbouring runs",
     ["log2 3 = 1.58"]),
    (nb02, "observed_order", _order(num="np.linalg.norm(b - c)", den="np.linalg.norm(a - b)"),
     "the ratio is upside down", ["log2(1/2) = -1"]),
    (nb02, "observed_order", _order(log="np.log"), "not the natural log", ["0.693"]),
    (nb02, "observed_order", _order(log="np.log10"), "not log10", ["0.301"]),
    (nb02, "observed_order", _order(log="round(np.log2").replace("))\n", ")))\n"),
     "not rounded to a whole order", ["without round() or int()"]),
]

# --- 03 ---------------------------------------------------------------------------------------

_R = "def stability_function(step, z):\n    z = np.asarray(z, dtype=complex)\n{}"
_LIMIT = ("def largest_stable_dt(f, y0, method, dt_hi):\n"
          "    def stable(dt):\n"
          "        return cl.integrate(f, y0, (0.0, 2000 * dt), dt, method).stable\n{}")
_POWERS = "def powers_stay_bounded(M):\n    mu = np.linalg.eigvals(M)\n    return bool({})\n"

CASES += [
    # Ex 1, stability_function (the review's real state)
    (nb03, "stability_function", _R.format(
        "    return step(lambda t, y: z * y, 0.0, np.ones(np.shape(z)), 1.0)\n"),
     "a real state cannot hold a complex R(z)", ["np.ones_like(z, dtype=complex)", "-1 + 1j"]),
    (nb03, "stability_function", _R.format(
        "    y0 = np.zeros(z.shape) + 1.0\n    return step(lambda t, y: z * y, 0.0, y0, 1.0)\n"),
     "a real state cannot hold a complex R(z)", ["float64", "casting"]),
    (nb03, "stability_function", _R.format(
        "    r = step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0)\n    return r * r\n"),
     "take one step, not two", ["0.0625", "0.0039"]),
    (nb03, "stability_function", _R.format(
        "    return np.abs(step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0))\n"),
     "the modulus", ["1 + z = 1j", "Drop np.abs"]),
    (nb03, "stability_function", _R.format("    return 1 + z\n"), "a method from the table",
     ["Kutta's third-order", "one call of step"]),
    # Ex 2, largest_stable_dt
    (nb03, "largest_stable_dt", _LIMIT.format("    return 0.25 * dt_hi\n"),
     "your function ran no simulation", ["traj.stable is True", "cl.integrate(f, y0"]),
    (nb03, "largest_stable_dt", _LIMIT.format("    stable(0.1 * dt_hi)\n    return 0.1 * dt_hi\n"),
     "your search ran no step above it", ["multiply the step by 1.1", "0.22 s"]),
    (nb03, "largest_stable_dt", _LIMIT.format(
        "    stable(0.1 * dt_hi)\n    stable(0.5 * dt_hi)\n    return 0.1 * dt_hi\n"),
     "your search tried no step between", ["try the middle, 0.6 s", "high / low > 1.01"]),
    (nb03, "largest_stable_dt", _LIMIT.format("    stable(0.1 * dt_hi)\n    return 0.275 * dt_hi\n"),
     "a run just above the limit grows slowly", ["694 steps", "|R| = 1.0"]),
    (nb03, "largest_stable_dt", "def largest_stable_dt(f, y0, method, dt_hi):\n"
     "    n = len(y0)\n    A = np.column_stack([f(0.0, e) for e in np.eye(n)])\n"
     "    lam = np.linalg.eigvals(A)\n    return float(np.min(-2 * lam.real / abs(lam) ** 2))\n",
     "judge each run by its verdict", ["none started from y0", "2000 * dt"]),
    # Ex 3, powers_stay_bounded (the review's "spectral radius only")
    (nb03, "powers_stay_bounded", _POWERS.format("np.max(np.abs(mu)) <= 1 + 1e-9"),
     "spectral radius ≤ 1 is not enough", ["M^10 = [[21, -20], [20, -19]]",
                                            "np.linalg.matrix_rank(M - μ I)"]),
    (nb03, "powers_stay_bounded", _POWERS.format("all(abs(m) < 1 + 1e-7 for m in mu)"),
     "spectral radius ≤ 1 is not enough", ["rank 1: one eigenvector"]),
    (nb03, "powers_stay_bounded", _POWERS.format("np.max(np.abs(mu)) < 1"),
     "|μ| = 1 neither grows nor decays", ["(-I)^n = ±I"]),
    (nb03, "powers_stay_bounded", _POWERS.format("np.max(np.abs(mu.real)) <= 1"),
     "an eigenvalue of modulus above 1", ["M^1000 about 21 000", "M^10 = [[21, -20]"]),
]


@pytest.mark.parametrize("module, exercise, source, nudge, more", CASES,
                         ids=[f"{c[1]}: {c[3][:30]}" for c in CASES])
def test_repeated_mistake_gets_a_fuller_hint(module, exercise, source, nudge, more):
    _escalates(module, exercise, source, nudge, more)


# --- every mistake hint of the six modules escalates -----------------------------------------

_MODULES = (nb01, nb02, nb03, _nb01_cases, _nb02_cases, _nb03_cases, _nb01_hints, _nb02_hints)
#: Where a call takes its hint by position: ``ck.expect(ok, what, detail, hint)``,
#: ``call_analysis(ck, what, budget, hint, ...)``.
_HINT_POSITION = {"expect": 3, "call_analysis": 3, "call_whole_array": 3}


def _plain_hints(module) -> list[str]:
    """The hints of ``module`` written as one string (or a one-element tuple), which would
    repeat the same text on a second wrong attempt: as ``hint=`` or by position in a check
    call, as a key of a mistakes dict, or returned by a ``*_hint`` function. A name is
    followed to its module-level value."""
    tree = ast.parse(inspect.getsource(module))
    constants = {t.id: node.value for node in tree.body if isinstance(node, ast.Assign)
                 for t in node.targets if isinstance(t, ast.Name)}
    found = []

    def plain(expr, seen=()) -> bool:
        if isinstance(expr, ast.Constant):
            return isinstance(expr.value, str)
        if isinstance(expr, ast.JoinedStr | ast.BinOp):
            return True
        if isinstance(expr, ast.Tuple):
            return len(expr.elts) < 2
        if isinstance(expr, ast.IfExp):
            return plain(expr.body, seen) or plain(expr.orelse, seen)
        if isinstance(expr, ast.BoolOp):
            return any(plain(v, seen) for v in expr.values)
        if isinstance(expr, ast.Name) and expr.id in constants and expr.id not in seen:
            return plain(constants[expr.id], (*seen, expr.id))
        return False   # escalate(...), a tuple of two or more, a local variable, None

    def flag(expr, where):
        if expr is not None and plain(expr):
            found.append(f"{module.__name__}:{expr.lineno} ({where}): "
                         f"{ast.unparse(expr)[:70]}")

    def visit(node, function=""):
        for child in ast.iter_child_nodes(node):
            name = function
            if isinstance(child, ast.FunctionDef):
                name = child.name
                if name.endswith("_hint"):
                    for ret in ast.walk(child):
                        if isinstance(ret, ast.Return):
                            flag(ret.value, f"returned by {name}")
            if isinstance(child, ast.Call):
                callee = child.func.attr if isinstance(child.func, ast.Attribute) else getattr(
                    child.func, "id", "")
                for kw in child.keywords:
                    if kw.arg == "hint":
                        flag(kw.value, "hint=")
                    if kw.arg == "mistakes" and isinstance(kw.value, ast.Dict):
                        for key in kw.value.keys:
                            flag(key, "mistakes=")
                pos = _HINT_POSITION.get(callee)
                if pos is not None and len(child.args) > pos:
                    flag(child.args[pos], f"{callee} hint")
            if isinstance(child, ast.Assign):   # mistakes = {...}; out[hint] = ... in one
                for target in child.targets:
                    if (isinstance(target, ast.Name) and "mistake" in target.id
                            and isinstance(child.value, ast.Dict)):
                        for key, value in zip(child.value.keys, child.value.values,
                                              strict=True):
                            flag(key, f"key of {target.id}")
                            if key is None and isinstance(value, ast.DictComp):  # **{...}
                                flag(value.key, f"key of {target.id}")
                    if "mistake" in name and isinstance(target, ast.Subscript):
                        flag(target.slice, f"key set in {name}")
            if "mistake" in name and isinstance(child, ast.Dict):
                for key in child.keys:
                    flag(key, f"key in {name}")
            if "mistake" in name and isinstance(child, ast.DictComp):
                flag(child.key, f"key in {name}")
            visit(child, name)

    visit(tree)
    for node in tree.body:   # module-level hints: *_HINT, and the values of *_HINTS
        for target in getattr(node, "targets", []):
            if isinstance(target, ast.Name) and target.id.endswith("HINT"):
                flag(node.value, target.id)
            if (isinstance(target, ast.Name) and target.id.endswith("HINTS")
                    and isinstance(node.value, ast.Dict)):
                for value in node.value.values:
                    flag(value, target.id)
    return found


def test_no_mistake_hint_is_a_single_string():
    """Every hint of the checks of 01-03 escalates: a plain string would repeat its text on
    the second wrong attempt."""
    found = [line for module in _MODULES for line in _plain_hints(module)]
    assert not found, "\n".join(found)


def test_the_walker_finds_plain_hints():
    """The walk above finds a plain-string hint in each of the forms the modules use (so that
    its silence means something)."""
    import types

    source = ('def check(ck):\n    ck.expect(False, "w", "d", "plain")\n'
              '    close(ck, 1, 2, "w", hint="plain")\n'
              '    close(ck, 1, 2, "w", mistakes={"plain": 1})\n'
              'def frame_mistakes():\n    out = {("one",): 1}\n    out["plain"] = 2\n'
              '    return out\n'
              'def check2(ck):\n    mistakes = {"plain": 1, **{f"{n}": 1 for n in "ab"}}\n'
              'def bad_hint():\n    return f"plain {1}"\n'
              'X_HINT = "plain"\nY_HINTS = {"k": "plain"}\n'
              'def ok(ck):\n    ck.expect(False, "w", "d", escalate("a", "b"))\n')
    module = types.ModuleType("planted_hints")
    module.__file__ = "<planted>"
    import linecache

    linecache.cache["<planted>"] = (len(source), None, source.splitlines(True), "<planted>")
    exec(compile(source, "<planted>", "exec"), {"escalate": lambda a, b: (a, b)})
    original = inspect.getsource
    try:
        inspect.getsource = lambda m: source if m is module else original(m)
        found = _plain_hints(module)
    finally:
        inspect.getsource = original
    assert len(found) == 10, found


def test_the_fuller_hints_numbers_are_right():
    """The numbers the fuller hints of 01-03 quote, recomputed from course_lib and the checks'
    own cases."""
    import course_lib as cl

    X, V = np.array([1.0, 2.0]), np.array([-1.0, -1.0])        # 01 Ex 3's worked example
    np.testing.assert_allclose(cl.forward_euler(lambda t, y: V, 0.0, X, 0.5), [0.5, 1.5])
    np.testing.assert_allclose([X + V, X - 0.5 * V, X + 0.25 * V, 0.5 * V],
                               [[0, 1], [1.5, 2.5], [0.75, 1.75], [-0.5, -0.5]])
    vortex = cl.fields.vortex
    np.testing.assert_allclose(vortex(0.0, np.array([0.5, -1.5])), [1.5, 0.5])
    np.testing.assert_allclose(nb01.whirlpool_reference(0.0, np.array([0.0, 1.0]), 0.5),
                               [-1.0, -0.5])
    np.testing.assert_allclose(nb01.whirlpool_reference(0.0, np.array([1.0, 0.0]), 2.0),
                               [-2.0, 1.0])
    (_, flock, r1), (_, at_radius, r2) = _nb01_cases.cohesion_cases()[:2]
    right = _nb01_cases.cohesion_reference(flock, r1)
    wrong = _nb01_cases.cohesion_mistakes(flock, r1, right)
    by_hint = {h[0] if isinstance(h, tuple) else h: w for h, w in wrong.items()}
    np.testing.assert_allclose(right[3], [0.5, 0.0])
    np.testing.assert_allclose(by_hint[next(h for h in by_hint if "its own" in h)][3], [0.25, 0])
    np.testing.assert_allclose(flock.mean(axis=0), [2.3, 2.2])
    near = _nb01_cases.cohesion_reference(at_radius, r2)[0]
    D = at_radius[None] - at_radius[:, None]
    np.testing.assert_allclose(near, [0.0, 1.0])
    np.testing.assert_allclose(_nb01_cases.cohesion_within(
        at_radius, D, (D**2).sum(-1) <= r2**2)[0], [0.75, 0.5])
    _, frame, _, dt, _ = _nb01_cases.particle_cases()[0]          # 01 Ex 4, frame 1
    assert frame["age"][1] + dt == frame["lifetime"][1] == 1.0
    assert frame["age"][2] + dt == 2.0 > frame["lifetime"][2] == 1.75
    # 02: the worked step, the radius factors, the drift step, the finest-run ratio
    y = np.array([0.0, 1.0])
    end = y + 0.5 * vortex(0.0, y)
    np.testing.assert_allclose(y + 0.5 * vortex(0.5, end), [-0.5, 0.75])
    assert f"{math.sqrt(0.625):.4f}" == "0.7906" and f"{0.75 * math.sqrt(1.0625):.4f}" == "0.7731"
    assert nb02.radius_formula(0.5, 0.25, 10, 1.0) == pytest.approx(0.0477, abs=5e-5)
    assert f"{nb02.largest_drift_dt(0.01):.4f}" == "0.0032"
    assert f"{math.log2(3):.2f}" == "1.58" and f"{math.log(2):.3f}" == "0.693"
    assert f"{np.linalg.norm([3e-4, -3e-4]):.1e}" == "4.2e-04"
    # 03: R of two half steps, the Jordan block's powers, growth and transients
    assert (1 - 1.25) ** 2 == 0.0625 and f"{0.0625**2:.4f}" == "0.0039"
    M = np.array([[-3.0, 2.0], [-2.0, 1.0]])
    np.testing.assert_array_equal(np.linalg.matrix_power(M, 10), [[21, -20], [20, -19]])
    assert np.linalg.matrix_rank(M + np.eye(2)) == 1
    assert 20_000 < 1.01**1000 < 22_000 and round(math.log(1000) / math.log(1.01)) == 694
    T = np.array([[0.5, 100.0], [0.0, 0.5]])
    corners = [np.linalg.matrix_power(T, n)[0, 1] for n in (1, 2, 3, 30)]
    np.testing.assert_allclose(corners[:3], [100, 100, 75])
    assert corners[3] < 1e-5
    assert 3.6 < 1000 * 0.999**999 / 100 < 3.8     # 1e306 n 0.999^(n-1): 3.7e308 near 1000
