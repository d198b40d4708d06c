"""Notebook 06 (forces): orbits, a cluster, drag, a bouncing ball, a charge, a steered swarm.

Pure scenes built on the core (:mod:`course_lib.forces`, :mod:`course_lib.collisions`,
:mod:`course_lib.integrators`), plus the steering widget's drawing and view (imports
:mod:`course_lib.widgets`). The core never imports this module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import collisions, forces
from ..events import crossing_ballistic
from ..integrators import Trajectory, integrate
from ..systems import newtonian, stack_state, sum_forces
from .nb05_newton import G_STD

# --- notebook 06: drag --------------------------------------------------------------------


def linear_drag_exact(t, x0, v0, m: float, b: float, g=(0.0, -G_STD), wind=(0.0, 0.0)):
    """Exact motion of a mass ``m`` under gravity ``g`` and linear drag ``-b (v - wind)``.

    The velocity relaxes to ``v_inf = wind + m g / b`` with time constant ``τ = m / b``:
    ``v(t) = v_inf + (v0 - v_inf) e^{-t/τ}`` and
    ``x(t) = x0 + v_inf t + (v0 - v_inf) τ (1 - e^{-t/τ})``. Returns ``(x, v)``, each of
    shape ``(len(t), d)``.
    """
    t = np.asarray(t, dtype=float)[:, None]
    x0, v0 = np.asarray(x0, dtype=float), np.asarray(v0, dtype=float)
    tau = m / b
    v_inf = np.asarray(wind, dtype=float) + tau * np.asarray(g, dtype=float)
    decay = np.exp(-t / tau)
    return x0 + v_inf * t + (v0 - v_inf) * tau * (1 - decay), v_inf + (v0 - v_inf) * decay


def quadratic_drag_velocity(t, m: float, c: float, g: float = G_STD):
    """Exact velocity (m/s, negative: downwards) of a mass ``m`` dropped from rest under
    gravity with quadratic drag ``-c |v| v``: ``-v_T tanh(g t / v_T)``, ``v_T = √(m g / c)``."""
    v_t = np.sqrt(m * g / c)
    return -v_t * np.tanh(g * np.asarray(t, dtype=float) / v_t)


def pushed_puck(push: float, mu: float, m: float = 1.0, g: float = G_STD, dt: float = 1e-3,
                t_end: float = 1.0) -> Trajectory:
    """A puck at rest on the ground pushed sideways by a constant force ``push`` (N), with
    Coulomb friction ``mu`` handled by the post-step ground response
    (:func:`course_lib.collisions.plane`), stepped by symplectic Euler."""
    def shove(t, x, v):
        return np.broadcast_to([push, 0.0], x.shape).copy()

    puck = newtonian(sum_forces(forces.constant_gravity(m, g=[0.0, -g]), shove), m)
    ground = collisions.plane(normal=(0.0, 1.0), restitution=0.0, friction=mu)
    return integrate(puck, stack_state([[0.0, 0.0]], [[0.0, 0.0]]), (0.0, t_end), dt,
                     "symplectic_euler", post_step=ground)


# --- notebook 06: gravity -----------------------------------------------------------------


def two_body_circular(M: float = 1.0, m: float = 0.01, r: float = 1.0, G: float = 1.0):
    """Two bodies on circular orbits about their centre of mass (at rest at the origin).

    Returns ``(masses, y0, period)``, with ``y0`` of shape ``(2, 2, 2)`` and the Kepler
    period ``2π sqrt(r³ / (G (M + m)))`` of the separation ``r``.
    """
    total = M + m
    v_rel = np.sqrt(G * total / r)
    x = np.array([[-m / total * r, 0.0], [M / total * r, 0.0]])
    v = np.array([[0.0, -m / total * v_rel], [0.0, M / total * v_rel]])
    return np.array([M, m]), stack_state(x, v), 2 * np.pi * np.sqrt(r**3 / (G * total))


def cluster(n: int = 8, seed: int = 2026, radius: float = 1.0):
    """A small star cluster: ``n`` equal masses (total 1) in a disc, slowly rotating, with
    zero total momentum and the centre of mass at the origin. Returns ``(masses, y0)``."""
    rng = np.random.default_rng(seed)
    rho = radius * np.sqrt(rng.uniform(0.05, 1.0, n))
    phi = rng.uniform(0.0, 2 * np.pi, n)
    x = np.column_stack((rho * np.cos(phi), rho * np.sin(phi)))
    v = 0.4 * np.column_stack((-x[:, 1], x[:, 0])) + 0.1 * rng.normal(size=(n, 2))
    m = np.full(n, 1.0 / n)
    x -= m @ x / m.sum()
    v -= m @ v / m.sum()
    return m, stack_state(x, v)


def cluster_gravity(mass, G: float = 1.0, softening: float = 0.1):
    """``f(t, y)`` of many independent clusters at once: ``y`` of shape ``(2, S, N, d)``
    holds ``S`` clusters of the same ``N`` masses; each feels only its own softened
    gravity (the force of :func:`course_lib.forces.nbody_gravity_force`, cluster by
    cluster, by broadcasting). Needs ``softening > 0`` (the self-pair then adds zero)."""
    mass = np.asarray(mass, dtype=float)
    if not softening > 0:
        raise ValueError(f"softening must be > 0 for the batched force, got {softening!r}")

    def f(t, y):
        x, v = y[0], y[1]
        r = x[:, :, None, :] - x[:, None, :, :]                 # (S, N, N, d)
        d2 = np.einsum("sijd,sijd->sij", r, r) + softening**2
        pull = mass / (d2 * np.sqrt(d2))                          # m_j / (r² + ε²)^1.5
        return np.stack((v, -G * (pull[:, :, None, :] @ r)[:, :, 0, :]))   # sum over j

    return f


@dataclass
class ClusterEnsemble:
    """What :func:`cluster_ensemble` returns: errors against time, one column per cluster."""

    t: np.ndarray            #: times, shape (n+1,)
    seeds: list              #: the clusters' seeds
    energy_error: dict       #: method -> |E/E0 - 1|, shape (n+1, S)
    momentum_error: dict     #: method -> |L - L0|, shape (n+1, S)

    def worst(self, method: str) -> np.ndarray:
        """Largest energy error of each cluster over the run, shape (S,)."""
        return self.energy_error[method].max(axis=0)


def cluster_ensemble(seeds=range(2026, 2042), methods=("forward_euler", "symplectic_euler",
                     "velocity_verlet", "rk4"), n: int = 8, softening: float = 0.1,
                     t_end: float = 20.0, dt: float = 0.01) -> ClusterEnsemble:
    """Run the clusters of :func:`cluster` for every seed with each method, all clusters in
    one integration (:func:`cluster_gravity`), and record the energy and angular-momentum
    errors. A cluster's close encounters make its run chaotic (its last digits depend on
    the machine's rounding), so only what the ensemble does is worth quoting."""
    seeds = list(seeds)
    m = cluster(n, seed=seeds[0])[0]
    y0 = np.stack([cluster(n, seed=s)[1] for s in seeds], axis=1)     # (2, S, N, 2)
    f = cluster_gravity(m, 1.0, softening)
    energy, momentum = {}, {}
    iu = np.triu_indices(n, 1)
    for method in methods:
        y = integrate(f, y0, (0.0, t_end), dt, method).y
        x, v = y[:, 0], y[:, 1]                                      # (n+1, S, N, 2)
        r = x[..., iu[0], :] - x[..., iu[1], :]
        E = (0.5 * np.sum(m * np.sum(v * v, axis=-1), axis=-1)
             - np.sum(m[iu[0]] * m[iu[1]] / np.sqrt(np.sum(r * r, axis=-1) + softening**2), axis=-1))
        L = np.sum(m * (x[..., 0] * v[..., 1] - x[..., 1] * v[..., 0]), axis=-1)
        energy[method], momentum[method] = np.abs(E / E[0] - 1.0), np.abs(L - L[0])
    return ClusterEnsemble(dt * np.arange(y.shape[0]), seeds, energy, momentum)


