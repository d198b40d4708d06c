"""Hints of notebook 02's forward Euler step check
(:func:`~course_lib.check.nb02.forward_euler_step`), each escalating: the mistake named on a
first wrong attempt, then, after another one, the numbers of one of the check's cases (the
worked example, the vortex from (0, 1) with dt = 0.5; the time-dependent wind :func:`gust` at
t = 0.3 s) and the line to write. Imports NumPy and
:func:`course_lib.check.tolerance.escalate`.
"""

from __future__ import annotations

import numpy as np

from .tolerance import escalate

SLOPE_AT_END = (
    "the slope must be taken at the START of the step, f(t, y); you used the end of "
    "the step (time t + dt or the predicted end state)"
)
FROZEN_T = (
    "pass the step's time t to f: this field changes with time, and you evaluated it at "
    "t = 0"
)
NO_DT_HINT = escalate(
    "multiply the slope by dt: the position changes by dt * f(t, y), not by f(t, y)",
    "f(t, y) is a velocity (m/s) and dt * f(t, y) the displacement (m) over the step: on the "
    "worked example, the vortex from (0, 1) with dt = 0.5, the step gives (0, 1) + 0.5 (-1, 0) "
    "= (-0.5, 1), where y + f(t, y) gives (-1, 1)")
#: The worked example: the vortex from (0, 1) with dt = 0.5 steps to (-0.5, 1).
_WORKED = "on the worked example, the vortex from (0, 1) with dt = 0.5, the slope is (-1, 0)"
SIGN_HINT = escalate(
    "wrong sign: forward Euler moves ALONG the velocity, y + dt * f(t, y)",
    f"{_WORKED} and the step (0, 1) + 0.5 (-1, 0) = (-0.5, 1); y - dt * f(t, y) gives "
    "(0.5, 1), a step backwards: write return y + dt * f(t, y)")
INCREMENT_HINT = escalate(
    "return the new state y + dt * f(t, y), not only the change dt * f(t, y)",
    f"{_WORKED}, the change (-0.5, 0) and the new state (0, 1) + (-0.5, 0) = (-0.5, 1): add y")
HALF_HINT = escalate(
    "a step moves along the slope for the whole dt, not dt/2",
    f"{_WORKED} and the step ends at (-0.5, 1); half of it gives (-0.25, 1): drop the 0.5, "
    "y + dt * f(t, y)")
END_STATE_HINT = escalate(
    SLOPE_AT_END,
    f"{_WORKED} at the start, so the step ends at (-0.5, 1); the slope at the predicted end "
    "(-0.5, 1) is (-1, -0.5) and gives (-0.5, 0.75). Use f(t, y) only: return y + dt * f(t, y)")



def gust(t, y):
    """A non-autonomous field: a wind that turns with time, plus a little decay."""
    return np.stack((np.cos(t) - 0.5 * y[..., 0], np.sin(t) - 0.5 * y[..., 1]), axis=-1)


def _wind(t: float) -> str:
    """The wind of the time-dependent case at y = (0.5, -1) and time ``t``, as "(a, b)"."""
    return "(" + ", ".join(f"{v:.3f}" for v in gust(t, np.array([0.5, -1.0]))) + ")"


#: The fuller hints' worked numbers on the time-dependent wind case (t = 0.3 s, dt = 0.25 s).
_ON_WIND = ("on the time-dependent wind at t = 0.3 s from y = (0.5, -1) with dt = 0.25, the "
            f"slope at the start is f(0.3, y) = {_wind(0.3)}")
TIME_END_HINT = escalate(
    SLOPE_AT_END,
    f"{_ON_WIND}; you took f(0.55, y) = {_wind(0.55)}, the wind at the END of the step. Call f "
    "with the step's own t: return y + dt * f(t, y)")
FROZEN_T_HINT = escalate(
    FROZEN_T,
    f"{_ON_WIND}; at t = 0 the wind is f(0, y) = {_wind(0.0)}. Pass the t your step was given: "
    "f(t, y), not f(0, y)")
