"""The spring network: damped Hooke springs between particles, and their forces.

A spring ``s`` joins particles ``i[s]`` and ``j[s]`` with rest length ``L``, stiffness
``k`` (N/m) and damping ``c`` (N s/m) along the spring. With ``d = x_i - x_j``,
``ℓ = |d|`` and unit vector ``u = d / ℓ``, the force on ``i`` is

    F_i = -[k (ℓ - L) + c (v_i - v_j)·u] u  =  -a d,   a = k (ℓ - L)/ℓ + c (v_i - v_j)·d / ℓ²,

and ``F_j = -F_i``: Hooke's law in 3D plus damping of the stretching rate only (rigid
motions are not damped). Because each spring pushes its two ends equally and oppositely
along the line joining them, the internal forces sum to zero and exert no net torque.

Where the two ends coincide (``ℓ = 0``) the direction ``u`` is undefined; we take
``1/ℓ = 0`` there, so the spring exerts no force. For a zero-rest-length spring that is
exact (its force ``-k d`` vanishes with ``d``); for ``L > 0`` it is our choice of a finite
answer (the true force jumps there: any direction, magnitude ``k L``).

Speed: :meth:`SpringNetwork.forces` is the version students read *and* the fast one. It
reuses preallocated, contiguous work arrays (fresh large arrays on every call cost page
faults), gathers both ends with ``np.take`` and adds the spring forces onto particles with
a sparse incidence matrix: a few whole-array operations, no Python loop over springs.

Core module: imports NumPy and SciPy only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp


def _index_array(name: str, value) -> np.ndarray:
    arr = np.asarray(value)
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise TypeError(f"{name} must hold integer particle indices, got dtype {arr.dtype}")
    arr = arr.astype(np.intp)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D (one index per spring), got shape {arr.shape}")
    return arr


def _kind_array(kind, m: int) -> np.ndarray:
    if kind is None or (np.ndim(kind) == 1 and len(kind) == 0 and m > 0):
        return np.full(m, "spring")
    arr = np.asarray(kind)
    if arr.ndim != 1 or arr.shape[0] != m:
        raise ValueError(f"kind must be a 1-D list of one label per spring ({m}), got shape "
                         f"{arr.shape}")
    if m and arr.dtype.kind != "U":
        raise TypeError(f"kind must hold strings such as 'edge' or 'bend', got dtype {arr.dtype}")
    return arr.astype(str)


class _Work:
    """Preallocated, contiguous arrays for one force evaluation in ``dim`` dimensions.

    ``state``, ``end_i``, ``end_j`` and ``diff`` come in two widths over the same memory:
    ``dim`` columns (positions only) and ``2 dim`` (positions and velocities side by side,
    so one gather fetches both).
    """

    def __init__(self, net: SpringNetwork, dim: int):
        m, n = net.n_springs, net.n_particles
        self.dim = dim

        def widths(rows):
            flat = np.empty(rows * 2 * dim)
            return {c: flat[: rows * c].reshape(rows, c) for c in (dim, 2 * dim)}

        self.state = widths(n)                     # [x | v], one row per particle
        self.end_i = widths(m)                     # [x_i | v_i] of every spring
        self.end_j = widths(m)
        self.diff = widths(m)                      # [d | v_i - v_j]
        self.prod = np.empty((m, dim))
        self.ones = np.ones(dim)
        self.length = np.empty(m)
        self.inv = np.empty(m)                     # 1/ℓ, or 0 where the ends coincide
        self.coef = np.empty(m)                    # a: force on i is -a d
        self.rate = np.empty(m)                    # (v_i - v_j)·d
        self.f = np.empty((m, dim))


@dataclass
class SpringNetwork:
    """A set of springs over ``n_particles`` particles.

    Attributes
    ----------
    i, j : ndarray of int, shape (M,)
        End points of each spring (``i != j``).
    rest : ndarray, shape (M,)
        Rest lengths (m), >= 0.
    k : ndarray, shape (M,)
        Stiffnesses (N/m), >= 0.
    c : ndarray, shape (M,)
        Damping along the spring (N s/m), >= 0.
    n_particles : int
        Number of particles.
    kind : ndarray of str, shape (M,)
        A label per spring (``"edge"``, ``"bend"``, ``"shear"``, ...); ``"spring"`` if
        omitted.

    Notes
    -----
    ``rest``, ``k`` and ``c`` may be given as scalars (one value for every spring). The
    network keeps work arrays for :meth:`forces`, so one network should not be used from
    two threads at once.
    """

    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    c: np.ndarray
    n_particles: int
    kind: np.ndarray | None = None
    _incidence: sp.csr_matrix = field(init=False, repr=False, compare=False)
    _work: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        self.i = _index_array("i", self.i)
        self.j = _index_array("j", self.j)
        m = self.i.shape[0]
        if self.j.shape != (m,):
            raise ValueError(f"i and j must have equal length, got {self.i.shape} and {self.j.shape}")
        if isinstance(self.n_particles, bool) or not isinstance(self.n_particles, int | np.integer):
            raise TypeError(f"n_particles must be an integer, got {self.n_particles!r}")
        if self.n_particles < 1:
            raise ValueError(f"n_particles must be >= 1, got {self.n_particles}")
        self.n_particles = int(self.n_particles)
        for name in ("rest", "k", "c"):
            value = np.asarray(getattr(self, name), dtype=float)
            try:
                arr = np.broadcast_to(value, (m,)).copy()
            except ValueError:
                raise ValueError(f"{name} must be a scalar or have one entry per spring ({m}), "
                                 f"got shape {value.shape}") from None
            if not np.all(np.isfinite(arr)) or np.any(arr < 0):
                raise ValueError(f"{name} must be finite and >= 0 for every spring")
            setattr(self, name, arr)
        if m and (min(self.i.min(), self.j.min()) < 0
                  or max(self.i.max(), self.j.max()) >= self.n_particles):
            raise ValueError(f"spring end indices i, j must lie in [0, {self.n_particles})")
        if m and np.any(self.i == self.j):
            raise ValueError("a spring must join two different particles (i != j)")
        self.kind = _kind_array(self.kind, m)
        # Incidence matrix Dᵀ (n_particles × M): +1 at (i_s, s), -1 at (j_s, s). The net
        # force on the particles is Dᵀ @ (force on the i end of each spring).
        cols = np.arange(m)
        self._incidence = sp.csr_matrix(
            (np.r_[np.ones(m), -np.ones(m)], (np.r_[self.i, self.j], np.r_[cols, cols])),
            shape=(self.n_particles, m),
        )
        self._work = {}

    @property
    def n_springs(self) -> int:
        """Number of springs ``M``."""
        return self.i.shape[0]

    def select(self, kinds) -> SpringNetwork:
        """The sub-network of springs whose ``kind`` is in ``kinds`` (a label or a list)."""
        keep = np.isin(self.kind, np.atleast_1d(kinds))
        return SpringNetwork(self.i[keep], self.j[keep], self.rest[keep], self.k[keep],
                             self.c[keep], self.n_particles, self.kind[keep])

    def with_stiffness(self, **k_by_kind: float) -> SpringNetwork:
        """A copy with the stiffness of each named kind replaced, e.g. ``bend=5.0``."""
        k = self.k.copy()
        for kind, value in k_by_kind.items():
            if kind not in self.kind:
                raise ValueError(f"no spring of kind {kind!r}; kinds are {sorted(set(self.kind))}")
            k[self.kind == kind] = value
        return SpringNetwork(self.i, self.j, self.rest, k, self.c, self.n_particles, self.kind)

    def lengths(self, x) -> np.ndarray:
        """Current spring lengths ``|x_i - x_j|`` (m), shape ``(M,)`` (or ``(n, M)``)."""
        x = np.asarray(x)
        return np.linalg.norm(x[..., self.i, :] - x[..., self.j, :], axis=-1)

    def strain(self, x) -> np.ndarray:
        """Relative stretch ``(ℓ - L) / L`` of each spring (needs ``L > 0``)."""
        return self.lengths(x) / self.rest - 1.0

    def energy(self, x) -> np.ndarray:
        """Elastic energy ``Σ ½ k (ℓ - L)²`` (J); ``x`` may be ``(N, d)`` or ``(n, N, d)``."""
        return 0.5 * np.sum(self.k * (self.lengths(x) - self.rest) ** 2, axis=-1)

    def _check(self, name: str, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.ndim != 2 or x.shape[0] != self.n_particles:
            raise ValueError(f"{name} must have shape ({self.n_particles}, d), got {x.shape}")
        return x

    def spring_coefficients(self, x, v=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per-spring ``(d, 1/ℓ, a)``: the difference ``x_i - x_j`` (M, d), the inverse
        length (0 where the ends coincide) and the force factor ``a`` (force on i is
        ``-a d``). Views of work arrays, overwritten by the next call."""
        x = self._check("x", x)
        dim = x.shape[1]
        w = self._work.get(dim) or self._work.setdefault(dim, _Work(self, dim))
        damped = v is not None and bool(np.any(self.c))
        cols = 2 * dim if damped else dim
        state, end_i, end_j, diff = w.state[cols], w.end_i[cols], w.end_j[cols], w.diff[cols]
        state[:, :dim] = x
        if damped:
            state[:, dim:] = self._check("v", v)
        # Gather both ends of every spring (positions, and velocities when damped).
        np.take(state, self.i, axis=0, out=end_i, mode="clip")
        np.take(state, self.j, axis=0, out=end_j, mode="clip")
        np.subtract(end_i, end_j, out=diff)
        d = diff[:, :dim]
        # ℓ = |d| and 1/ℓ; where ℓ = 0 the direction is undefined and we take 1/ℓ = 0.
        np.multiply(d, d, out=w.prod)
        np.matmul(w.prod, w.ones, out=w.length)
        np.sqrt(w.length, out=w.length)
        np.divide(1.0, w.length, out=w.inv, where=w.length > 0.0)
        w.inv[w.length == 0.0] = 0.0
        # a = k (ℓ - L) / ℓ  [+ c (v_i - v_j)·d / ℓ²]
        np.subtract(w.length, self.rest, out=w.coef)
        w.coef *= self.k
        w.coef *= w.inv
        if damped:
            np.multiply(diff[:, dim:], d, out=w.prod)
            np.matmul(w.prod, w.ones, out=w.rate)
            w.rate *= w.inv
            w.rate *= w.inv
            w.rate *= self.c
            w.coef += w.rate
        return d, w.inv, w.coef

    def spring_forces(self, x, v=None) -> np.ndarray:
        """Force on the ``i`` end of each spring (N), shape ``(M, d)`` (a new array)."""
        d, _, a = self.spring_coefficients(x, v)
        return -a[:, None] * d

    def forces(self, x, v=None, out: np.ndarray | None = None) -> np.ndarray:
        """Net spring force on every particle (N), shape ``(N, d)``.

        Parameters
        ----------
        x : ndarray, shape (N, d)
            Positions (m).
        v : ndarray, shape (N, d), optional
            Velocities (m/s); needed only for damping.
        out : ndarray, shape (N, d), optional
            Array to write the forces into (and return), to avoid allocating one.
        """
        d, _, a = self.spring_coefficients(x, v)
        w = self._work[d.shape[1]]
        np.multiply(d, a[:, None], out=w.f)        # a d: minus the force on each i end
        total = self._incidence @ w.f              # sum over the springs at each particle
        if out is None:
            return np.negative(total, out=total)
        return np.negative(total, out=out)

    def gather(self, p, out: np.ndarray | None = None) -> np.ndarray:
        """Per-spring differences ``p_i - p_j`` of a per-particle array ``p`` (N, d): shape
        ``(M, d)`` (the incidence matrix ``D`` applied to ``p``)."""
        p = self._check("p", p)
        dim = p.shape[1]
        w = self._work.get(dim) or self._work.setdefault(dim, _Work(self, dim))
        np.take(p, self.i, axis=0, out=w.end_i[dim], mode="clip")
        np.take(p, self.j, axis=0, out=w.end_j[dim], mode="clip")
        if out is None:
            out = np.empty((self.n_springs, dim))
        return np.subtract(w.end_i[dim], w.end_j[dim], out=out)

    def scatter(self, f, same_sign: bool = False) -> np.ndarray:
        """Per-particle sums of per-spring vectors ``f`` (M, d): ``+f`` at each ``i`` end
        and ``-f`` at each ``j`` end (``Dᵀ f``), or ``+f`` at both with ``same_sign=True``."""
        if same_sign:
            if "abs" not in self._work:
                self._work["abs"] = abs(self._incidence)
            return self._work["abs"] @ f
        return self._incidence @ f

    def force(self, t, x, v) -> np.ndarray:
        """``F(t, x, v)`` form of :meth:`forces`, for :class:`~course_lib.systems.NewtonianSystem`."""
        return self.forces(x, v)


def spring_force_pair(x1, x2, k: float, rest: float) -> np.ndarray:
    """Hooke force on particle 1 of a single spring: ``-k (|x1 - x2| - L) (x1 - x2)/|x1 - x2|``.

    Zero where the two ends coincide (the direction is undefined there).
    """
    d = np.asarray(x1, dtype=float) - np.asarray(x2, dtype=float)
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    inv = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0.0)
    return -k * (length - rest) * d * inv
