"""Hair strands as chains of masses and springs: the strand model.

A strand is a row of particles joined by edge, bending and torsion springs
(:func:`~course_lib.springs.hair_chain`, :func:`~course_lib.strands.strand_network`, after
Selle, Lentine & Fedkiw 2008) with its root particle(s) pinned. An animation shows one
picture per *frame* (1/30 s), but an explicit integrator must take steps shorter than
``2 / ω_max`` of the stiff edge springs, so each frame is split into ``substeps`` steps.

- :func:`simulate` runs a strand (or a whole hairstyle: several strands in one
  :class:`~course_lib.springs.SpringNetwork`) with symplectic Euler, written out as one
  short loop of whole-array operations (:func:`symplectic_euler_run`): the same numbers as
  :func:`~course_lib.integrators.integrate`, at a fraction of the cost per step;
- :func:`static_shape` finds the resting shape under gravity, a minimum checked with the
  stiffness matrix (:mod:`course_lib.statics`); :func:`chain_dt_max` measures the step limit;
- :func:`hairstyle` roots curly strands on a spherical head, :func:`head_collision` keeps
  them outside it.

Core module: imports NumPy, SciPy and other core modules only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from . import _validate
from .collisions import sphere
from .forces import G_EARTH, constant_gravity, viscous_damping
from .springs import SpringNetwork, max_frequency
from .stability import bisect_stable_dt
from .statics import equilibrium
from .strands import helix, strand_network
from .systems import NewtonianSystem, sum_forces

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


def _strand(network, mass, pinned, damping=0.0, gravity=None, x0=None, v0=None, dim=None):
    """The strand's arguments checked (a ValueError or TypeError names the bad one):
    ``(x0, v0, mass (N,), pinned, damping, gravity)``, ``x0`` and ``v0`` copied."""
    if not isinstance(network, SpringNetwork):
        raise TypeError(f"network must be a SpringNetwork, got {type(network).__name__}")
    n = network.n_particles
    x = None if x0 is None else _validate.positions("x0", x0, n)
    dim = dim if x is None else x.shape[1]
    v = None if v0 is None else _validate.positions("v0", v0, n, dim)
    g = None if gravity is None else _validate.real_array("gravity", gravity, (dim,))
    return (x, v, _validate.masses("mass", mass, n), _validate.indices("pinned", pinned, n),
            _validate.nonnegative("damping", damping), g)


def strand_system(network: SpringNetwork, mass=MASS, pinned=(0,), damping: float = 0.0,
                  gravity=G_EARTH) -> NewtonianSystem:
    """Springs + gravity + viscous damping ``-c v`` as a :class:`NewtonianSystem`, for
    :func:`~course_lib.integrators.integrate` (any method); :func:`symplectic_euler_run`
    is the same system stepped by symplectic Euler."""
    _strand(network, mass, pinned, damping, gravity)
    forces = [network.force]
    if gravity is not None:
        forces.append(constant_gravity(mass, gravity))
    if damping:
        forces.append(viscous_damping(damping))
    return NewtonianSystem(sum_forces(*forces), mass, pinned=list(pinned))


def symplectic_euler_run(x0, network: SpringNetwork, dt: float, n_steps: int, *, mass=MASS,
                         pinned=(0,), damping: float = 0.0, gravity=G_EARTH, v0=None,
                         post_step=None, blowup_bound: float = 100.0):
    """``n_steps`` steps of symplectic Euler on springs + gravity + viscous damping ``-c v``.

    Each step: spring forces (gather ``x_i - x_j`` for every spring, one force per spring,
    scatter onto particles), then ``v += dt F/m`` (zero for ``pinned`` particles), then
    ``x += dt v``, then ``post_step(t, (x, v))`` if given. The state is checked every 16
    steps: the run stops at the first step where a coordinate or velocity passes
    ``blowup_bound`` (or is not finite), as :func:`~course_lib.integrators.integrate` does.

    Returns
    -------
    x : ndarray, shape (n_steps+1, N, 3)
        Positions at every step (NaN after a blow-up).
    message : str
        ``"ok"`` or ``"unstable at step k, t = … (|y| > bound)"``.
    """
    x, v, m, pinned, damping, gravity = _strand(network, mass, pinned, damping, gravity, x0, v0)
    dt = _validate.positive_finite("dt", dt)
    n_steps = _validate.positive_int("n_steps", n_steps)
    blowup_bound = _validate.positive_finite("blowup_bound", blowup_bound)
    if post_step is not None:
        _validate.callable_arg("post_step", post_step)
    n, dim = x.shape
    v = np.zeros_like(x) if v is None else v
    free = np.ones(n)
    free[pinned] = 0.0
    M = network.n_springs
    # D: +1 at (i_s, s), -1 at (j_s, s). Gather: d = Dᵀ x; scatter: F = D f. Dense for one
    # strand, where it is fastest, sparse for more; each step is a dozen whole-array operations.
    D = np.zeros((n, M))
    D[network.i, np.arange(M)] += 1.0
    D[network.j, np.arange(M)] -= 1.0
    gather = D.T.copy()
    kick = -dt * D * (free / m)[:, None]          # dv = kick @ (a d), force on i is -a d
    if n * M > 2000:
        gather, kick = sp.csr_matrix(gather), sp.csr_matrix(kick)
    k, k_rest, c = network.k, network.k * network.rest, network.c
    damped_springs = bool(np.any(c))
    g_dt = dt * np.asarray([0.0] * dim if gravity is None else gravity, dtype=float)
    fall = free[:, None] * g_dt
    keep = 1.0 - dt * float(damping) / m[:, None]
    X = np.full((n_steps + 1, n, dim), np.nan)
    X[0] = x
    V = np.empty((16, n, dim))
    message, start = "ok", 1
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for step in range(1, n_steps + 1):
            d = gather @ x
            length = np.sqrt(np.einsum("md,md->m", d, d))
            a = k - k_rest / length                  # k (ℓ - L) / ℓ
            if damped_springs:
                a += c * np.einsum("md,md->m", gather @ v, d) / length**2
            v *= keep
            v += kick @ (a[:, None] * d)
            v += fall
            x += dt * v
            if post_step is not None:
                y = post_step(step * dt, np.stack((x, v)))
                x[...], v[...] = y[0], y[1]
            X[step] = x
            V[step % 16] = v
            if step % 16 == 0 or step == n_steps:
                block = slice(start, step + 1)
                size = np.maximum(np.abs(X[block]).max(axis=(1, 2)),
                                  np.abs(V[np.arange(start, step + 1) % 16]).max(axis=(1, 2)))
                bad = np.flatnonzero(~(size <= blowup_bound))
                if bad.size:
                    k_bad = start + int(bad[0])
                    finite = bool(np.isfinite(size[bad[0]]))
                    X[k_bad + finite:] = np.nan      # a finite state past the bound is kept
                    why = f"|y| > {blowup_bound:.3g}" if finite else "non-finite state"
                    message = f"unstable at step {k_bad}, t = {k_bad * dt:.6g} ({why})"
                    break
                start = step + 1
    return X, message


def simulate(x0, network: SpringNetwork, *, frames: int, substeps: int, fps: float = FPS,
             mass=MASS, pinned=(0,), damping: float = 0.0, gravity=G_EARTH, v0=None,
             post_step=None, blowup_bound: float = 100.0) -> HairRun:
    """Run a strand (or hairstyle) for ``frames`` frames of ``substeps`` steps each, with
    symplectic Euler and ``dt = 1 / (fps * substeps)``. ``blowup_bound`` (m or m/s) is far
    beyond anything a 30 cm strand does, so passing it means the run exploded."""
    frames = _validate.positive_int("frames", frames)
    substeps = _validate.positive_int("substeps", substeps)
    dt = 1.0 / (_validate.positive_finite("fps", fps) * substeps)
    x, message = symplectic_euler_run(x0, network, dt, frames * substeps, mass=mass,
                                      pinned=pinned, damping=damping, gravity=gravity, v0=v0,
                                      post_step=post_step, blowup_bound=blowup_bound)
    t = np.arange(frames + 1) / fps
    return HairRun(t, x[::substeps], x, dt, message == "ok", message)


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
    x0, _, mass, pinned, _, _ = _strand(network, mass, pinned, x0=x0)
    n_steps = _validate.positive_int("n_steps", n_steps)
    amplitude = _validate.positive_finite("amplitude", amplitude)
    rng = np.random.default_rng(seed)
    nudge = amplitude * rng.standard_normal(x0.shape)
    nudge[list(pinned)] = 0.0
    guess = 2.0 / max_frequency(network, x0, mass, pinned)

    def stable(dt):
        _, message = symplectic_euler_run(x0 + nudge, network, dt, n_steps, mass=mass,
                                          pinned=pinned, gravity=None, blowup_bound=1.0)
        return message == "ok"

    return bisect_stable_dt(stable, 0.6 * guess, 1.6 * guess, rtol)


def static_shape(x0, network: SpringNetwork, mass=MASS, pinned=(0, 1), gravity=G_EARTH,
                 axes=None, rtol: float = 1e-9, max_iter: int = 600) -> np.ndarray:
    """Resting positions (m) under gravity: a *stable* minimum of elastic + gravitational
    energy reached from ``x0`` (:func:`course_lib.statics.equilibrium`).

    Newton's method in a trust region, which leaves saddle points along directions of
    negative curvature; the result is checked with the stiffness matrix (no negative
    eigenvalue on the free coordinates). ``axes=(0, 1)`` keeps the free particles in their
    plane (a 2D strand). Raises ``RuntimeError`` when no stable minimum is found.
    """
    return equilibrium(x0, network, mass, pinned, gravity, axes=axes, rtol=rtol,
                       max_iter=max_iter).x


# --- several strands on a head ------------------------------------------------------------


def hairstyle(n_strands: int = 7, center=(0.0, 0.0, 0.0), radius: float = 0.1,
              seed: int = 2026, curl_radius: float = 0.008, turn: float = np.pi / 3, **strand):
    """Several curly strands rooted on the upper half of a spherical head, in ONE network.

    Roots are spread around the crown (seeded jitter). Each strand is a helix of radius
    ``curl_radius`` (m) about the outward normal at its root (:func:`~course_lib.strands.helix`)
    with edge, bending and torsion springs measured on that curly rest shape (``strand``
    overrides :data:`STRAND` and may set ``k_bend``, ``k_twist``). Strand ``s`` owns
    particles ``s*n ... s*n + n - 1``; its root ``s*n`` is pinned.

    Returns
    -------
    x0 : ndarray, shape (n_strands * n, 3)
    network : SpringNetwork
    roots : ndarray of int, shape (n_strands,)
    """
    n_strands = _validate.positive_int("n_strands", n_strands)
    c = _validate.real_array("center", center, (3,))
    radius = _validate.positive_finite("radius", radius)
    curl_radius = _validate.nonnegative("curl_radius", curl_radius)
    params = {**STRAND, **strand}
    n = params["n"]
    rng = np.random.default_rng(seed)
    azimuth = np.linspace(0.0, 2 * np.pi, n_strands, endpoint=False) + 0.2 * rng.uniform(-1, 1, n_strands)
    polar = np.deg2rad(45.0 + 15.0 * rng.uniform(-1, 1, n_strands))
    normal = np.stack((np.sin(polar) * np.cos(azimuth), np.cos(polar),
                       np.sin(polar) * np.sin(azimuth)), axis=1)
    shapes = [helix(n, params["length"], curl_radius, turn, root=c + radius * nrm, axis=nrm)
              for nrm in normal]
    nets = [strand_network(x, params["k_edge"], params.get("k_bend", 0.0),
                           params.get("k_twist", 0.0)) for x in shapes]
    offsets = np.arange(n_strands) * n
    net = SpringNetwork(np.concatenate([o + s.i for o, s in zip(offsets, nets, strict=True)]),
                        np.concatenate([o + s.j for o, s in zip(offsets, nets, strict=True)]),
                        np.concatenate([s.rest for s in nets]), np.concatenate([s.k for s in nets]),
                        np.concatenate([s.c for s in nets]), n_strands * n,
                        np.concatenate([s.kind for s in nets]))
    return np.concatenate(shapes), net, offsets


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
