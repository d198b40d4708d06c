"""Walls made of particles, after Akinci et al. (2012).

A wall is a set of fixed particles at ``x`` (K, dim) with weights ``ψ_k`` (kg): they add
``ψ_k W_ik`` to the density of a fluid particle near them, so that its density does not
drop at the wall (a particle there would otherwise miss part of its neighbourhood), and
they push back with the pressure force ``-γ ψ_k (p_i/ρ_i²) ∇W_ik`` (see
:mod:`course_lib.sph.forces`). Akinci et al. weight a wall particle by the volume its
wall neighbours leave it, ``ψ_k = ρ₀ / Σ_l W_kl`` (:func:`akinci_psi`), so that one
layer of particles sampled at any spacing works; a single layer on a flat wall still
leaves the density of the first fluid row 15 % off (the notebook measures it). Our
boxes therefore use the equivalent that is exact for a flat wall at rest: enough rows of
wall particles to fill the kernel's support, on the fluid's own lattice, each weighted
by a fluid particle's mass ``ρ₀ V`` (:func:`lattice_volume`, :func:`box`).

Wall particles may move: a :class:`Boundary` carries their velocities ``v`` (zero for a
fixed wall), which enter the viscous force and the continuity equation, and a
:class:`Gate` is a block of wall particles lifted at a constant speed (the barrier of a
dam-break experiment). Core module.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from .kernels import KERNELS, SUPPORT, check_name


@dataclass
class Boundary:
    """Wall particles: positions ``x`` (K, dim), m, weights ``psi`` (K,), kg, and
    velocities ``v`` (K, dim), m/s (default: at rest)."""

    x: np.ndarray
    psi: np.ndarray
    v: np.ndarray | None = None
    tree: cKDTree = field(init=False, repr=False)

    def __post_init__(self):
        self.x = np.asarray(self.x, dtype=float)
        self.psi = np.broadcast_to(np.asarray(self.psi, dtype=float), (len(self.x),)).copy()
        if self.x.ndim != 2:
            raise ValueError(f"wall positions x must have shape (K, dim), got {self.x.shape}")
        if not np.all(np.isfinite(self.x)) or not np.all(self.psi > 0):
            raise ValueError("wall positions must be finite and weights psi positive")
        self.v = np.zeros_like(self.x) if self.v is None else np.array(self.v, dtype=float)
        if self.v.shape != self.x.shape or not np.all(np.isfinite(self.v)):
            raise ValueError(f"wall velocities v must be finite with the shape of x, {self.x.shape}, "
                             f"got {self.v.shape}")
        self.tree = cKDTree(self.x)

    @property
    def moving(self) -> bool:
        """Whether any wall particle moves."""
        return bool(np.any(self.v))

    @property
    def n(self) -> int:
        """Number of wall particles."""
        return len(self.x)


def lattice_volume(spacing: float, h: float, kernel: str = "cubic", dim: int = 2) -> float:
    """``V = 1 / Σ_n W(|n Δx|)`` (m^dim) over a square lattice of side ``spacing``: a
    particle of mass ``ρ₀ V`` in a full lattice has density exactly ``ρ₀``."""
    W = KERNELS[check_name(kernel)]
    reach = int(np.ceil(SUPPORT[kernel] * h / spacing))
    axis = np.arange(-reach, reach + 1) * spacing
    grid = np.stack(np.meshgrid(*([axis] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    return 1.0 / float(np.sum(W(np.linalg.norm(grid, axis=1), h, dim)))


def layers_needed(spacing: float, h: float, kernel: str = "cubic") -> int:
    """Rows of wall particles that fill the support of a fluid particle touching the wall."""
    return int(np.ceil(SUPPORT[check_name(kernel)] * h / spacing - 0.5))


def akinci_psi(x, rho0: float, h: float, kernel: str = "cubic") -> np.ndarray:
    """Akinci et al.'s (2012) weights ``ψ_k = ρ₀ / Σ_l W(|x_k - x_l|)`` (kg), the sum over
    the wall particles ``l`` near ``k`` (``k`` included)."""
    x = np.asarray(x, dtype=float)
    W = KERNELS[check_name(kernel)]
    tree = cKDTree(x)
    pairs = tree.query_pairs(SUPPORT[kernel] * h, output_type="ndarray")
    w = W(np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1), h, x.shape[1])
    total = W(0.0, h, x.shape[1]) + np.bincount(pairs[:, 0], w, minlength=len(x)) \
        + np.bincount(pairs[:, 1], w, minlength=len(x))
    return rho0 / total


def box(width: float, height: float, spacing: float, rho0: float, h: float,
        kernel: str = "cubic", layers: int | None = None) -> Boundary:
    """An open-topped 2D box ``[0, width] × [0, ∞)`` whose walls rise to ``height`` (m).

    Wall particles sit at ``(k + 1/2) Δx`` outside each wall face, continuing the fluid's
    lattice (fluid particles at ``(i + 1/2) Δx`` inside), ``layers`` rows deep (default:
    :func:`layers_needed`); each weighs ``ρ₀`` times :func:`lattice_volume`.
    """
    for name, value in (("width", width), ("height", height), ("spacing", spacing)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive length (m), got {value!r}")
    layers = layers_needed(spacing, h, kernel) if layers is None else int(layers)
    if layers < 1:
        raise ValueError(f"layers must be >= 1, got {layers!r}")
    offsets = (np.arange(layers) + 0.5) * spacing
    n_x = round(float(width) / spacing)
    xs = (np.arange(-layers, n_x + layers) + 0.5) * spacing
    xs[xs > width] += width - n_x * spacing        # the right wall's rows start at x = width
    ys = (np.arange(int(np.ceil(height / spacing))) + 0.5) * spacing
    floor = np.stack(np.meshgrid(xs, -offsets, indexing="ij"), axis=-1).reshape(-1, 2)
    left = np.stack(np.meshgrid(-offsets, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    right = np.stack(np.meshgrid(width + offsets, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    volume = lattice_volume(spacing, h, kernel, 2)
    return Boundary(np.concatenate([floor, left, right]), rho0 * volume)


@dataclass
class Gate:
    """A barrier of wall particles at ``x`` (K, dim) (m, at t = 0) with weights ``psi``
    (K,) (kg), lifted at ``speed`` (m/s, along +y) from t = 0 on: at time ``t`` its
    particles are at ``x + speed t ŷ`` and move at ``speed ŷ``. ``speed=inf`` removes it
    at once (a release without a gate)."""

    x: np.ndarray
    psi: np.ndarray
    speed: float

    def __post_init__(self):
        self.x = np.asarray(self.x, dtype=float)
        self.psi = np.broadcast_to(np.asarray(self.psi, dtype=float), (len(self.x),)).copy()
        if not (isinstance(self.speed, int | float | np.floating) and self.speed > 0):
            raise ValueError(f"the gate's speed must be a positive number of m/s, got {self.speed!r}")

    def offset(self, t: float) -> np.ndarray:
        """The lift (dim,) in m at time ``t`` (s)."""
        up = np.zeros(self.x.shape[1])
        up[1] = self.speed * t
        return up

    def bottom(self, t: float) -> float:
        """Height (m) of the gate's lowest particle at time ``t`` (s)."""
        return float(np.min(self.x[:, 1])) + self.speed * t if np.isfinite(self.speed) else np.inf

    def walls(self, wall: Boundary | None, t: float, clear: float = np.inf) -> Boundary | None:
        """``wall`` with the gate's particles added as they are at time ``t`` (s), unless the
        gate's bottom is above ``clear`` (m; then ``wall`` alone)."""
        if not np.isfinite(self.speed) or self.bottom(t) > clear:
            return wall
        v = np.zeros_like(self.x)
        v[:, 1] = self.speed
        if wall is None:
            return Boundary(self.x + self.offset(t), self.psi, v)
        return Boundary(np.concatenate([wall.x, self.x + self.offset(t)]),
                        np.concatenate([wall.psi, self.psi]), np.concatenate([wall.v, v]))


def gate(at: float, height: float, spacing: float, rho0: float, h: float, kernel: str = "cubic",
         speed: float = np.inf, layers: int | None = None) -> Gate:
    """A vertical gate ``height`` m tall whose face is the line ``x = at`` (m), with the
    fluid at ``x < at``: ``layers`` columns (default :func:`layers_needed`) at
    ``at + (k + 1/2) Δx``, rows at ``(j + 1/2) Δx`` from the floor, continuing the fluid's
    lattice, each particle weighing ``ρ₀`` times :func:`lattice_volume`; lifted at ``speed``."""
    layers = layers_needed(spacing, h, kernel) if layers is None else int(layers)
    xs = at + (np.arange(layers) + 0.5) * spacing
    ys = (np.arange(int(np.ceil(height / spacing))) + 0.5) * spacing
    x = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    return Gate(x, rho0 * lattice_volume(spacing, h, kernel, 2), float(speed))
