"""Notebook 08 (hair chains), the computations: the held strand and its widget's pure
function, substep studies, the twist experiments.

Built on the strand model of :mod:`course_lib.hair` and :mod:`course_lib.strands` and the
springs of :mod:`course_lib.springs`. The drawings, the widget and the animations live in
:mod:`course_lib.lessons.nb08_hair_view`, which imports this module (never the other way);
the notebook imports both through :mod:`course_lib.lessons.nb08_hair_chains`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..forces import G_EARTH
from ..hair import FPS, MASS, STRAND, max_strain, simulate, static_shape, symplectic_euler_run
from ..springs import SpringNetwork, hair_chain, max_frequency
from ..statics import Equilibrium, curvature, equilibrium
from ..strands import helix, strand_network, twist, twist_angle


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


def held_strand(k_bend: float = 0.0, zigzag: float = 0.0, **strand):
    """A strand laid out horizontally along +x with a clamped root (particles 0 and 1
    pinned): ``(x0, network)``."""
    return hair_chain(**{**STRAND, "k_bend": k_bend, "zigzag": zigzag, **strand})


@functools.lru_cache(maxsize=256)
def _held_equilibrium(k_bend: float, zigzag: float) -> np.ndarray:
    x0, net = held_strand(k_bend, zigzag)
    x = static_shape(x0, net, axes=(0, 1))     # in its plane: the runs below stay planar
    x.setflags(write=False)
    return x


@functools.lru_cache(maxsize=256)
def _held_omega(k_bend: float, zigzag: float) -> float:
    x0, net = held_strand(k_bend, zigzag)
    return max_frequency(net, x0, MASS, (0, 1))


def damped_step_limit(omega_max: float, damping: float, mass: float = MASS) -> float:
    """Symplectic Euler's largest stable step (s) for the fastest mode ``omega_max`` (rad/s)
    with viscous damping ``-c v`` on every particle of mass ``mass``: notebook 07's
    ``ω² dt² + 2 (c/m) dt < 4``, so ``dt < 4 / (γ + √(γ² + 4 ω²))``, ``γ = c/m``. With equal
    masses the damping acts on every mode alike, and the fastest mode sets the limit."""
    gamma = damping / mass
    return float(4.0 / (gamma + np.sqrt(gamma**2 + 4.0 * omega_max**2)))


def tip_sag(k_bend: float = 0.0, zigzag: float = 0.0) -> float:
    """How far (m) the tip of the held-out :data:`STRAND` drops at its equilibrium under
    gravity in its own plane (root clamped: particles 0 and 1 pinned). In 3D a zigzag's
    in-plane equilibrium is a saddle (:func:`saddle_escape`)."""
    x0, _ = held_strand(k_bend, zigzag)
    return float(x0[-1, 1] - _held_equilibrium(float(k_bend), float(zigzag))[-1, 1])


# --- the held zigzag: a minimum in its plane, a saddle in 3D ----------------------------


@dataclass
class SaddleEscape:
    """Result of :func:`saddle_escape`."""

    planar: Equilibrium       #: the strand's equilibrium kept in its plane (axes x, y)
    minimum: Equilibrium      #: the stable resting shape in 3D
    lowest: np.ndarray        #: the three lowest eigenvalues of K in 3D at ``planar`` (N/m)
    t: np.ndarray             #: times of the stored states of the nudged run (s)
    x: np.ndarray             #: its states (m), shape (F, n, 3)
    away: np.ndarray          #: distance of each stored state from ``planar`` (m)
    near: np.ndarray          #: ... from ``minimum`` or its mirror image z -> -z (m)


def saddle_escape(k_bend: float = 2000.0, zigzag: float = 0.3, nudge: float = 1e-6,
                  damping: float = 2e-3, dt: float = 1e-4, t_end: float = 3.0, seed: int = 8,
                  every: int = 50) -> SaddleEscape:
    """The held strand's equilibrium in its plane, the stiffness matrix there in 3D, the
    stable 3D resting shape (:func:`course_lib.statics.equilibrium`), and a damped run
    started at the planar equilibrium nudged by ``nudge`` (m, seeded, every coordinate).
    Distances are Euclidean norms over all coordinates."""
    x0, net = held_strand(k_bend, zigzag)
    planar = equilibrium(x0, net, MASS, (0, 1), G_EARTH, axes=(0, 1))
    minimum = equilibrium(x0, net, MASS, (0, 1), G_EARTH)
    rng = np.random.default_rng(seed)
    push = nudge * rng.standard_normal(x0.shape)
    push[:2] = 0.0
    x, _ = symplectic_euler_run(planar.x + push, net, dt, round(t_end / dt), pinned=(0, 1),
                                damping=damping)
    x = x[::every]
    mirror = minimum.x * np.array([1.0, 1.0, -1.0])
    near = np.minimum(np.linalg.norm(x - minimum.x, axis=(1, 2)),
                      np.linalg.norm(x - mirror, axis=(1, 2)))
    return SaddleEscape(planar, minimum, curvature(net, planar.x, (0, 1))[:3],
                        dt * every * np.arange(len(x)), x,
                        np.linalg.norm(x - planar.x, axis=(1, 2)), near)


def drooped_equilibrium(k_bend: float = 2000.0, zigzag: float = 0.3, droop: float = 1.0
                        ) -> Equilibrium:
    """The held strand's equilibrium in its plane reached from its rest shape turned down by
    ``droop`` rad about particle 1 (the clamp): another local minimum of the same energy,
    in which the bend next to the clamp has snapped through (its triangle is turned inside
    out, :func:`flipped_bends`) and acts as a hinge."""
    x0, net = held_strand(k_bend, zigzag)
    c, s = np.cos(droop), np.sin(droop)
    turn = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])     # clockwise in x-y
    start = x0.copy()
    start[2:] = (x0[2:] - x0[1]) @ turn.T + x0[1]
    return equilibrium(start, net, MASS, (0, 1), G_EARTH, axes=(0, 1))


def flipped_bends(x, x_rest) -> np.ndarray:
    """Particles ``p`` whose bend (the triangle ``p - 1, p, p + 1``) turns the other way in
    ``x`` than in ``x_rest``, seen in the x-y plane."""
    def turns(y):
        a, b = y[1:-1] - y[:-2], y[2:] - y[1:-1]
        return np.sign(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.flatnonzero(turns(np.asarray(x)) != turns(np.asarray(x_rest))) + 1


# --- the notebook 08 widget's pure function -------------------------------------------------


@dataclass
class HeldStrandRun:
    """Result of :func:`run_held_strand`."""

    t: np.ndarray             #: snapshot times (s), shape (F,)
    frames: np.ndarray        #: strand at the snapshots (m), shape (F, 16, 3)
    tip_y: np.ndarray         #: tip height at every step (m); NaN after a blow-up
    equilibrium: np.ndarray   #: the in-plane equilibrium it should settle to (m)
    stable: bool
    message: str
    dt_limit: float           #: the step limit with this damping (s), from ω_max at rest
    params: dict              #: the arguments, the step times "t" and "t_shown"
    last_finite: np.ndarray | None = None   #: last finite state of a blown-up run
    last_step: int = 0        #: index of the last finite step
    growth: np.ndarray | None = None        #: blown up: max |x - x0| at every step (m)
    speed: np.ndarray | None = None         #: blown up: largest speed at steps 1... (m/s)


def run_held_strand(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4,
                    zigzag: float = 0.3, t_end: float = 0.5, n_frames: int = 6,
                    max_steps: int | None = None) -> HeldStrandRun:
    """Release a held-out strand (clamped root) under gravity with symplectic Euler, in its
    plane: every force of a strand laid out in the x-y plane stays in it, so the run is the
    2D strand.

    Returns the strand at ``n_frames`` times, the tip height at every step, the in-plane
    equilibrium it should settle to, the verdict, and the step limit with this damping
    (:func:`damped_step_limit`; ``2 / ω_max`` without damping). With
    ``max_steps`` the run stops after that many steps (``t_end`` shortened to
    ``max_steps · dt``, said in ``params["t_shown"]``): the widget's cap. Pure and cached
    where it can be (the equilibrium and the limit depend on ``k_bend`` only).
    """
    x0, net = held_strand(k_bend, zigzag)
    n = max(1, round(t_end / dt))
    if max_steps is not None:
        n = min(n, int(max_steps))
    equilibrium = _held_equilibrium(float(k_bend), float(zigzag))
    x, message = symplectic_euler_run(x0, net, dt, n, pinned=(0, 1), damping=damping,
                                      blowup_bound=100.0)
    t = dt * np.arange(n + 1)
    finite = np.flatnonzero(np.all(np.isfinite(x[:, :, 0]), axis=1))
    last = int(finite[-1])
    pick = np.linspace(0, n, n_frames).round().astype(int)
    stable = message == "ok"
    growth = None if stable else np.abs(x[: last + 1] - x0).max(axis=(1, 2))
    # symplectic Euler moves x by dt times the new velocity: the speeds are the differences
    speed = None if stable else np.linalg.norm(np.diff(x[: last + 1], axis=0), axis=2).max(axis=1) / dt
    if not stable:   # say what passed the bound: a position (m) or a speed (m/s)
        step = int(message.split("step ")[1].split(",")[0])
        what = ("a coordinate past 100 m" if np.isfinite(x[step]).all()
                and np.abs(x[step]).max() > 100.0 else "a speed past 100 m/s")
        message = f"unstable at step {step}, t = {step * dt * 1e3:.3g} ms ({what})"
    return HeldStrandRun(t[pick], x[pick], x[:, -1, 1], equilibrium, stable, message,
                         damped_step_limit(_held_omega(float(k_bend), float(zigzag)), damping),
                         {"k_bend": k_bend, "damping": damping, "dt": dt, "t": t,
                          "t_end": t_end, "t_shown": float(t[-1]), "steps": n},
                         None if stable else x[last], last, growth, speed)


# --- twist: planar rest shapes against a helix --------------------------------------------


#: Rest shapes of the twist experiments: three planar ones and a helix (16 particles, 30 cm).
def twist_shapes() -> dict[str, np.ndarray]:
    """The strands of the twist experiments, each laid out along +x from the origin."""
    return {
        "straight": hair_chain(**STRAND)[0],
        "planar curl": hair_chain(**STRAND, curl=0.3)[0],
        "zigzag": hair_chain(**STRAND, zigzag=0.3)[0],
        "helix": helix(STRAND["n"], STRAND["length"], radius=0.01, turn=np.pi / 3,
                       axis=(1.0, 0.0, 0.0)),
    }


def twist_energy(x0, angles, k_bend: float = 2000.0, k_twist: float = 500.0, cut: int = 2):
    """Elastic energy (J) of a strand twisted by each of ``angles`` (rad) beyond particle
    ``cut`` (:func:`~course_lib.strands.twist`), with edge, bending and torsion springs."""
    net = strand_network(x0, STRAND["k_edge"], k_bend, k_twist)
    return np.array([net.energy(twist(x0, a, cut)) for a in np.atleast_1d(angles)])


def twist_release(x0, angle: float = 0.3, k_bend: float = 2000.0, k_twist: float = 500.0,
                  damping: float = 1e-3, dt: float = 1e-4, t_end: float = 1.5, cut: int = 2):
    """Twist a strand by ``angle`` beyond particle ``cut`` (root clamped: particles
    ``0 ... cut`` pinned), release it without gravity, and return ``(t, twist angle of the
    tip)`` at every step, with the verdict message."""
    net = strand_network(x0, STRAND["k_edge"], k_bend, k_twist)
    n = round(t_end / dt)
    x, message = symplectic_euler_run(twist(x0, angle, cut), net, dt, n,
                                      pinned=tuple(range(cut + 1)), damping=damping,
                                      gravity=None)
    return dt * np.arange(n + 1), twist_angle(x, x0, cut), message


def twist_releases(shapes: dict, angle: float = 0.3, k_bend: float = 2000.0, k_twist: float = 500.0,
                   damping: float = 1e-3, dt: float = 1e-4, t_end: float = 1.5, cut: int = 2) -> dict:
    """:func:`twist_release` of every strand of ``shapes`` (``{name: x0}``, each ``(n, 3)``)
    in ONE run: the strands side by side in one network, which they do not share, so each
    moves as it would alone (the same arithmetic, particle by particle) at a third of the
    cost of three runs. Returns ``{name: (t, twist angle of the tip, message)}``."""
    rest = [np.asarray(x0, dtype=float) for x0 in shapes.values()]
    nets = [strand_network(x0, STRAND["k_edge"], k_bend, k_twist) for x0 in rest]
    offsets = np.cumsum([0] + [len(x0) for x0 in rest])
    def joined(field, shift=False):
        return np.concatenate([getattr(s, field) + o if shift else getattr(s, field)
                               for o, s in zip(offsets, nets, strict=False)])

    net = SpringNetwork(joined("i", True), joined("j", True), joined("rest"), joined("k"),
                        joined("c"), int(offsets[-1]), joined("kind"))
    n = round(t_end / dt)
    x, message = symplectic_euler_run(np.concatenate([twist(x0, angle, cut) for x0 in rest]), net, dt,
                                      n, pinned=tuple(int(o) + p for o in offsets[:-1]
                                                      for p in range(cut + 1)),
                                      damping=damping, gravity=None)
    t = dt * np.arange(n + 1)
    return {name: (t, twist_angle(x[:, a:b], x0, cut), message)
            for name, x0, a, b in zip(shapes, rest, offsets[:-1], offsets[1:], strict=True)}
