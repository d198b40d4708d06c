"""Notebook 09 (particle systems): the scenes, the frame loop that runs them, and timings.

Holds the frame loop (:func:`run`: emit, update, expire, count), the update rules of the
scenes (:func:`gravity_bounce`, :func:`fire_update`, :func:`advect_update`), the scenes
themselves (:func:`fountain`, :func:`fire`, :func:`genesis`, :func:`field_sources`), the
exact answers the notebook compares with (:func:`parabola_offset`, :func:`whirlpool_exact`)
and the per-frame cost at scale (:func:`frame_cost`). Built on the core
(:mod:`course_lib.particles`, :mod:`course_lib.fields`); the drawings live in
:mod:`course_lib.lessons.nb09_drawings`. The core never imports this module.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import fields
from ..particles import Emitter, ParticleSystem

FPS = 30.0
DT = 1.0 / FPS
G = np.array([0.0, -9.81, 0.0])


@dataclass
class Run:
    """What :func:`run` records: population and emission per frame, and snapshots."""

    t: np.ndarray            # time at the end of each frame (s)
    population: np.ndarray   # live particles after each frame
    emitted: np.ndarray      # particles emitted in each frame
    snapshots: dict          # frame index -> {attribute: copy of its live rows}
    system: ParticleSystem   # the system after the last frame


def run(emit: Callable, update: Callable, frames: int, *, dt: float = DT, seed: int = 2026,
        dim: int = 3, attributes=None, snapshot_frames=(), capacity: int = 4096) -> Run:
    """Run ``frames`` frames of emit → update → expire and count the live particles.

    ``emit(system, t, rng) -> int`` adds the frame's particles (an :class:`Emitter`'s
    ``emit``); ``update(system, t, dt)`` moves and ages them.
    """
    rng = np.random.default_rng(seed)
    ps = ParticleSystem(dim, capacity, attributes)
    population = np.zeros(frames, dtype=int)
    emitted = np.zeros(frames, dtype=int)
    wanted, snaps = set(snapshot_frames), {}
    for f in range(frames):
        t = f * dt
        emitted[f] = emit(ps, t, rng)
        update(ps, t, dt)
        ps.expire()
        population[f] = len(ps)
        if f in wanted:
            snaps[f] = {name: ps[name].copy() for name in ps.shapes}
    return Run(dt * np.arange(1, frames + 1), population, emitted, snaps, ps)


# --- update rules -----------------------------------------------------------------------


def bounce(ps: ParticleSystem, restitution: float, height: float = 0.0) -> None:
    """Ground contact at ``y = height``: project up and reverse ``v_y`` times ``restitution``."""
    x, v = ps["x"], ps["v"]
    below = x[:, 1] < height
    x[below, 1] = height
    v[below, 1] = np.where(v[below, 1] < 0.0, -restitution * v[below, 1], v[below, 1])


def gravity_bounce(restitution: float = 0.5) -> Callable:
    """Update rule: symplectic Euler under gravity, then ground bounce."""

    def update(ps: ParticleSystem, t: float, dt: float) -> None:
        ps.step(dt, G)
        bounce(ps, restitution)

    return update


def fire_update(ambient: float = 300.0, tau: float = 0.4, buoyancy: float = 0.004,
                drag: float = 1.5, pull: float = 6.0, flicker: float = 1.5,
                seed: int = 9) -> Callable:
    """Update rule for fire and smoke (the y axis points up).

    Temperature relaxes to ``ambient`` (K) with time constant ``tau`` (s), updated
    exactly, ``T ← T_a + (T − T_a) e^{−dt/τ}``; hot gas rises with acceleration
    ``buoyancy × (T − T_a)`` (m/s² per K) against linear ``drag`` (1/s), is drawn to the
    axis by ``pull`` (1/s², scaled by its heat, which tapers the flame) and shaken by a
    random horizontal acceleration of size ``flicker`` (m/s²).
    """
    rng = np.random.default_rng(seed)

    def update(ps: ParticleSystem, t: float, dt: float) -> None:
        temp = ps["temperature"]
        heat = temp - ambient
        a = -drag * ps["v"]
        a[:, 1] += buoyancy * heat
        a[:, [0, 2]] -= pull * (heat / 1300.0)[:, None] * ps["x"][:, [0, 2]]
        a[:, [0, 2]] += flicker * rng.uniform(-1.0, 1.0, (len(ps), 2))
        ps.step(dt, a)
        temp[...] = ambient + (temp - ambient) * np.exp(-dt / tau)

    return update


def advect_update(field: Callable) -> Callable:
    """Update rule: carry the particles by the velocity field ``V(t, x)`` (midpoint step)."""

    def update(ps: ParticleSystem, t: float, dt: float) -> None:
        ps.advect(t, dt, field)

    return update


# --- the scenes --------------------------------------------------------------------------


def fountain(count: float = 40.0, lifetime: float = 2.5) -> Emitter:
    """A fountain: a disc nozzle of radius 5 cm on the ground shooting ``count`` ± 10 drops
    per frame up at 6 ± 0.5 m/s within 12° of the vertical, lifetimes ``lifetime`` ± 0.5 s."""
    return Emitter(count=count, count_variance=10.0, shape="disc", radius=0.05,
                   speed=6.0, speed_variance=0.5, direction=(0.0, 1.0, 0.0),
                   spread=np.radians(12.0), lifetime=lifetime, lifetime_variance=0.5)


def parabola_offset(age, dt: float = DT) -> np.ndarray:
    """Height (m) by which symplectic Euler under constant gravity ends below the exact
    parabola after ``age = m dt``: ``½ g dt · age`` (exactly)."""
    return 0.5 * 9.81 * dt * np.asarray(age, dtype=float)


def fire(count: float = 60.0, temperature: float = 1600.0) -> Emitter:
    """A camp fire: a disc of radius 0.3 m emitting ``count`` ± 15 particles of hot gas per
    frame upward (0.5 ± 0.3 m/s within 20° of the vertical) at ``temperature`` (K),
    lifetimes 2.4 ± 0.8 s."""
    return Emitter(count=count, count_variance=15.0, shape="disc", radius=0.3, speed=0.5,
                   speed_variance=0.3, spread=np.radians(20.0), lifetime=2.4,
                   lifetime_variance=0.8, attributes={"temperature": (temperature, 0.0)})


def cooled(age, temperature: float = 1600.0, ambient: float = 300.0, tau: float = 0.4):
    """Exact temperature (K) after ``age`` (s) of Newtonian cooling."""
    return ambient + (temperature - ambient) * np.exp(-np.asarray(age) / tau)


def genesis(front_speed: float = 1.5, density: float = 6.0, start: float = 0.2) -> Callable:
    """The wall of fire of the Genesis effect: an emitter on a ring of radius
    ``R(t) = start + front_speed · t`` (m) emitting ``density`` particles per metre of
    ring per frame, so its mean count ``density · 2πR(t)`` grows with time. Particles
    burst up within 20° of the vertical at 5 ± 1.5 m/s, and 0.5 m/s outwards; lifetimes
    1.2 ± 0.4 s. Returns ``emit(ps, t, rng)`` with the emitter as its ``.emitter``
    attribute and ``.mean_count(t)``."""
    em = Emitter(count=0.0, shape="ring", speed=5.0, speed_variance=1.5,
                 spread=np.radians(20.0), radial=0.5, lifetime=1.2, lifetime_variance=0.4)

    def mean_count(t):
        return density * 2.0 * np.pi * (start + front_speed * np.asarray(t, dtype=float))

    def emit(ps: ParticleSystem, t: float, rng: np.random.Generator) -> int:
        em.radius = start + front_speed * t
        em.count = float(mean_count(t))
        em.count_variance = 0.25 * em.count
        return em.emit(ps, t, rng)

    emit.emitter, emit.mean_count = em, mean_count
    return emit


def whirl(k: float = 0.25) -> Callable:
    """Notebook 01's whirlpool ``V = (−y, x) − k (x, y)`` (m/s)."""
    return fields.compose(fields.vortex, fields.scaled(fields.radial, -k))


