"""Cloth as a grid of masses and springs, stepped explicitly, implicitly or by constraints.

Holds :class:`Cloth` (the grid's rest positions, spring network of
:func:`~course_lib.springs.cloth_grid`, particle masses and pinned particles) and
:func:`sheet`, which lays one out horizontally with two corners pinned; the energies of a
state (:func:`energies`); a time loop that takes ``substeps`` steps per animation frame
(:func:`simulate`) with one of :data:`METHODS`: symplectic Euler, the implicit step of
:class:`~course_lib.baraff_witkin.BaraffWitkin`, fast mass-springs
(:class:`~course_lib.largestep.local_global.FastMassSpring`) or XPBD
(:class:`~course_lib.largestep.xpbd.XPBD`), each optionally followed by Provot's strain
limiting (:class:`~course_lib.largestep.strain_limit.StrainLimiter`) and by collisions;
and the largest stable explicit step, measured by bisection (:func:`explicit_dt_max`) to
set beside ``2/ω_max`` of :func:`~course_lib.springs.max_frequency`. Core module:
imports NumPy and core modules only.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from . import _validate
from .baraff_witkin import BaraffWitkin
from .forces import G_EARTH
from .largestep import XPBD, FastMassSpring, LongRangeAttachments, StrainLimiter
from .springs import SpringNetwork, cloth_grid
from .stability import bisect_stable_dt

METHODS = ("symplectic_euler", "baraff_witkin", "fast_mass_spring", "xpbd")
#: XPBD's small steps per simulated second when ``options`` gives no ``substeps``: 288 per
#: 1/60 s frame, the fewest that keep the peak strain of the 32² sheet of issue 19 within
#: 0.5 percentage points of converged symplectic Euler at stiffness ×100 and ×1000 (with
#: room for the spread of the whipping free edge; 240 is at the edge).
XPBD_SUBSTEPS_PER_SECOND = 60 * 288


@dataclass
class Cloth:
    """A cloth: ``x0`` (N, 3) rest positions (m), its springs, ``mass`` (N,) (kg), the
    ``pinned`` particle indices, and the grid ``shape`` (rows, columns)."""

    x0: np.ndarray
    network: SpringNetwork
    mass: np.ndarray
    pinned: np.ndarray
    shape: tuple[int, int]

    @property
    def n(self) -> int:
        return self.x0.shape[0]


def sheet(n: int = 12, size: float = 0.55, total_mass: float = 0.1, k_struct: float = 300.0,
          k_shear: float | None = None, k_bend: float | None = None, c: float = 0.0,
          height: float = 0.0, pinned: str = "corners", damping_ratio: float | None = None) -> Cloth:
    """A square cloth of ``n × n`` particles and side ``size`` (m), lying flat in the
    horizontal plane ``y = height``, centred on the y axis (rows along z). Shear and bend stiffness default to
    10 % and 2 % of ``k_struct`` (N/m); ``c`` damps along every spring (N s/m), or
    ``damping_ratio=ζ`` sets ``c = ζ · 2 √(k_struct m)``, ``ζ`` times the critical damping
    of one particle on one structural spring. ``pinned="corners"`` holds the two corners
    of the first row, ``"none"`` nothing.
    """
    _validate.choice("pinned", pinned, ("corners", "none"))
    height = _validate.finite_real("height", height)
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    size = _validate.positive_finite("size", size)
    if damping_ratio is not None:
        if c:
            raise ValueError("give either c or damping_ratio, not both")
        zeta = _validate.finite_real("damping_ratio", damping_ratio)
        if zeta < 0:
            raise ValueError(f"damping_ratio must be >= 0, got {zeta}")
        m = _validate.positive_finite("total_mass", total_mass) / (n * n)
        c = zeta * 2.0 * np.sqrt(_validate.positive_finite("k_struct", k_struct) * m)
    k_shear = 0.1 * k_struct if k_shear is None else k_shear
    k_bend = 0.02 * k_struct if k_bend is None else k_bend
    grid, net = cloth_grid(n, n, size / (n - 1), k_struct, k_shear, k_bend, c)
    x0 = np.stack((grid[:, 0] - size / 2, np.full(n * n, float(height)), grid[:, 1] - size / 2),
                  axis=1)
    mass = np.full(n * n, _validate.positive_finite("total_mass", total_mass) / (n * n))
    pins = np.array([0, n - 1] if pinned == "corners" else [], dtype=int)
    return Cloth(x0, net, mass, pins, (n, n))


def energies(cloth: Cloth, x, v, gravity=G_EARTH) -> dict[str, np.ndarray]:
    """Kinetic, elastic and gravitational energy (J) of states ``x, v`` of shape (N, 3)
    or (F, N, 3); ``"total"`` is their sum. Height is measured along ``-gravity``."""
    x, v = _validate.state_array("x", x), _validate.state_array("v", v)
    if x.shape != v.shape or x.shape[-2:] != cloth.x0.shape:
        raise ValueError(f"x and v must both have shape {cloth.x0.shape} or (F, *that), got "
                         f"{x.shape} and {v.shape}")
    kinetic = 0.5 * np.sum(cloth.mass * np.sum(v * v, axis=-1), axis=-1)
    elastic = cloth.network.energy(x)
    potential = -np.sum(cloth.mass * (x @ np.asarray(gravity, dtype=float)), axis=-1)
    return {"kinetic": kinetic, "elastic": elastic, "gravity": potential,
            "total": kinetic + elastic + potential}


@dataclass
class ClothRun:
    """Result of :func:`simulate`: positions and velocities at every frame (NaN after a
    blow-up), the verdict, the step, and the CG iterations of every implicit step."""

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    dt: float
    stable: bool
    message: str
    iterations: np.ndarray


def simulate(cloth: Cloth, method: str = "symplectic_euler", *, frames: int = 60,
             substeps: int = 1, fps: float = 30.0, gravity=G_EARTH, x0=None, v0=None,
             post_step: Callable | None = None, rtol: float = 1e-4,
             blowup_bound: float = 100.0, iterations: int | None = None,
             strain_limit: float | None = None, options: Mapping | None = None) -> ClothRun:
    """Run ``frames`` animation frames of ``substeps`` steps each, ``dt = 1/(fps substeps)``.

    ``"symplectic_euler"``: ``v += dt (F(x, v)/m + g)`` (zero for pinned particles), then
    ``x += dt v``. ``"baraff_witkin"``: one linearized implicit step, CG to ``rtol``
    (``iterations`` caps CG). ``"fast_mass_spring"``: implicit Euler by ``iterations``
    (default 20) local/global iterations accelerated by L-BFGS. ``"xpbd"``: each step is
    ``dt`` × :data:`XPBD_SUBSTEPS_PER_SECOND` small XPBD steps (rounded up; or
    ``options["substeps"]``) of ``iterations`` (default 1) sweeps; ``options["tethers"]``
    may be ``True`` or a tether scale ``s >= 1`` for long range attachments from every
    particle to the pins at ``s`` times its rest distance (Kim et al. 2012; see
    :class:`~course_lib.largestep.attachments.LongRangeAttachments`). ``options`` go to the
    solver's constructor (e.g. ``{"memory": 0}`` for plain local/global). With
    ``strain_limit=τ`` every step is followed by Provot's (1995) strain limiting
    (:class:`~course_lib.largestep.strain_limit.StrainLimiter`): sweeps until no spring's
    strain exceeds ``τ (1 + 0.01)``, at most 1,000 per step (enough unless the pins hold
    the cloth farther apart than the limit allows). Then ``post_step(t, y)`` (e.g.
    :func:`course_lib.collisions.sphere`) may change the stacked state ``y = (x, v)``.
    A run whose coordinates pass ``blowup_bound`` (m or m/s) or stop being finite ends
    there; later frames are NaN. Damping (the network's ``c``) acts in every method.
    """
    _validate.choice("method", method, METHODS)
    if isinstance(substeps, bool) or not isinstance(substeps, int | np.integer) or substeps < 1:
        raise ValueError(f"substeps must be an integer >= 1, got {substeps!r}")
    frames = _validate.positive_int("frames", frames)
    dt = 1.0 / (_validate.positive_finite("fps", fps) * substeps)
    g = _validate.vector("gravity", gravity)
    x = _validate.state_array("x0", cloth.x0 if x0 is None else x0)
    v = np.zeros_like(x) if v0 is None else _validate.state_array("v0", v0)
    for name, a in (("x0", x), ("v0", v)):
        if a.shape != cloth.x0.shape or np.iscomplexobj(a):
            raise ValueError(f"{name} must be a real array of shape {cloth.x0.shape}, got {a.shape}")
    if g.shape != (x.shape[1],):
        raise ValueError(f"gravity must have shape ({x.shape[1]},), got {g.shape}")
    if post_step is not None:
        _validate.callable_arg("post_step", post_step)
    _validate.positive_finite("rtol", rtol)
    blowup_bound = _validate.positive_finite("blowup_bound", blowup_bound)
    if iterations is not None:
        if method == "symplectic_euler":
            raise ValueError("iterations does not apply to symplectic_euler (it has none)")
        iterations = _validate.positive_int("iterations", iterations)
    options = dict(options or {})
    solver = _solver(cloth, method, g, rtol, iterations, dt, options)
    limiter = None if strain_limit is None else StrainLimiter(
        cloth.network, cloth.mass, _validate.positive_finite("strain_limit", strain_limit),
        pinned=cloth.pinned)
    free = np.ones((cloth.n, 1))
    free[cloth.pinned] = 0.0
    inv_m = free / cloth.mass[:, None]
    xs = np.full((frames + 1, *x.shape), np.nan)
    vs = np.full_like(xs, np.nan)
    xs[0], vs[0] = x, v
    force = np.empty_like(x)
    iterations_done, message = [], "ok"

    def broken(x, v) -> bool:
        return not (np.all(np.isfinite(x)) and np.abs(x).max() <= blowup_bound
                    and np.all(np.isfinite(v)) and np.abs(v).max() <= blowup_bound)

    with np.errstate(over="ignore", invalid="ignore"):
        for f in range(1, frames + 1):
            for s in range(substeps):
                t = ((f - 1) * substeps + s) * dt
                if solver is None:
                    cloth.network.forces(x, v, out=force)
                    v = v + dt * (force * inv_m + free * g)
                    x = x + dt * v
                else:
                    x, v = solver.step(x, v, dt, t=t)
                    info = solver.info
                    iterations_done.append(getattr(info, "iterations", getattr(info, "sweeps", 0)))
                if limiter is not None:
                    x, v = limiter.apply(x, v, dt)
                if post_step is not None:
                    x, v = post_step(t + dt, np.stack((x, v)))
                if solver is not None and broken(x, v):
                    break             # a costly solver must not start from a broken state
            if broken(x, v):
                message = f"unstable at frame {f}, t = {f / fps:.3g} s (|y| > {blowup_bound:g})"
                break
            xs[f], vs[f] = x, v
    return ClothRun(np.arange(frames + 1) / fps, xs, vs, dt, message == "ok", message,
                    np.array(iterations_done, dtype=int))


def _solver(cloth: Cloth, method: str, g, rtol: float, iterations, dt: float, options: dict):
    """The stepper of ``method`` for ``cloth`` (``None`` for symplectic Euler)."""
    common = {"pinned": cloth.pinned, "gravity": g}
    if method == "symplectic_euler":
        if options:
            raise ValueError(f"options do not apply to symplectic_euler, got {sorted(options)}")
        return None
    if method == "baraff_witkin":
        return BaraffWitkin(cloth.network, cloth.mass, **common, rtol=rtol, check=False,
                            maxiter=iterations, **options)
    if method == "fast_mass_spring":
        return FastMassSpring(cloth.network, cloth.mass, **common,
                              iterations=iterations or 20, **options)
    options.setdefault("substeps", max(1, math.ceil(dt * XPBD_SUBSTEPS_PER_SECOND - 1e-9)))
    tethers = options.get("tethers")
    if tethers is True or (isinstance(tethers, int | float) and not isinstance(tethers, bool)):
        options["tethers"] = LongRangeAttachments(
            cloth.x0, cloth.pinned, scale=1.0 if tethers is True else tethers)
    elif tethers is False:
        options["tethers"] = None
    return XPBD(cloth.network, cloth.mass, **common, iterations=iterations or 1, **options)


def explicit_dt_max(cloth: Cloth, n_steps: int = 600, rtol: float = 1e-3, seed: int = 0,
                    lo: float | None = None, hi: float | None = None) -> float:
    """Largest stable symplectic Euler step (s) about the rest shape, measured by bisection.

    Each trial starts at rest, every free particle nudged by 1 μm at random, without
    gravity (so the motion stays linear about the rest shape), and runs ``n_steps`` steps;
    it is unstable if some particle ever moves 1 mm (a growth by 1000). The bracket
    defaults to ``[0.5, 2] × 2/ω`` with ``ω = √(max k / min m)`` scaled by 2.
    """
    n_steps = _validate.positive_int("n_steps", n_steps)
    rng = np.random.default_rng(seed)
    nudge = 1e-6 * rng.uniform(-1.0, 1.0, cloth.x0.shape)
    nudge[cloth.pinned] = 0.0
    guess = 1.0 / np.sqrt(cloth.network.k.max() / cloth.mass.min())
    lo = 0.25 * guess if lo is None else lo
    hi = 2.0 * guess if hi is None else hi
    free = np.ones((cloth.n, 1))
    free[cloth.pinned] = 0.0
    inv_m = free / cloth.mass[:, None]

    def stable(dt: float) -> bool:
        x, v = cloth.x0 + nudge, np.zeros_like(cloth.x0)
        force = np.empty_like(x)
        with np.errstate(over="ignore", invalid="ignore"):
            for k in range(n_steps):
                cloth.network.forces(x, v, out=force)
                v += dt * force * inv_m
                x += dt * v
                if k % 20 == 19 and not np.abs(x - cloth.x0).max() < 1e-3:
                    return False
        return bool(np.abs(x - cloth.x0).max() < 1e-3)

    return bisect_stable_dt(stable, lo, hi, rtol)
