"""Notebook 05 (Newton's second law): the falling apple and the energy of symplectic methods.

Pure scenes built on the core (:mod:`course_lib.integrators`, :mod:`course_lib.systems`,
:mod:`course_lib.events`); the core never imports this module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import forces
from ..integrators import Trajectory, integrate
from ..systems import newtonian, stack_state

G_STD = 9.81  #: standard gravity (m/s²)


# --- notebook 05: the apple ---------------------------------------------------------------


def apple_drop(method: str, dt: float = 0.1, h0: float = 10.0, g: float = G_STD,
               t_end: float = 2.0) -> Trajectory:
    """An apple (1 kg) released at rest at height ``h0`` under constant gravity, in 2D.

    The state is ``y = (x, v)`` of shape ``(2, 1, 2)``; the height is ``y[:, 0, 0, 1]``.
    """
    system = newtonian(forces.constant_gravity(1.0, g=[0.0, -g]), mass=1.0)
    y0 = stack_state([[0.0, h0]], [[0.0, 0.0]])
    return integrate(system, y0, (0.0, t_end), dt, method)


def euler_apple_height(n, dt: float = 0.1, h0: float = 10.0, g: float = G_STD):
    """Closed form of forward Euler's height after ``n`` steps: ``h0 - g dt² n(n-1)/2``."""
    n = np.asarray(n, dtype=float)
    return h0 - g * dt**2 * n * (n - 1) / 2


def symplectic_apple_height(n, dt: float = 0.1, h0: float = 10.0, g: float = G_STD):
    """Closed form of symplectic Euler's height after ``n`` steps: ``h0 - g dt² n(n+1)/2``."""
    n = np.asarray(n, dtype=float)
    return h0 - g * dt**2 * n * (n + 1) / 2


# --- notebook 05: energy of the oscillator ---------------------------------------------


def symplectic_modified_energy(y, omega: float, dt: float):
    """``½ v² + ½ ω² x² - ½ dt ω² x v``: conserved exactly by symplectic Euler on
    ``x'' = -ω² x`` (states ``(..., 2)`` in the layout ``(x, v)``)."""
    y = np.asarray(y)
    x, v = y[..., 0], y[..., 1]
    return 0.5 * v**2 + 0.5 * omega**2 * x**2 - 0.5 * dt * omega**2 * x * v


def verlet_modified_energy(y, omega: float, dt: float):
    """``½ v² + ½ ω² (1 - ω² dt²/4) x²``: conserved exactly by velocity Verlet on
    ``x'' = -ω² x``."""
    y = np.asarray(y)
    x, v = y[..., 0], y[..., 1]
    return 0.5 * v**2 + 0.5 * omega**2 * (1.0 - 0.25 * (omega * dt) ** 2) * x**2


# --- notebook 05: the phase error of symplectic methods ----------------------------------


def discrete_frequency(omega: float, dt: float) -> float:
    """Angular frequency (rad/s) of symplectic Euler and velocity Verlet on ``x'' = -ω² x``:
    both step matrices have determinant 1 and trace ``2 - ω² dt²``, so their eigenvalues are
    ``e^{±i ω̃ dt}`` with ``cos ω̃ dt = 1 - ω² dt² / 2`` (for ``ω dt < 2``)."""
    return float(np.arccos(1.0 - 0.5 * (omega * dt) ** 2) / dt)


def phase_error(t, y, omega: float = 1.0):
    """Phase (rad) of an oscillator run ``y = (x, v)`` (shape ``(n, 2)``) minus the exact
    ``ω t`` of ``x0 cos ω t``: positive when the run is ahead. The phase is the angle of
    ``(x, -v/ω)``, unwrapped."""
    y = np.asarray(y, dtype=float)
    return np.unwrap(np.arctan2(-y[:, 1] / omega, y[:, 0])) - omega * np.asarray(t)


# --- notebook 05: the position (Störmer) form of Verlet -----------------------------------


def stormer_verlet(accel, x0, v0, dt: float, n_steps: int, start: str = "taylor"):
    """Positions of Störmer's (position) form of Verlet, ``x_{k+1} = 2 x_k - x_{k-1} + dt² a(x_k)``,
    started with the Taylor step ``x_1 = x0 + dt v0 + dt²/2 a(x0)`` (``start="euler"``:
    the usual slip ``x_1 = x0 + dt v0``). Returns the positions, shape ``(n+1, ...)``.

    No velocities are stored; they can be recovered as ``(x_{k+1} - x_{k-1}) / 2 dt``.
    """
    x = np.empty((n_steps + 1, *np.shape(x0)))
    x[0] = x0
    x[1] = x[0] + dt * np.asarray(v0) + (0.5 * dt**2 * accel(x[0]) if start == "taylor" else 0.0)
    for k in range(1, n_steps):
        x[k + 1] = 2.0 * x[k] - x[k - 1] + dt**2 * accel(x[k])
    return x


# --- notebook 05: orders measured without an exact solution ------------------------------


def pendulum(g_over_l: float = 9.81):
    """``f(t, y)`` of the pendulum ``θ'' = -(g/L) sin θ``, ``y = (θ, θ')`` of shape (2,):
    no elementary closed-form solution."""

    def f(t, y):
        return np.array([y[1], -g_over_l * np.sin(y[0])])

    return f


def reference_run(f, y0, t1: float, n_steps: int = 20000):
    """State at ``t1`` from RK4 with ``n_steps`` steps: a stand-in for the exact solution,
    far more accurate than the runs it judges."""
    return integrate(f, y0, (0.0, t1), t1 / n_steps, "rk4").y[-1]


