"""Hair strands as chains of masses and springs: simulation helpers for notebook 08.

A strand is a :func:`~course_lib.springs.hair_chain` (edge springs ``(i, i+1)``, bending
springs ``(i, i+2)``, torsion springs ``(i, i+3)``, after Selle, Lentine & Fedkiw 2008)
with its root particle(s) pinned. An animation shows one picture per *frame* (1/30 s)
but an explicit integrator must take steps shorter than ``2 / ω_max`` of the stiff edge
springs, so each frame is split into ``substeps`` steps. A "hairstyle" puts several
strands in one :class:`~course_lib.springs.SpringNetwork`, so one vectorized force call
moves them all, and a sphere collision keeps them outside the head.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .collisions import sphere
from .forces import G_EARTH, constant_gravity, viscous_damping
from .integrators import integrate
from .springs import SpringNetwork, bisect_stable_dt, hair_chain, max_frequency
from .systems import NewtonianSystem, split_state, stack_state, sum_forces

#: The strand used throughout notebook 08: 16 particles of 0.1 g over 30 cm, stiff edges.
STRAND = {"n": 16, "length": 0.3, "k_edge": 2000.0}
#: Mass of one particle (kg).
MASS = 1e-4
#: Frames per second of the animations.
FPS = 30.0


@dataclass
class HairRun:
    """Result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray, shape (F+1,)
        Frame times (s).
    frames : ndarray, shape (F+1, N, 3)
        Positions at each frame (m); NaN after a blow-up.
    x : ndarray, shape (n+1, N, 3)
        Positions at every substep (m).
    dt : float
        Substep (s).
    stable : bool
    message : str
    """

    t: np.ndarray
    frames: np.ndarray
    x: np.ndarray
    dt: float
    stable: bool
    message: str


def strand_system(network: SpringNetwork, mass=MASS, pinned=(0,), damping: float = 0.0,
                  gravity=G_EARTH) -> NewtonianSystem:
    """Springs + gravity + viscous damping ``-c v`` on particles of mass ``mass``."""
    forces = [network.force]
    if gravity is not None:
        forces.append(constant_gravity(mass, gravity))
    if damping:
        forces.append(viscous_damping(damping))
    return NewtonianSystem(sum_forces(*forces), mass, pinned=list(pinned))


def simulate(x0, network: SpringNetwork, *, frames: int, substeps: int, fps: float = FPS,
             mass=MASS, pinned=(0,), damping: float = 0.0, gravity=G_EARTH, v0=None,
             method: str = "symplectic_euler", post_step=None, blowup_bound: float = 100.0
             ) -> HairRun:
    """Run a strand (or hairstyle) for ``frames`` frames of ``substeps`` steps each.

    The step is ``dt = 1 / (fps * substeps)``. ``blowup_bound`` (m or m/s) is far beyond
    anything a 30 cm strand does, so passing it means the run exploded.
    """
    x0 = np.asarray(x0, dtype=float)
    system = strand_system(network, mass, pinned, damping, gravity)
    y0 = stack_state(x0, np.zeros_like(x0) if v0 is None else v0)
    dt = 1.0 / (fps * substeps)
    traj = integrate(system, y0, (0.0, frames / fps), dt, method=method, post_step=post_step,
                     blowup_bound=blowup_bound)
    x, _ = split_state(traj.y)
    return HairRun(traj.t[::substeps], x[::substeps], x, dt, traj.stable, traj.message)


def max_strain(run: HairRun, network: SpringNetwork, kind: str = "edge") -> float:
    """Largest ``|ℓ/L - 1|`` of the springs of one kind over every substep of a run."""
    sub = network.select(kind)
    return float(np.max(np.abs(sub.strain(run.x))))


def stiffest_edge(substeps: int, fps: float = FPS, mass=MASS, safety: float = 0.5) -> float:
    """Edge stiffness (N/m) a budget of ``substeps`` per frame affords: the step
    ``dt = 1/(fps substeps)`` must stay below about ``√(m/k)``, so ``k = safety · m / dt²``."""
    return float(safety * mass * (fps * substeps) ** 2)


def max_strain_vs_substeps(substeps, frames: int = 12, **strand) -> list[float]:
    """Inextensibility error against the substep budget: for each number of substeps per
    frame, the strand (released horizontally, root pinned) gets the stiffest edges that
    budget affords (:func:`stiffest_edge`); returns the max edge strain over ``frames``."""
    out = []
    for s in substeps:
        x0, net = hair_chain(**{**STRAND, **strand, "k_edge": stiffest_edge(s)})
        out.append(max_strain(simulate(x0, net, frames=frames, substeps=s), net))
    return out


def chain_dt_max(network: SpringNetwork, x0, mass=MASS, pinned=(0,), n_steps: int = 1000,
                 amplitude: float = 1e-8, seed: int = 2026, rtol: float = 1e-4) -> float:
    """Largest stable symplectic Euler step (s) of a strand, measured by bisection.

    The strand starts at rest at ``x0`` (no gravity) with every free particle nudged by a
    seeded random ``amplitude`` (m); a run is unstable when within ``n_steps`` steps its
    state passes 1 (m or m/s): for the fast modes that is a speed of 1 m/s, reached while
    the vibration is still far smaller than a segment (linear). The bisection brackets
    ``[0.6, 1.6] × 2 / ω_max``.
    """
    rng = np.random.default_rng(seed)
    x0 = np.asarray(x0, dtype=float)
    nudge = amplitude * rng.standard_normal(x0.shape)
    nudge[list(pinned)] = 0.0
    system = strand_system(network, mass, pinned, gravity=None)
    y0 = stack_state(x0 + nudge, np.zeros_like(x0))
    guess = 2.0 / max_frequency(network, x0, mass, pinned)

    def stable(dt):
        return integrate(system, y0, (0.0, n_steps * dt), dt, method="symplectic_euler",
                         blowup_bound=1.0).stable

    return bisect_stable_dt(stable, 0.6 * guess, 1.6 * guess, rtol)


def static_shape(x0, network: SpringNetwork, mass=MASS, pinned=(0, 1), gravity=G_EARTH):
    """Equilibrium positions under gravity: the minimum of elastic + gravitational energy
    reached from ``x0`` (L-BFGS with the exact gradient, the negative net force)."""
    from scipy.optimize import minimize

    x0 = np.asarray(x0, dtype=float)
    n = x0.shape[0]
    m = np.broadcast_to(np.asarray(mass, dtype=float), (n,))[:, None]
    g = np.asarray(gravity, dtype=float)
    free = np.setdiff1d(np.arange(n), np.asarray(pinned, dtype=int))

    def energy_and_gradient(z):
        x = x0.copy()
        x[free] = z.reshape(-1, 3)
        e = network.energy(x) - np.sum(m * (x @ g)[:, None])
        return e, -(network.forces(x) + m * g)[free].ravel()

    res = minimize(energy_and_gradient, x0[free].ravel(), jac=True, method="L-BFGS-B",
                   options={"gtol": 1e-12, "ftol": 1e-15, "maxiter": 20000})
    x = x0.copy()
    x[free] = res.x.reshape(-1, 3)
    return x


def held_strand(k_bend: float = 0.0, zigzag: float = 0.0, **strand):
    """A strand laid out horizontally along +x with a clamped root (particles 0 and 1
    pinned): ``(x0, network)``."""
    return hair_chain(**{**STRAND, "k_bend": k_bend, "zigzag": zigzag, **strand})


@functools.lru_cache(maxsize=64)
def _held_equilibrium(k_bend: float, zigzag: float) -> np.ndarray:
    x0, net = held_strand(k_bend, zigzag)
    x = static_shape(x0, net)
    x.setflags(write=False)
    return x


def tip_sag(k_bend: float = 0.0, zigzag: float = 0.0) -> float:
    """How far (m) the tip of the held-out :data:`STRAND` drops at equilibrium under
    gravity (root clamped: particles 0 and 1 pinned)."""
    x0, _ = held_strand(k_bend, zigzag)
    return float(x0[-1, 1] - _held_equilibrium(float(k_bend), float(zigzag))[-1, 1])


# --- the notebook 08 widget ---------------------------------------------------------------


@dataclass
class HeldStrandRun:
    """Result of :func:`run_held_strand`."""

    t: np.ndarray
    frames: np.ndarray
    tip_y: np.ndarray
    equilibrium: np.ndarray
    stable: bool
    message: str
    dt_limit: float
    params: dict


def run_held_strand(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4,
                    zigzag: float = 0.3, t_end: float = 0.5, n_frames: int = 6) -> HeldStrandRun:
    """Release a held-out strand (clamped root) under gravity with symplectic Euler.

    Returns the strand at ``n_frames`` times, the tip height at every step, the static
    equilibrium it should settle to, the verdict, and the step limit ``2 / ω_max``.
    """
    x0, net = held_strand(k_bend, zigzag)
    equilibrium = _held_equilibrium(float(k_bend), float(zigzag))
    system = strand_system(net, MASS, (0, 1), damping)
    traj = integrate(system, stack_state(x0, np.zeros_like(x0)), (0.0, t_end), dt,
                     method="symplectic_euler", blowup_bound=100.0)
    x, _ = split_state(traj.y)
    pick = np.linspace(0, len(traj.t) - 1, n_frames).round().astype(int)
    return HeldStrandRun(traj.t[pick], x[pick], x[:, -1, 1], equilibrium,
                         traj.stable, traj.message, 2.0 / max_frequency(net, x0, MASS, (0, 1)),
                         {"k_bend": k_bend, "damping": damping, "dt": dt, "t": traj.t,
                          "t_end": t_end})


def draw_held_strand(run: HeldStrandRun):
    """Strand snapshots (side view) and tip height against time, with the equilibrium."""
    import matplotlib.pyplot as plt

    from .plotting import EXACT_STYLE

    p = run.params
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4))
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(run.t)))
    for tk, xk, col in zip(run.t, run.frames, colors, strict=True):
        ax1.plot(xk[:, 0], xk[:, 1], "o-", ms=2, color=col, label=f"t = {tk:.2f} s")
    ax1.plot(run.equilibrium[:, 0], run.equilibrium[:, 1], **EXACT_STYLE, label="equilibrium")
    ax1.set(xlim=(-0.05, 0.35), ylim=(-0.33, 0.07), xlabel="x (m)", ylabel="y (m)",
            aspect="equal")
    ax1.legend(fontsize=7, loc="lower left")
    ax2.plot(p["t"], run.tip_y, color="C0", label="tip, symplectic Euler")
    ax2.axhline(run.equilibrium[-1, 1], **EXACT_STYLE, label="equilibrium")
    ax2.set(xlim=(0.0, p["t_end"]), ylim=(-0.33, 0.07), xlabel="t (s)", ylabel="tip height y (m)")
    ax2.legend(fontsize=8, loc="upper right")
    verdict = "stable" if run.stable else "BLOWN UP: " + run.message
    fig.suptitle(f"k_bend = {p['k_bend']:.3g} N/m, damping = {p['damping']:.3g} kg/s, "
                 f"dt = {p['dt']:.3g} s (limit {run.dt_limit:.3g} s): {verdict}", fontsize=10)
    fig.tight_layout()
    return fig


def held_strand_explorer(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4):
    """An :class:`~course_lib.widgets.ExplorerView` over :func:`run_held_strand`."""
    import ipywidgets as w

    from .widgets import ExplorerView, log_slider

    controls = {
        "k_bend": log_slider("k_bend (N/m)", k_bend, 1.0, 1e4),
        "damping": w.FloatSlider(value=damping, min=0.0, max=1e-2, step=5e-4,
                                 description="damping (kg/s)", readout_format=".1e",
                                 continuous_update=False, style={"description_width": "initial"}),
        "dt": log_slider("dt (s)", dt, 2e-5, 1e-3),
    }
    return ExplorerView(run_held_strand, draw_held_strand, controls)


# --- several strands on a head ------------------------------------------------------------


def hairstyle(n_strands: int = 7, center=(0.0, 0.0, 0.0), radius: float = 0.1,
              seed: int = 2026, **strand):
    """Several strands rooted on the upper half of a spherical head, in ONE network.

    Roots are spread over the top of the sphere (seeded jitter); each strand starts
    straight along the outward normal at its root. Strand ``s`` owns particles
    ``s*n ... s*n + n - 1``; its root ``s*n`` is pinned.

    Returns
    -------
    x0 : ndarray, shape (n_strands * n, 3)
    network : SpringNetwork
    roots : ndarray of int, shape (n_strands,)
    """
    params = {**STRAND, **strand}
    n = params["n"]
    rng = np.random.default_rng(seed)
    # Roots: a ring of strands around the crown, tilted from the vertical by `polar`.
    azimuth = np.linspace(0.0, 2 * np.pi, n_strands, endpoint=False) + 0.2 * rng.uniform(-1, 1, n_strands)
    polar = np.deg2rad(45.0 + 15.0 * rng.uniform(-1, 1, n_strands))
    normal = np.stack((np.sin(polar) * np.cos(azimuth), np.cos(polar),
                       np.sin(polar) * np.sin(azimuth)), axis=1)
    c = np.asarray(center, dtype=float)
    _, net_one = hair_chain(**params)      # one straight strand's springs
    s = np.arange(n)[None, :, None] * (params["length"] / (n - 1))
    x0 = (c + radius * normal)[:, None, :] + s * normal[:, None, :]
    offsets = (np.arange(n_strands) * n)[:, None]
    m = net_one.n_springs
    net = SpringNetwork((offsets + net_one.i).ravel(), (offsets + net_one.j).ravel(),
                        np.tile(net_one.rest, n_strands), np.tile(net_one.k, n_strands),
                        np.tile(net_one.c, n_strands), n_strands * n,
                        np.tile(net_one.kind, n_strands))
    assert net.n_springs == m * n_strands
    return x0.reshape(-1, 3), net, offsets.ravel()


def head_collision(center=(0.0, 0.0, 0.0), radius: float = 0.1, pinned=()):
    """Post-step response for the head: :func:`course_lib.collisions.sphere` with no
    bounce (particles inside are projected out and lose their inward velocity).

    ``pinned`` particles (the roots, which sit on the scalp) are left exactly where they
    are, so round-off in the projection cannot nudge them."""
    collide = sphere(center, radius, restitution=0.0, friction=0.0)
    keep = np.asarray(pinned, dtype=int)

    def post_step(t, y):
        out = collide(t, y)
        if keep.size and out is not y:
            out[:, keep] = y[:, keep]
        return out

    return post_step


def animate(frames, network: SpringNetwork, *, head=None, size: float = 4.0,
            xlim=(-0.35, 0.35), ylim=(-0.45, 0.42), fps: float = FPS, title: str = ""):
    """A ``FuncAnimation`` of strands seen from the front (x-y), one line per strand
    (springs of kind ``"edge"``), with an optional head ``(center, radius)``."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    edges = network.select("edge")
    fig, ax = plt.subplots(figsize=(size, size))
    if head is not None:
        ax.add_patch(plt.Circle(head[0][:2], head[1], color="0.85", zorder=0))
    # NaN between consecutive edges of different strands breaks the line per strand.
    seg = np.stack((edges.i, edges.j), axis=1)

    def coords(x):
        pts = np.concatenate((x[seg], np.full((seg.shape[0], 1, 3), np.nan)), axis=1)
        return pts.reshape(-1, 3)

    p0 = coords(frames[0])
    (line,) = ax.plot(p0[:, 0], p0[:, 1], "-", color="saddlebrown", lw=1.5)
    stamp = ax.text(0.97, 0.03, "", transform=ax.transAxes, fontsize=9, ha="right")
    ax.set(xlim=xlim, ylim=ylim, aspect="equal", xlabel="x (m)", ylabel="y (m)", title=title)
    fig.tight_layout()

    def update(k):
        p = coords(frames[k])
        line.set_data(p[:, 0], p[:, 1])
        stamp.set_text(f"t = {k / fps:.2f} s")
        return line, stamp

    return FuncAnimation(fig, update, frames=len(frames), interval=1000.0 / fps, blit=True)
