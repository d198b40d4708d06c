"""Damped Hooke springs between particles, and the networks built from them.

A spring ``s`` joins particles ``i[s]`` and ``j[s]`` with rest length ``L``, stiffness
``k`` (N/m) and damping ``c`` (N s/m) along the spring. With ``d = x_i - x_j``,
``ℓ = |d|`` and unit vector ``u = d / ℓ``, the force on ``i`` is

    F_i = -[k (ℓ - L) + c (v_i - v_j)·u] u,        F_j = -F_i,

Hooke's law in 3D plus damping of the stretching rate only (rigid motions are not
damped). Forces are gathered onto particles with a sparse incidence matrix, so a network
of any size costs a few vectorized operations and no Python loop over springs. Because
each spring pushes its two ends equally and oppositely along the line joining them, the
internal forces sum to zero (momentum) and exert no net torque (angular momentum).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from . import _validate


@dataclass
class SpringNetwork:
    """A set of springs over ``n_particles`` particles.

    Attributes
    ----------
    i, j : ndarray of int, shape (M,)
        End points of each spring.
    rest : ndarray, shape (M,)
        Rest lengths (m).
    k : ndarray, shape (M,)
        Stiffnesses (N/m).
    c : ndarray, shape (M,)
        Damping along the spring (N s/m).
    n_particles : int
        Number of particles.
    kind : ndarray of str, shape (M,)
        A label per spring (``"edge"``, ``"bend"``, ``"twist"``, ``"shear"``, ...).
    """

    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    c: np.ndarray
    n_particles: int
    kind: np.ndarray = field(default_factory=lambda: np.array([], dtype=str))
    _incidence: sp.csr_matrix | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        self.i = np.asarray(self.i, dtype=int)
        self.j = np.asarray(self.j, dtype=int)
        m = self.i.shape[0]
        if self.i.shape != (m,) or self.j.shape != (m,):
            raise ValueError(f"i and j must be 1-D of equal length, got {self.i.shape}, {self.j.shape}")
        for name in ("rest", "k", "c"):
            arr = np.broadcast_to(np.asarray(getattr(self, name), dtype=float), (m,)).copy()
            if not np.all(np.isfinite(arr)) or np.any(arr < 0):
                raise ValueError(f"{name} must be finite and >= 0 for every spring")
            setattr(self, name, arr)
        if m and (min(self.i.min(), self.j.min()) < 0
                  or max(self.i.max(), self.j.max()) >= self.n_particles):
            raise ValueError(f"spring end indices must lie in [0, {self.n_particles})")
        if m and np.any(self.i == self.j):
            raise ValueError("a spring must join two different particles (i != j)")
        if self.kind.size == 0:
            self.kind = np.full(m, "spring")
        # Incidence matrix D (n_particles × M): +1 at (i_s, s), -1 at (j_s, s), so the
        # particle forces are D @ (force on i of each spring).
        cols = np.arange(m)
        self._incidence = sp.csr_matrix(
            (np.r_[np.ones(m), -np.ones(m)], (np.r_[self.i, self.j], np.r_[cols, cols])),
            shape=(self.n_particles, m),
        )

    @property
    def n_springs(self) -> int:
        return self.i.shape[0]

    def select(self, kinds) -> SpringNetwork:
        """The sub-network of springs whose ``kind`` is in ``kinds``."""
        keep = np.isin(self.kind, np.atleast_1d(kinds))
        return SpringNetwork(self.i[keep], self.j[keep], self.rest[keep], self.k[keep],
                             self.c[keep], self.n_particles, self.kind[keep])

    def with_stiffness(self, **k_by_kind: float) -> SpringNetwork:
        """A copy with the stiffness of each named kind replaced, e.g. ``bend=5.0``."""
        k = self.k.copy()
        for kind, value in k_by_kind.items():
            k[self.kind == kind] = value
        return SpringNetwork(self.i, self.j, self.rest, k, self.c, self.n_particles, self.kind)

    def lengths(self, x) -> np.ndarray:
        """Current spring lengths ``|x_i - x_j|`` (m), shape ``(M,)`` (or ``(n, M)``)."""
        x = np.asarray(x)
        return np.linalg.norm(x[..., self.i, :] - x[..., self.j, :], axis=-1)

    def strain(self, x) -> np.ndarray:
        """Relative stretch ``(ℓ - L) / L`` of each spring."""
        return self.lengths(x) / self.rest - 1.0

    def spring_forces(self, x, v=None) -> np.ndarray:
        """Force on the ``i`` end of each spring (N), shape ``(M, d)``."""
        d = x[self.i] - x[self.j]
        length = np.linalg.norm(d, axis=1)
        u = d / length[:, None]
        magnitude = self.k * (length - self.rest)
        if v is not None and np.any(self.c):
            magnitude = magnitude + self.c * np.einsum("md,md->m", v[self.i] - v[self.j], u)
        return -magnitude[:, None] * u

    def forces(self, x, v=None) -> np.ndarray:
        """Net spring force on every particle (N), shape ``(N, d)``.

        Parameters
        ----------
        x : ndarray, shape (N, d)
            Positions (m).
        v : ndarray, shape (N, d), optional
            Velocities (m/s); needed only for damping.
        """
        x = np.asarray(x, dtype=float)
        if x.ndim != 2 or x.shape[0] != self.n_particles:
            raise ValueError(f"x must have shape ({self.n_particles}, d), got {x.shape}")
        return np.asarray(self._incidence @ self.spring_forces(x, v))

    def force(self, t, x, v) -> np.ndarray:
        """``F(t, x, v)`` form of :meth:`forces`, for :class:`~course_lib.systems.NewtonianSystem`."""
        return self.forces(x, v)

    def energy(self, x) -> np.ndarray:
        """Elastic energy ``Σ ½ k (ℓ - L)²`` (J); ``x`` may be ``(N, d)`` or ``(n, N, d)``."""
        return 0.5 * np.sum(self.k * (self.lengths(x) - self.rest) ** 2, axis=-1)


def chain_pairs(n: int, offset: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs ``(i, i + offset)`` along a chain of ``n`` particles.

    ``offset=1`` gives the edges, 2 the bending springs, 3 the torsion springs of
    Selle, Lentine & Fedkiw (2008).
    """
    if not isinstance(n, int | np.integer) or n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    if not isinstance(offset, int | np.integer) or offset < 1:
        raise ValueError(f"offset must be an integer >= 1, got {offset!r}")
    i = np.arange(max(n - offset, 0))
    return i, i + offset


