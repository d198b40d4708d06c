"""A running SPH liquid: state, time stepping, frames and per-step statistics.

:class:`Simulation` holds the fluid's positions and velocities (N, dim), its walls and
:class:`~course_lib.sph.params.Params`, and advances them with one of :data:`METHODS`
(``"wcsph"``: Becker & Teschner 2007; ``"iisph"``: Ihmsen et al. 2014), each at its own
CFL step unless given one. It records, for every step, the step, the solver's sweeps, the
number of pairs, the density error at the start of the step (mean and largest
``max(ρ/ρ₀ - 1, 0)``: the compression; a free surface's lower density is not an error) and
the fastest particle's speed at its end.
A run that turns non-finite, or whose fastest particle passes ``params.speed_limit``,
stops with :attr:`Simulation.message` saying where. An optional
:class:`~course_lib.sph.boundary.Gate` joins the walls, lifted as time goes on, until its
lowest particle is a support radius above the highest fluid particle; while it touches the
fluid, no step lets it move more than ``λ Δx``.
Core module.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _validate
from . import iisph, wcsph
from .params import Params

METHODS = ("iisph", "wcsph")


@dataclass
class Frames:
    """States saved at the frame times ``t`` (F,): positions ``x`` (F, N, dim) in m,
    speeds (F, N) in m/s and pressures (F, N) in Pa (pressure solved during the step
    that ends at the frame; zeros at t = 0)."""

    t: np.ndarray
    x: np.ndarray
    speed: np.ndarray
    p: np.ndarray


@dataclass
class Simulation:
    """An SPH liquid at positions ``x`` (N, dim, m) with velocities ``v`` (m/s, default 0)
    between the walls ``wall`` (:class:`~course_lib.sph.boundary.Boundary` or None) and
    behind a ``gate`` (:class:`~course_lib.sph.boundary.Gate` or None) lifted from t = 0."""

    x: np.ndarray
    params: Params
    wall: object = None
    v: np.ndarray | None = None
    method: str = "iisph"
    t: float = 0.0
    gate: object = None
    p: np.ndarray = field(init=False)
    stable: bool = field(init=False, default=True)
    message: str = field(init=False, default="")
    history: dict = field(init=False)

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"unknown method {self.method!r}; valid choices are: {', '.join(METHODS)}")
        self.x = _validate.real_array("x", self.x)
        self.t = _validate.finite_real("t", self.t)
        if self.x.ndim != 2 or self.x.shape[1] != self.params.dim or not np.all(np.isfinite(self.x)):
            raise ValueError(f"x must be a finite array of shape (N, {self.params.dim}), got shape "
                             f"{self.x.shape}")
        self.v = np.zeros_like(self.x) if self.v is None else _validate.real_array("v", self.v)
        if self.v.shape != self.x.shape or not np.all(np.isfinite(self.v)):
            raise ValueError(f"v must be finite with the shape of x, {self.x.shape}, got {self.v.shape}")
        self.p = np.zeros(len(self.x))
        self.history = {k: [] for k in ("t", "dt", "iterations", "pairs", "density_error",
                                        "max_density_error", "speed")}

    @property
    def n(self) -> int:
        """Number of fluid particles."""
        return len(self.x)

    def walls(self):
        """The walls as they are now: :attr:`wall`, with the gate's particles while the
        gate still reaches the fluid."""
        if self.gate is None:
            return self.wall
        top = float(np.max(self.x[:, 1], initial=0.0)) + self.params.support
        return self.gate.walls(self.wall, self.t, clear=top)

    def _gate_dt(self, walls) -> float:
        """The longest step (s) that moves a gate in contact by at most ``λ Δx``."""
        if self.gate is None or walls is self.wall:
            return np.inf
        return self.params.cfl * self.params.spacing / self.gate.speed

    @property
    def steps(self) -> int:
        """Steps taken so far."""
        return len(self.history["dt"])

    def step(self, dt: float | None = None, dt_max: float = np.inf) -> dict:
        """Advance one step (``dt`` in s, default the method's CFL step but at most
        ``dt_max``); returns the
        solver's ``info``. A non-finite result leaves the state as it was, sets
        :attr:`stable` to False and :attr:`message`, and returns ``{}``."""
        if not self.stable:
            return {}
        if dt is not None and not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
        walls = self.walls()
        dt_max = min(dt_max, self._gate_dt(walls))
        with np.errstate(over="ignore", invalid="ignore"):
            if self.method == "iisph":
                x, v, info = iisph.step(self.x, self.v, self.params, walls, dt, dt_max, self.p)
            else:
                x, v, info = wcsph.step(self.x, self.v, self.params, walls, dt, dt_max)
        speed = np.sqrt(np.max(np.einsum("nk,nk->n", v, v), initial=0.0))
        if not (np.all(np.isfinite(x)) and np.isfinite(speed)) or speed > self.params.speed_limit:
            self.stable = False
            what = ("the state turned non-finite" if not np.isfinite(speed) else
                    f"a particle reached {speed:.3g} m/s, past the speed limit "
                    f"{self.params.speed_limit:.3g} m/s")
            self.message = f"unstable at step {self.steps + 1}, t = {self.t:.4g} s: {what}"
            return {}
        self.x, self.v, self.p = x, v, info["p"]
        self.t += info["dt"]
        compression = np.maximum(info["rho"] / self.params.rho0 - 1.0, 0.0)
        for key, value in (("t", self.t), ("dt", info["dt"]), ("iterations", info["iterations"]),
                           ("pairs", info["pairs"]), ("density_error", float(compression.mean())),
                           ("max_density_error", float(compression.max(initial=0.0))),
                           ("speed", speed)):
            self.history[key].append(value)
        return info

    def run(self, t_end: float, frame_dt: float | None = None, max_steps: int = 1_000_000,
            on_step=None) -> Frames:
        """Step until ``t_end`` (s). With ``frame_dt`` (s) the steps before each frame time
        are made equal so as to land on it, and the state is saved there (and at the start). ``on_step(sim)``
        is called after each step that succeeded. Stops early if the run turns unstable."""
        if not (np.isfinite(t_end) and t_end > self.t):
            raise ValueError(f"t_end must be a time after t = {self.t} s, got {t_end!r}")
        max_steps = _validate.positive_int("max_steps", max_steps)
        if frame_dt is not None and not (np.isfinite(frame_dt) and frame_dt > 0):
            raise ValueError(f"frame_dt must be a positive number of seconds, got {frame_dt!r}")
        frames = [self._frame()]
        next_frame = self.t + frame_dt if frame_dt else np.inf
        for _ in range(max_steps):
            if self.t >= t_end * (1 - 1e-12) or not self.stable:
                break
            # land on the next frame with equal steps: a sliver of a step would leave IISPH
            # to undo a whole step's compression in it, a velocity kick of Δρ/ρ Δx/Δt
            remaining = min(t_end, next_frame) - self.t
            parts = max(1, int(np.ceil(remaining / self._cfl() * (1 - 1e-9))))
            self.step(dt_max=remaining / parts)
            if not self.stable:
                break
            if self.t >= next_frame * (1 - 1e-12):
                frames.append(self._frame())
                next_frame += frame_dt
            if on_step is not None:
                on_step(self)
        return Frames(*(np.array(a) for a in zip(*frames, strict=True)))

    def _cfl(self) -> float:
        """The method's step for the present speeds, with gravity as the acceleration bound."""
        v_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", self.v, self.v), initial=0.0)))
        g = float(np.linalg.norm(self.params.gravity))
        step = iisph.cfl_step if self.method == "iisph" else wcsph.cfl_step
        return min(step(self.params, v_max, g), self._gate_dt(self.walls()))

    def _frame(self):
        return (self.t, self.x.copy(), np.linalg.norm(self.v, axis=1), self.p.copy())
