"""Notebook 07 (springs): a mass on a damped spring, its runner, drawing and widget.

Holds the pure computation behind the notebook's widget (:func:`run_spring`), its drawing
(:func:`draw_spring_run`), the view (:func:`spring_explorer`), and the measured step limit
(:func:`spring_dt_max`). Built on the core (:mod:`course_lib.springs`,
:mod:`course_lib.integrators`); imports view helpers (:mod:`course_lib.plotting`,
:mod:`course_lib.widgets`). The core never imports this module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..springs import anchored_spring, damped_oscillator
from ..stability import bisect_stable_dt


def spring_dt_max(k: float, m: float = 1.0, method: str = "symplectic_euler",
                  n_steps: int = 1000, rtol: float = 1e-4) -> float:
    """Largest stable step (s) for a mass on a spring, measured: bisection on the verdict
    of :func:`~course_lib.integrators.integrate` over ``n_steps`` steps.

    The spring (rest length 1 m) starts stretched by 1 nm; a run whose state grows past
    1.5 (m or m/s), i.e. a stretch of 0.5 m or a speed of 1.5 m/s, is declared unstable.
    That is a growth by more than 10⁸, caught while the motion is still linear (the mass
    never reaches the anchor).
    """
    from ..integrators import integrate

    system, y0, _ = anchored_spring(k, m, stretch=1e-9)
    scale = np.sqrt(m / k)

    def stable(dt):
        return integrate(system, y0, (0.0, n_steps * dt), dt, method=method,
                         blowup_bound=1.5).stable

    return bisect_stable_dt(stable, 0.5 * scale, 3.0 * scale, rtol)


# --- a mass on a spring: the pure computation behind the notebook 07 widget --------------


@dataclass
class SpringRun:
    """Result of :func:`run_spring`: one mass on a damped spring, numerical and exact."""

    t: np.ndarray
    x: np.ndarray          # stretch (m); NaN after a blow-up
    exact: np.ndarray      # exact stretch (m)
    energy: np.ndarray     # kinetic + elastic energy (J)
    exact_energy: np.ndarray
    stable: bool
    message: str
    dt_limit: float        # undamped stability limit of the method (s)
    params: dict
    t_fine: np.ndarray     # a fine time grid for drawing the exact solution
    exact_fine: np.ndarray


def run_spring(k: float = 10.0, c: float = 0.0, dt: float = 0.05,
               method: str = "symplectic_euler", m: float = 1.0, t_end: float = 20.0,
               stretch: float = 0.1) -> SpringRun:
    """Integrate a mass ``m`` on a spring ``k`` with damping ``c`` along it (3D, anchored),
    and return its stretch and energy beside the exact solution and the verdict."""
    from ..integrators import integrate
    from ..stability import max_stable_dt
    from ..systems import split_state

    system, y0, net = anchored_spring(k, m, c, 1.0, stretch)
    traj = integrate(system, y0, (0.0, t_end), dt, method=method, blowup_bound=1e3)
    x, v = split_state(traj.y)
    s = net.lengths(x)[:, 0] - 1.0
    energy = 0.5 * m * np.sum(v[:, 1] ** 2, axis=-1) + 0.5 * k * s**2
    exact = damped_oscillator(traj.t, k, m, c, stretch)
    omega = np.sqrt(k / m)
    exact_v = damped_oscillator(traj.t, k, m, c, stretch, velocity=True)
    exact_energy = 0.5 * m * exact_v**2 + 0.5 * k * exact**2
    t_fine = np.linspace(0.0, traj.t[-1], 2001)
    return SpringRun(traj.t, s, exact, energy, exact_energy, traj.stable, traj.message,
                     max_stable_dt(method, 1j * omega), dict(k=k, c=c, dt=dt, method=method, m=m),
                     t_fine, damped_oscillator(t_fine, k, m, c, stretch))


def draw_spring_run(run: SpringRun):
    """Stretch and energy of a :class:`SpringRun` beside the exact answer (a Figure)."""
    import matplotlib.pyplot as plt

    from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS

    p = run.params
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4))
    color = METHOD_COLORS[p["method"]]
    a = float(np.abs(run.exact[0]))
    ax1.plot(run.t_fine, run.exact_fine, **EXACT_STYLE, label="exact")
    ax1.plot(run.t, run.x, ".-", ms=3, color=color, label=METHOD_LABELS[p["method"]])
    ax1.set_ylim(-4 * a, 4 * a)
    ax1.set(xlabel="t (s)", ylabel="stretch (m)")
    ax1.legend(loc="upper right", fontsize=8, frameon=True, framealpha=0.9)
    ax2.semilogy(run.t, np.maximum(run.exact_energy, 1e-12), **EXACT_STYLE, label="exact")
    ax2.semilogy(run.t, run.energy, color=color, label=METHOD_LABELS[p["method"]])
    ax2.set_ylim(1e-6 * run.exact_energy[0], 1e3 * run.exact_energy[0])
    ax2.set(xlabel="t (s)", ylabel="energy (J)")
    ax2.legend(loc="lower left", fontsize=8, frameon=True, framealpha=0.9)
    verdict = "stable" if run.stable else "BLOWN UP: " + run.message
    fig.suptitle(f"k = {p['k']:.3g} N/m, c = {p['c']:.3g} N s/m, dt = {p['dt']:.3g} s "
                 f"(limit {run.dt_limit:.3g} s): {verdict}", fontsize=10)
    fig.tight_layout()
    return fig


def spring_explorer(k: float = 10.0, c: float = 0.0, dt: float = 0.05,
                    method: str = "symplectic_euler"):
    """An :class:`~course_lib.widgets.ExplorerView` over :func:`run_spring`:
    sliders for ``k``, ``c``, ``dt`` and a method menu."""
    import ipywidgets as w

    from ..integrators import METHODS
    from ..widgets import ExplorerView, log_slider

    controls = {
        "k": log_slider("k (N/m)", k, 1.0, 1e3),
        "c": w.FloatSlider(value=c, min=0.0, max=20.0, step=0.1, description="c (N s/m)",
                           continuous_update=False),
        "dt": log_slider("dt (s)", dt, 1e-3, 1.0),
        "method": w.Dropdown(options=list(METHODS), value=method, description="method"),
    }
    return ExplorerView(run_spring, draw_spring_run, controls)


def settling_time(t, x, tol: float = 0.01) -> float:
    """First time (s) after which ``|x|`` stays below ``tol · |x[0]|`` for good."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    outside = np.nonzero(np.abs(x) > tol * abs(x[0]))[0]
    if outside.size == 0:
        return float(t[0])
    if outside[-1] + 1 >= t.size:
        return float("inf")
    return float(t[outside[-1] + 1])