def hair_chain(
    n: int = 12,
    length: float = 0.3,
    k_edge: float = 500.0,
    k_bend: float = 0.0,
    k_twist: float = 0.0,
    c_edge: float = 0.0,
    c_bend: float = 0.0,
    root=(0.0, 0.0, 0.0),
    direction=(1.0, 0.0, 0.0),
    curl: float = 0.0,
    zigzag: float = 0.0,
) -> tuple[np.ndarray, SpringNetwork]:
    """A strand of ``n`` particles joined by edge springs (i, i+1), bending springs (i, i+2)
    and, optionally, torsion springs (i, i+3).

    Parameters
    ----------
    n : int
        Number of particles (>= 2); particle 0 is the root.
    length : float
        Total rest length of the strand (m).
    k_edge, k_bend, k_twist : float
        Stiffness of the three families (N/m); a family with zero stiffness is omitted.
    c_edge, c_bend : float
        Damping along edge and bending springs (N s/m).
    root : array_like, shape (3,)
        Position of particle 0 (m).
    direction : array_like, shape (3,)
        Direction in which the strand is laid out straight.
    curl : float
        Turn angle (rad) between successive segments in the plane of ``direction`` and
        ``y``: 0 lays the strand straight; a small curl gives the bending springs a
        curved rest shape (rest lengths are measured on the initial shape).
    zigzag : float
        Offset of every odd particle along the side direction, in units of the segment
        length: a non-zero zigzag makes the rest shape non-collinear, so the bending
        springs resist bending to first order (on a straight strand they do not).

    Returns
    -------
    x0 : ndarray, shape (n, 3)
        Rest positions (m).
    network : SpringNetwork
        The springs, labelled ``"edge"``, ``"bend"`` and ``"twist"``.
    """
    if not isinstance(n, int | np.integer) or n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    length = _validate.positive_finite("length", length)
    seg = length / (n - 1)
    d = _validate.shape_of("direction", _validate.state_array("direction", direction), (3,))
    d = d / np.linalg.norm(d)
    up = np.array([0.0, 1.0, 0.0]) if abs(d[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    side = up - d * (up @ d)
    side /= np.linalg.norm(side)
    angles = curl * np.arange(n - 1)
    steps = seg * (np.cos(angles)[:, None] * d + np.sin(angles)[:, None] * side)
    x0 = np.asarray(root, dtype=float) + np.vstack([np.zeros(3), np.cumsum(steps, axis=0)])
    x0[1::2] += zigzag * seg * side
    families = [(1, k_edge, c_edge, "edge"), (2, k_bend, c_bend, "bend"), (3, k_twist, 0.0, "twist")]
    ii, jj, kk, cc, kinds = [], [], [], [], []
    for offset, k, c, name in families:
        if k > 0 and n > offset:
            i, j = chain_pairs(n, offset)
            ii.append(i)
            jj.append(j)
            kk.append(np.full(i.size, float(k)))
            cc.append(np.full(i.size, float(c)))
            kinds.append(np.full(i.size, name))
    i, j = np.concatenate(ii), np.concatenate(jj)
    rest = np.linalg.norm(x0[i] - x0[j], axis=1)
    net = SpringNetwork(i, j, rest, np.concatenate(kk), np.concatenate(cc), n, np.concatenate(kinds))
    return x0, net


def cloth_grid(
    nx: int = 10,
    ny: int = 10,
    spacing: float = 0.1,
    k_struct: float = 1000.0,
    k_shear: float = 100.0,
    k_bend: float = 10.0,
    c: float = 0.0,
) -> tuple[np.ndarray, SpringNetwork]:
    """A rectangular cloth of ``nx × ny`` particles in the x-y plane (z = 0).

    Particle ``(r, q)`` (row ``r`` along y, column ``q`` along x) has index ``r * nx + q``.
    Structural springs join grid neighbours, shear springs the diagonals of each cell, bend
    springs particles two apart along rows and columns.

    Returns
    -------
    x0 : ndarray, shape (nx * ny, 3)
        Rest positions (m).
    network : SpringNetwork
        Springs labelled ``"struct"``, ``"shear"``, ``"bend"``.
    """
    if nx < 2 or ny < 2:
        raise ValueError(f"nx and ny must be >= 2, got {nx}, {ny}")
    spacing = _validate.positive_finite("spacing", spacing)
    idx = np.arange(nx * ny).reshape(ny, nx)
    gx, gy = np.meshgrid(np.arange(nx) * spacing, np.arange(ny) * spacing)
    x0 = np.stack((gx.ravel(), gy.ravel(), np.zeros(nx * ny)), axis=1)
    groups = {
        "struct": (np.r_[idx[:, :-1].ravel(), idx[:-1, :].ravel()],
                   np.r_[idx[:, 1:].ravel(), idx[1:, :].ravel()], k_struct),
        "shear": (np.r_[idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()],
                  np.r_[idx[1:, 1:].ravel(), idx[1:, :-1].ravel()], k_shear),
        "bend": (np.r_[idx[:, :-2].ravel(), idx[:-2, :].ravel()],
                 np.r_[idx[:, 2:].ravel(), idx[2:, :].ravel()], k_bend),
    }
    ii, jj, kk, kinds = [], [], [], []
    for name, (i, j, k) in groups.items():
        if k > 0 and i.size:
            ii.append(i)
            jj.append(j)
            kk.append(np.full(i.size, float(k)))
            kinds.append(np.full(i.size, name))
    i, j = np.concatenate(ii), np.concatenate(jj)
    rest = np.linalg.norm(x0[i] - x0[j], axis=1)
    return x0, SpringNetwork(i, j, rest, np.concatenate(kk), c, nx * ny, np.concatenate(kinds))


def spring_force_pair(x1, x2, k: float, rest: float) -> np.ndarray:
    """Hooke force on particle 1 of a single spring: ``-k (|x1 - x2| - L) (x1 - x2)/|x1 - x2|``."""
    d = np.asarray(x1, dtype=float) - np.asarray(x2, dtype=float)
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    return -k * (length - rest) * d / length


# --- linearization, damping and time-step limits ----------------------------------------


def stiffness_matrix(network: SpringNetwork, x) -> np.ndarray:
    """Hessian ``K = ∂²E/∂x²`` of the elastic energy at positions ``x`` (N/m).

    For a spring with unit vector ``u`` and length ``ℓ``, the block of particle ``i`` is
    ``K_s = k [u uᵀ + (1 - L/ℓ)(I - u uᵀ)]``; ``(j, j)`` gets ``K_s`` too and the two
    off-diagonal blocks ``-K_s``. Small motions ``δx`` about ``x`` feel ``δF = -K δx``.

    Returns
    -------
    ndarray, shape (N d, N d)
        Dense and symmetric; row ``a d + p`` is component ``p`` of particle ``a``.
    """
    x = np.asarray(x, dtype=float)
    n, d = x.shape
    diff = x[network.i] - x[network.j]
    length = np.linalg.norm(diff, axis=1)
    u = diff / length[:, None]
    uu = u[:, :, None] * u[:, None, :]
    eye = np.eye(d)[None]
    blocks = network.k[:, None, None] * (uu + (1.0 - network.rest / length)[:, None, None] * (eye - uu))
    K = np.zeros((n, n, d, d))
    np.add.at(K, (network.i, network.i), blocks)
    np.add.at(K, (network.j, network.j), blocks)
    np.add.at(K, (network.i, network.j), -blocks)
    np.add.at(K, (network.j, network.i), -blocks)
    return K.transpose(0, 2, 1, 3).reshape(n * d, n * d)


def max_frequency(network: SpringNetwork, x, mass, pinned=None) -> float:
    """Highest angular frequency ``ω_max`` (rad/s) of small oscillations about ``x``.

    The square roots of the eigenvalues of ``M^{-1/2} K M^{-1/2}`` over the free (not
    pinned) particles. An explicit method is stable while ``ω_max dt`` stays inside its
    stability interval, e.g. ``dt <= 2 / ω_max`` for symplectic Euler.
    """
    x = np.asarray(x, dtype=float)
    n, d = x.shape
    K = stiffness_matrix(network, x)
    m = np.broadcast_to(np.asarray(mass, dtype=float), (n,))
    free = np.setdiff1d(np.arange(n), np.asarray([] if pinned is None else pinned, dtype=int))
    dofs = (free[:, None] * d + np.arange(d)).ravel()
    w = 1.0 / np.sqrt(np.repeat(m[free], d))
    A = K[np.ix_(dofs, dofs)] * w[:, None] * w[None, :]
    return float(np.sqrt(max(np.linalg.eigvalsh(A).max(), 0.0)))


def chain_max_frequency(n_free: int, k: float, m: float) -> float:
    """Exact ``ω_max`` of a chain of ``n_free`` equal masses ``m`` joined by equal springs
    ``k`` and fixed at one end (longitudinal motion): ``2 √(k/m) sin((2N-1)π / (4N+2))``.
    Tends to ``2 √(k/m)`` as the chain grows."""
    return float(2.0 * np.sqrt(k / m) * np.sin((2 * n_free - 1) * np.pi / (4 * n_free + 2)))


def critical_damping(k: float, m: float) -> float:
    """Damping ``c = 2 √(k m)`` (N s/m) at which a mass ``m`` on a spring ``k`` returns to
    rest fastest without oscillating."""
    return float(2.0 * np.sqrt(_validate.positive_finite("k", k) * _validate.positive_finite("m", m)))


def damped_oscillator(t, k: float, m: float, c: float = 0.0, x0: float = 1.0, v0: float = 0.0,
                      velocity: bool = False):
    """Exact displacement ``x(t)`` (or velocity, with ``velocity=True``) of
    ``m x'' + c x' + k x = 0`` with ``x(0) = x0``, ``x'(0) = v0``.

    Under-damped (``c < 2√(km)``) it oscillates inside a decaying envelope, critically
    damped it is ``(x0 + (v0 + ω x0) t) e^{-ω t}`` with ``ω = √(k/m)``, over-damped it
    is a sum of two decaying exponentials.
    """
    t = np.asarray(t, dtype=float)
    omega = np.sqrt(k / m)
    zeta = c / (2.0 * np.sqrt(k * m))
    if np.isclose(zeta, 1.0, rtol=1e-12, atol=0.0):
        b = v0 + omega * x0
        if velocity:
            return (b - omega * (x0 + b * t)) * np.exp(-omega * t)
        return (x0 + b * t) * np.exp(-omega * t)
    root = np.sqrt(complex(zeta**2 - 1.0))
    r1, r2 = omega * (-zeta + root), omega * (-zeta - root)
    a = (v0 - r2 * x0) / (r1 - r2)
    if velocity:
        return np.real(a * r1 * np.exp(r1 * t) + (x0 - a) * r2 * np.exp(r2 * t))
    return np.real(a * np.exp(r1 * t) + (x0 - a) * np.exp(r2 * t))


def anchored_spring(k: float, m: float = 1.0, c: float = 0.0, rest: float = 1.0, stretch: float = 0.1):
    """A mass ``m`` on a damped spring tied to a fixed anchor, in 3D.

    The anchor is particle 0 (pinned, at the origin); the mass is particle 1, released at
    rest at ``(rest + stretch, 0, 0)``. Along the spring this is the 1D oscillator
    ``m x'' = -k x - c x'`` for the stretch ``x``.

    Returns
    -------
    system : NewtonianSystem
    y0 : ndarray, shape (2, 2, 3)
    network : SpringNetwork
    """
    from .systems import NewtonianSystem, stack_state

    net = SpringNetwork([1], [0], [rest], [k], [c], 2, np.array(["spring"]))
    x0 = np.array([[0.0, 0.0, 0.0], [rest + stretch, 0.0, 0.0]])
    return NewtonianSystem(net.force, m, pinned=[0]), stack_state(x0, np.zeros_like(x0)), net
