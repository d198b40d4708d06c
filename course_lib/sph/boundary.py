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
by a fluid particle's mass ``ρ₀ V`` (:func:`lattice_volume`, :func:`box`). Core module.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from .kernels import KERNELS, SUPPORT, check_name


@dataclass
class Boundary:
    """Fixed wall particles: positions ``x`` (K, dim), m, and weights ``psi`` (K,), kg."""

    x: np.ndarray
    psi: np.ndarray
    tree: cKDTree = field(init=False, repr=False)

    def __post_init__(self):
        self.x = np.asarray(self.x, dtype=float)
        self.psi = np.broadcast_to(np.asarray(self.psi, dtype=float), (len(self.x),)).copy()
        if self.x.ndim != 2:
            raise ValueError(f"wall positions x must have shape (K, dim), got {self.x.shape}")
        if not np.all(np.isfinite(self.x)) or not np.all(self.psi > 0):
            raise ValueError("wall positions must be finite and weights psi positive")
        self.tree = cKDTree(self.x)

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