def step_errors(method: str, dts, f=None, y0=(1.0, 0.0), t1: float = 2.0):
    """Local (one step from ``y0``) and global (at ``t1``) errors of ``method`` for each
    step in ``dts``, against :func:`reference_run`. Returns two arrays."""
    from ..integrators import step

    f = pendulum() if f is None else f
    y0 = np.asarray(y0, dtype=float)
    y_end = reference_run(f, y0, t1)
    local = [np.linalg.norm(step(method, f, 0.0, y0, h) - reference_run(f, y0, h, 200))
             for h in dts]
    glob = [np.linalg.norm(integrate(f, y0, (0.0, t1), h, method).y[-1] - y_end) for h in dts]
    return np.array(local), np.array(glob)


def three_grid_order(run, dt: float):
    """Order ``p`` and error of the finest run, from three runs ``run(dt)``, ``run(dt/2)``,
    ``run(dt/4)`` and nothing else: with ``y_h ≈ y + C h^p``,
    ``|y_h - y_{h/2}| / |y_{h/2} - y_{h/4}| ≈ 2^p``, and the finest run is off by about
    ``|y_{h/2} - y_{h/4}| / (2^p - 1)``. Returns ``(p, error)``."""
    coarse, middle, fine = (np.asarray(run(h), dtype=float) for h in (dt, dt / 2, dt / 4))
    d1, d2 = np.linalg.norm(coarse - middle), np.linalg.norm(middle - fine)
    p = float(np.log2(d1 / d2))
    return p, float(d2 / (2.0**p - 1.0))


# --- notebook 05: the energy-band explorer's pure function --------------------------------

#: The explorer's methods, in the order drawn.
BAND_METHODS = ("forward_euler", "symplectic_euler", "velocity_verlet")


def theory_band(method: str, omega: float, dt: float) -> tuple[float, float]:
    """Band ``(lo, hi)`` of ``E/E0`` for an oscillator released at rest (``ω dt < 2``):
    symplectic Euler ``1/(1 ± ω dt/2)`` (its modified energy is conserved), velocity Verlet
    ``[1 - ω² dt²/4, 1]``; forward Euler has no band (``(lo, hi) = (1, inf)``)."""
    h = omega * dt
    if method == "symplectic_euler":
        return 1.0 / (1.0 + 0.5 * h), (1.0 / (1.0 - 0.5 * h) if h < 2 else np.inf)
    if method == "velocity_verlet":
        return 1.0 - 0.25 * h * h, 1.0
    return 1.0, np.inf


@dataclass
class EnergyBands:
    """Result of :func:`energy_bands`: each method's energy on ``x'' = -ω² x`` at one step."""

    dt: float                 #: the step (s)
    omega: float              #: angular frequency (rad/s)
    t: np.ndarray             #: times (s), shape (n+1,)
    ratio: dict               #: method -> E/E0 at every step (NaN past 1e12)
    band: dict                #: method -> theory band (lo, hi) of E/E0
    spread: dict              #: method -> (min, max) of E/E0 over the run
    stable: bool              #: symplectic Euler and Verlet bounded (ω dt < 2)
    verdict: str


def energy_bands(dt: float = 0.1, omega: float = 1.0, periods: float = 20.0) -> EnergyBands:
    """Energy ``E/E0`` of the oscillator ``x'' = -ω² x`` released at rest from ``x = 1``,
    by forward Euler, symplectic Euler and velocity Verlet, over ``periods`` periods.

    Each method's step on this linear problem is a 2×2 matrix built from course_lib's own
    steppers (:func:`~course_lib.lessons.nb07_spring_runs.step_matrix`); the run is its
    powers, computed all at once (a few milliseconds whatever the number of steps), the
    numbers of :func:`~course_lib.integrators.integrate` to round-off. Pure.
    """
    from .nb07_spring_runs import matrix_powers, step_matrix

    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
    n = max(1, round(periods * 2.0 * np.pi / (omega * dt)))
    t = dt * np.arange(n + 1)
    ratio, band, spread = {}, {}, {}
    with np.errstate(over="ignore", invalid="ignore"):
        for method in BAND_METHODS:
            S = step_matrix(method, omega**2, 1.0, 0.0, dt)
            x, v = (matrix_powers(S, n) @ np.array([1.0, 0.0])).T
            e = (0.5 * v**2 + 0.5 * omega**2 * x**2) / (0.5 * omega**2)
            past = np.flatnonzero(~(e <= 1e12))
            if past.size:
                e[past[0]:] = np.nan
            ratio[method] = e
            band[method] = theory_band(method, omega, dt)
            spread[method] = (float(np.nanmin(e)), float(np.nanmax(e)))
    stable = omega * dt < 2.0 and np.all(np.isfinite(ratio["symplectic_euler"]))
    grow = ratio["forward_euler"][-1]
    fe = (f"forward Euler × {grow:.2g}" if np.isfinite(grow) else "forward Euler past 1e12")
    if stable:
        (lo, hi), vlo = band["symplectic_euler"], band["velocity_verlet"][0]
        verdict = (f"stable: symplectic Euler's E/E0 in [{lo:.3g}, {hi:.3g}], Verlet's up to "
                   f"{(1 - vlo) * 100:.2g} % below 1; {fe} in {periods:g} periods")
    elif abs(omega * dt - 2.0) <= 1e-12:
        # a Jordan block (double eigenvalue -1): growth is linear, and x = 1, v = 0 is
        # Verlet's eigenvector there, so its run only flips sign
        verdict = ("marginal: ω dt = 2, symplectic Euler grows linearly; Verlet only flips "
                   f"sign from this start (x = 1, v = 0) but grows from any other; {fe}")
    else:
        verdict = f"unstable: ω dt > 2, symplectic Euler and Verlet grow; {fe}"
    return EnergyBands(dt, omega, t, ratio, band, spread, bool(stable), verdict)
