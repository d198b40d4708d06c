"""Hair strands as chains of masses and springs: the strand model.

A strand is a :func:`~course_lib.springs.hair_chain` (edge springs ``(i, i+1)``, bending
springs ``(i, i+2)``, torsion springs ``(i, i+3)``, after Selle, Lentine & Fedkiw 2008)
with its root particle(s) pinned. An animation shows one picture per *frame* (1/30 s)
but an explicit integrator must take steps shorter than ``2 / ω_max`` of the stiff edge
springs, so each frame is split into ``substeps`` steps. A "hairstyle" puts several
strands in one :class:`~course_lib.springs.SpringNetwork`, so one vectorized force call
moves them all, and a sphere collision keeps them outside the head.

Core module: imports only other core modules (no plotting, widgets or lessons).
Notebook 08's scenes and widget live in :mod:`course_lib.lessons.nb08_hair_chains`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .collisions import sphere
from .forces import G_EARTH, constant_gravity, viscous_damping
from .integrators import integrate
from .springs import SpringNetwork, hair_chain, max_frequency
from .stability import bisect_stable_dt
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