# --- notebook 06: contact -----------------------------------------------------------------


def bouncing_ball(h0: float = 1.0, restitution: float = 0.8, g: float = G_STD,
                  dt: float = 0.01, t_end: float = 3.0, locate: bool = True):
    """A ball dropped from ``h0`` onto the ground ``y = 0``; returns ``(t, h, v)``.

    ``locate=False`` is the usual post-step response (:func:`course_lib.collisions.plane`
    after each velocity Verlet step): the ball is found below the ground at the end of a
    step, moved back to the surface and its velocity reflected and scaled by ``e``.
    ``locate=True`` finds the instant of impact inside the step by solving the step's own
    quadratic (:func:`course_lib.events.crossing_ballistic`), bounces there and finishes
    the step from the impact, which under constant gravity is exact (velocity Verlet's
    step is the exact parabola). A ball whose rebound would last less than ``1e-9`` s
    is put to rest on the ground.
    """
    if not locate:
        system = newtonian(forces.constant_gravity(1.0, g=[0.0, -g]), mass=1.0)
        ground = collisions.plane(normal=(0.0, 1.0), restitution=restitution)
        y0 = stack_state([[0.0, h0]], [[0.0, 0.0]])
        traj = integrate(system, y0, (0.0, t_end), dt, "velocity_verlet", post_step=ground)
        return traj.t, traj.y[:, 0, 0, 1], traj.y[:, 1, 0, 1]
    n = round(t_end / dt)
    t = dt * np.arange(n + 1)
    h = np.empty(n + 1)
    v = np.empty(n + 1)
    h[0], v[0] = h0, 0.0
    hk, vk = h0, 0.0
    for k in range(n):
        left = dt
        while left > 0.0:
            if hk + vk * left - 0.5 * g * left**2 >= 0:
                s = np.nan
            elif hk == 0.0:                    # just bounced: back down after 2 v / g
                s = 2.0 * vk / g
            else:
                s = crossing_ballistic(hk, vk, -g)
            if not np.isfinite(s) or s > left:
                hk, vk = hk + vk * left - 0.5 * g * left**2, vk - g * left
                break
            vk = -restitution * (vk - g * s)
            hk = 0.0
            left -= s
            if 2 * vk / g < 1e-9:              # resting contact: stop bouncing
                hk, vk, left = 0.0, 0.0, 0.0
        h[k + 1], v[k + 1] = hk, vk
    return t, h, v


