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

Speed: :meth:`SpringNetwork.forces` is the version students read *and* the fast one: a
few whole-array operations, no Python loop over springs. It reuses preallocated work
arrays (a fresh large array on every call costs page faults), and a
:class:`~course_lib.springs.layout.SpringLayout` decides where each spring's numbers live:
chains and grids as contiguous *bands* of springs a fixed index offset apart (shifted
slices, no gather), anything else gathered with ``np.take`` and summed with a sparse
incidence matrix.

Solvers use three public methods and nothing below them: :meth:`SpringNetwork.forces`
(and :meth:`~SpringNetwork.potential`, energy and forces at once),
:meth:`~SpringNetwork.linearize` (Jacobian–vector products, see
:mod:`course_lib.springs.linearization`) and :meth:`~SpringNetwork.project` (each spring
projected onto its rest length, see :mod:`course_lib.springs.projection`).

Core module: imports NumPy and :mod:`course_lib.springs.layout` only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .layout import SpringLayout, sum_rows
from .pair import spring_force_pair  # noqa: F401  (its historical home)


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
    """Preallocated work arrays for one evaluation in ``dim`` dimensions.

    Per-slot vectors are component-major, shape ``(dim, S)``: one contiguous row per
    component, so every operation runs over long rows (an ``(S, 3)`` layout would make
    NumPy loop over rows of three).
    """

    def __init__(self, layout: SpringLayout, dim: int):
        s, g = layout.n_slots, layout.lo.size
        self.rows = np.empty((dim, layout.n))      # x (or v) transposed: one row per component
        self.total = np.empty((dim, layout.n))     # per-particle sums, transposed
        self.gather = (self.rows, np.empty((dim, g)), np.empty((dim, g)))   # the two ends
        self.d = np.empty((dim, s))                # x_lo - x_hi in every slot
        self.rel = np.empty((dim, s))              # v_lo - v_hi
        self.f = np.empty((dim, s))
        self.length = np.empty(s)
        self.inv = np.empty(s)                     # 1/ℓ, or 0 where the ends coincide
        self.coef = np.empty(s)                    # a: force on the lo end is -a d
        self.rate = np.empty(s)                    # (v_lo - v_hi)·d


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
    arrays are read-only: the network lays its springs out once for fast force evaluation,
    so change springs by building another network (:meth:`with_stiffness`,
    :meth:`select`). It keeps work arrays for :meth:`forces`, so one network should not be
    used from two threads at once.
    """

    i: np.ndarray
    j: np.ndarray
    rest: np.ndarray
    k: np.ndarray
    c: np.ndarray
    n_particles: int
    kind: np.ndarray | None = None
    layout: SpringLayout = field(init=False, repr=False, compare=False)
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
        self.layout = SpringLayout(self.i, self.j, self.n_particles)
        # Parameters per slot (0 in unused slots of a band: no force there).
        self.slot_rest, self.slot_k, self.slot_c = (
            self.layout.to_slots(a) for a in (self.rest, self.k, self.c))
        self._work = {}
        self._damped = bool(self.c.any())
        for arr in (self.i, self.j, self.rest, self.k, self.c, self.kind):
            arr.setflags(write=False)

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

    def _workspace(self, dim: int) -> _Work:
        if dim not in self._work:
            self._work[dim] = _Work(self.layout, dim)
        return self._work[dim]

    def slot_differences(self, p, out: np.ndarray | None = None) -> np.ndarray:
        """``p_lo - p_hi`` in every slot of :attr:`layout` for per-particle values ``p``
        of shape ``(N, d)``; returned component-major, shape ``(d, S)``."""
        p = self._check("p", p)
        w = self._workspace(p.shape[1])
        if out is None:
            out = np.empty((p.shape[1], self.layout.n_slots))
        np.copyto(w.rows, p.T)                     # (d, N): whole contiguous rows
        return self.layout.differences(w.rows, out, w.gather)

    def slot_sums(self, f, same_sign: bool = False, out: np.ndarray | None = None) -> np.ndarray:
        """Per-particle sums ``(N, d)`` of per-slot vectors ``f`` of shape ``(d, S)``:
        ``+f`` at each ``lo`` end and ``-f`` at each ``hi`` end (``+f`` at both with
        ``same_sign=True``)."""
        w = self._workspace(f.shape[0])
        total = self.layout.accumulate(f, w.total, same_sign)    # (d, N), contiguous
        if out is None:
            return total.T.copy()
        np.copyto(out, total.T)
        return out

    def slot_coefficients(self, x, v=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per slot of :attr:`layout`: ``d = x_lo - x_hi`` (component-major, ``(dim, S)``),
        the inverse length ``1/ℓ`` (0 where the ends coincide) and the factor ``a`` of the
        force ``-a d`` on the ``lo`` end. Work arrays, overwritten by the next call."""
        x = self._check("x", x)
        w = self._workspace(x.shape[1])
        d = self.slot_differences(x, out=w.d)
        # ℓ = |d| and 1/ℓ; where ℓ = 0 the direction is undefined and we take 1/ℓ = 0.
        np.multiply(d, d, out=w.f)
        sum_rows(w.f, out=w.length)                # sum over the components
        np.sqrt(w.length, out=w.length)
        with np.errstate(divide="ignore"):
            np.divide(1.0, w.length, out=w.inv)
        if not w.length.min() > 0.0:
            w.inv[w.length == 0.0] = 0.0
        # a = k (ℓ - L) / ℓ
        np.subtract(w.length, self.slot_rest, out=w.coef)
        w.coef *= self.slot_k
        w.coef *= w.inv
        if v is not None and self._damped:
            # + c (v_lo - v_hi)·d / ℓ²: damping of the stretching rate only
            rel = self.slot_differences(self._check("v", v), out=w.rel)
            np.multiply(rel, d, out=w.f)
            sum_rows(w.f, out=w.rate)
            w.rate *= w.inv
            w.rate *= w.inv
            w.rate *= self.slot_c
            w.coef += w.rate
        return d, w.inv, w.coef

    def spring_coefficients(self, x, v=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per spring, in the order of ``i, j``: ``d = x_i - x_j`` (shape ``(M, d)``), the
        inverse length ``1/ℓ`` (0 where the ends coincide) and ``a`` (force on ``i`` is
        ``-a d``). New arrays."""
        d, inv, a = self.slot_coefficients(x, v)
        slot = self.layout.slot
        return (d[:, slot] * self.layout.sign).T, inv[slot], a[slot]

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
        d, _, a = self.slot_coefficients(x, v)
        w = self._work[d.shape[0]]
        np.multiply(d, a, out=w.f)                 # a d = minus the force on each lo end
        total = self.slot_sums(w.f, out=out)       # sum over the springs at each particle
        return np.negative(total, out=total)

    def force(self, t, x, v) -> np.ndarray:
        """``F(t, x, v)`` form of :meth:`forces`, for :class:`~course_lib.systems.NewtonianSystem`."""
        return self.forces(x, v)

    # --- the interface of the solvers: forces, Jacobian–vector products, projections ---

    def potential(self, x) -> tuple[float, np.ndarray]:
        """Elastic energy (J) and spring forces ``(N, d)`` (N) at positions ``x``, in one pass."""
        from .projection import elastic_energy_slots

        return elastic_energy_slots(self, x)

    def linearize(self, x, v=None, *, definite: bool = True):
        """The network linearized about ``(x, v)``: its force and products with ``K = -∂F/∂x``
        and ``C = -∂F/∂v`` (a :class:`~course_lib.springs.linearization.Linearization`)."""
        from .linearization import Linearization

        return Linearization(self, x, v, definite=definite)

    def project(self, x) -> np.ndarray:
        """Each spring projected onto its rest length, ``L u``, shape ``(M, d)`` (see
        :mod:`course_lib.springs.projection`)."""
        from .projection import rest_projection

        return rest_projection(self, x)