def whirlpool_exact(age, x0, k: float = 0.25) -> np.ndarray:
    """Exact position ``e^{−k a} R(a) x0`` after ``age`` (s) in the whirlpool."""
    a = np.asarray(age, dtype=float)
    c, s, decay = np.cos(a), np.sin(a), np.exp(-k * a)
    x, y = x0[..., 0], x0[..., 1]
    return np.stack((decay * (c * x - s * y), decay * (s * x + c * y)), axis=-1)


def field_sources() -> dict:
    """Notebook 01's fields, each with a small 2D source: name -> (field, emitter)."""
    src = dict(count=8.0, count_variance=2.0, shape="disc", radius=0.05, speed=0.0,
               lifetime=3.0, lifetime_variance=1.0)
    return {
        "radial": (fields.radial, Emitter(center=(0.3, 0.2), **src)),
        "vortex": (fields.vortex, Emitter(center=(1.2, 0.0), **src)),
        "whirlpool": (whirl(), Emitter(center=(1.8, 0.0), **src)),
        "vortex + wind": (fields.compose(fields.vortex, fields.constant_wind((0.5, 0.0))),
                          Emitter(center=(0.0, -1.0), **src)),
    }


def remember_birth(emit: Callable) -> Callable:
    """Wrap ``emit(ps, t, rng)`` so that it also stores each new particle's birth position
    and velocity in the attributes ``x0`` and ``v0`` (which the system must have)."""

    def emit_and_remember(ps: ParticleSystem, t: float, rng: np.random.Generator) -> int:
        start = len(ps)
        k = emit(ps, t, rng)
        ps["x0"][start:] = ps["x"][start:]
        ps["v0"][start:] = ps["v"][start:]
        return k

    return emit_and_remember


def whirlpool_error(dt: float, seconds: float = 4.0) -> float:
    """Largest distance (m) between a whirlpool particle and its exact position after
    ``seconds`` of emission with step ``dt`` (midpoint advection)."""
    fld, em = field_sources()["whirlpool"]
    r = run(remember_birth(em.emit), advect_update(fld), round(seconds / dt), dt=dt,
            dim=2, attributes={"x0": (2,), "v0": (2,)})
    ps = r.system
    return float(np.max(np.linalg.norm(ps["x"] - whirlpool_exact(ps["age"], ps["x0"]), axis=1)))


def frame_cost(n_live: int = 10_000, frames: int = 60, dt: float = 1.0 / 60.0,
               seed: int = 2026) -> tuple[float, int]:
    """Median CPU time (s, ``time.process_time``, so that other programs' load on the
    machine does not count) of one fountain frame (emit + step + bounce + compact) with
    about ``n_live`` live particles, and the live count at the end."""
    L = 2.0
    em = fountain(count=n_live / (L / dt - 0.5), lifetime=L)
    em.count_variance = 0.2 * em.count
    rng = np.random.default_rng(seed)
    ps = ParticleSystem(3, 2 * n_live)
    update = gravity_bounce()
    for f in range(int(L / dt) + 30):                     # warm up to the steady state
        em.emit(ps, f * dt, rng), update(ps, f * dt, dt), ps.expire()
    times = []
    for f in range(frames):
        t0 = time.process_time()
        em.emit(ps, f * dt, rng)
        update(ps, f * dt, dt)
        ps.expire()
        times.append(time.process_time() - t0)
    return float(np.median(times)), len(ps)