def located_bounce_step(h, v, dt: float, g: float = G_STD, restitution: float = 0.8):
    """One step ``dt`` of balls at heights ``h`` (m, all ``>= 0``) with vertical velocities
    ``v`` (m/s, arrays of one shape) under gravity ``g`` above the ground ``h = 0``, the
    impact located inside the step: the exercise of notebook 06. Returns ``(h, v)``.

    A ball that would end the step below ground hits it at the positive root ``s`` of the
    step's own quadratic ``h + v s - g s²/2 = 0``, leaves with ``-e (v - g s)`` and flies the
    rest of the step, ``dt - s``. At most one impact per step (the caller's step is short
    enough); a ball resting on the ground (``h = v = 0``) has no impact to locate.
    """
    h, v = np.asarray(h, dtype=float), np.asarray(v, dtype=float)
    free_h, free_v = h + v * dt - 0.5 * g * dt**2, v - g * dt
    hit = free_h < 0.0
    disc = np.sqrt(np.maximum(v * v + 2.0 * g * h, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        # the positive root, written without cancellation on either sign of v
        s = np.where(v > 0.0, (v + disc) / g, 2.0 * h / (disc - v))
    s = np.where(hit, s, dt)
    up = -restitution * (v - g * s)
    rest = dt - s
    return (np.where(hit, up * rest - 0.5 * g * rest**2, free_h),
            np.where(hit, up - g * rest, free_v))


def charged_particle(q: float = 1.0, m: float = 1.0, B=(0.0, 0.0, 2.0), v0=(1.0, 0.0, 0.3),
                     dt: float = 0.01, t_end: float = 10.0, method: str = "rk4") -> Trajectory:
    """A charge released at the origin with velocity ``v0`` in a uniform magnetic field."""
    system = newtonian(forces.magnetic(q, B), mass=m)
    y0 = stack_state([[0.0, 0.0, 0.0]], [list(v0)])
    return integrate(system, y0, (0.0, t_end), dt, method)


# --- notebook 06: user control (the widget's pure half) -----------------------------------


@dataclass
class SteeringResult:
    """What :func:`steer_swarm` returns."""

    t: np.ndarray            #: times (s), shape (n+1,)
    x: np.ndarray            #: positions (m), shape (n+1, N, 2)
    center: np.ndarray       #: the attractor (m), shape (2,)
    wind: np.ndarray         #: the wind (m/s), shape (2,)
    centroid: np.ndarray     #: final mean position (m), shape (2,)
    spread: float            #: final RMS distance to the centroid (m)


def steer_swarm(cx: float = 0.0, cy: float = 0.0, strength: float = 1.0, wind: float = 0.0,
                n: int = 40, t_end: float = 4.0, dt: float = 0.02, drag_b: float = 1.0,
                seed: int = 2026) -> SteeringResult:
    """Particles (1 kg each) pulled by a user-placed attractor and pushed by a wind.

    The net force is ``attractor((cx, cy), strength) + drag(b, wind=(wind, 0))``; the
    particles start at rest, scattered (seeded) over ``[-1, 1]²``, and are advanced by
    symplectic Euler. Pure: same arguments, same result.
    """
    rng = np.random.default_rng(seed)
    x0 = rng.uniform(-1.0, 1.0, size=(n, 2))
    w = np.array([float(wind), 0.0])
    center = np.array([float(cx), float(cy)])
    net = sum_forces(forces.attractor(center, float(strength), softening=0.3),
                     forces.drag(b=drag_b, wind=w))
    traj = integrate(newtonian(net, mass=np.ones(n)), stack_state(x0, np.zeros_like(x0)),
                     (0.0, t_end), dt, "symplectic_euler")
    x = traj.y[:, 0]
    centroid = x[-1].mean(axis=0)
    spread = float(np.sqrt(np.mean(np.sum((x[-1] - centroid) ** 2, axis=1))))
    return SteeringResult(traj.t, x, center, w, centroid, spread)


#: Half the width of the swarm's panel (m); particles beyond it are marked at its edge.
_EDGE = 2.5


def draw_swarm(result: SteeringResult, ax=None):
    """Draw the particle paths, their final positions, the attractor and the wind."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(4.5, 4.5))
    else:
        fig = ax.figure
    ax.plot(result.x[:, :, 0], result.x[:, :, 1], color="0.6", linewidth=0.6)
    ax.plot(result.x[0, :, 0], result.x[0, :, 1], "o", color="0.6", markersize=3,
            label="start")
    end = result.x[-1]
    away = np.any(np.abs(end) > _EDGE, axis=1)         # blown past the panel's edge
    ax.plot(end[~away, 0], end[~away, 1], "o", color="#1f77b4", markersize=4, label="end")
    if away.any():   # marked where they left the panel, pointing the way they went
        edge = np.clip(end[away], -_EDGE, _EDGE)
        ax.plot(edge[:, 0], edge[:, 1], "<" if result.wind[0] < 0 else ">", color="#1f77b4",
                markersize=6, fillstyle="none", label=f"end off the panel ({away.sum()})")
    ax.plot(*result.center, "*", color="#d62728", markersize=14, label="attractor")
    if result.wind[0] != 0:
        half = 0.2 * result.wind[0]
        ax.annotate("", xy=(-1.6 + half, 2.1), xytext=(-1.6 - half, 2.1),
                    arrowprops={"arrowstyle": "->", "color": "#2ca02c", "linewidth": 2})
        ax.text(-1.6, 2.25, f"wind {result.wind[0]:g} m/s", color="#2ca02c", fontsize=9,
                ha="center")
    ax.set(xlim=(-_EDGE - 0.1, _EDGE + 0.1), ylim=(-_EDGE - 0.1, _EDGE + 0.1), xlabel="x (m)",
           ylabel="y (m)", aspect="equal")
    ax.legend(loc="lower right", fontsize=8)
    return fig


def steering_view(**initial):
    """The widget: sliders for the attractor's position and strength and the wind."""
    import ipywidgets as w

    from ..widgets import log_slider
    from .busy_view import BusyExplorerView

    p = {"cx": 0.0, "cy": 0.0, "strength": 1.0, "wind": 0.0, **initial}
    style = {"description_width": "initial"}
    controls = {
        "cx": w.FloatSlider(value=p["cx"], min=-2, max=2, step=0.1, description="attractor x (m)",
                            continuous_update=False, style=style),
        "cy": w.FloatSlider(value=p["cy"], min=-2, max=2, step=0.1, description="attractor y (m)",
                            continuous_update=False, style=style),
        "strength": log_slider("strength (N m²)", p["strength"], 0.1, 10.0),
        "wind": w.FloatSlider(value=p["wind"], min=-3, max=3, step=0.1, description="wind (m/s)",
                              continuous_update=False, style=style),
    }
    return BusyExplorerView(steer_swarm, draw_swarm, controls)
