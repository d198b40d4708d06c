"""Contact by impulses: restitution and Coulomb friction, against the ground and between spheres.

A contact at the point ``p`` of a body (offset ``r = p − x`` from its centre of mass) with
normal ``n`` changes the body's velocity there by an impulse ``J``: ``Δv = J/m``,
``Δω = I⁻¹(r × J)``. The point's velocity ``u = v + ω × r`` changes along ``n`` by
``K_n j`` for ``J = j n``, with the *effective inverse mass*

    K_n = 1/m + n · ((I⁻¹ (r × n)) × r)

(plus the other body's terms in a two-body contact). Newton's law of restitution asks for
``u_n' = −e u_n``, so the normal impulse is ``j = −(1 + e) u_n / K_n`` (Baraff 2001;
Mirtich 1996; :func:`normal_impulse`). Coulomb friction caps the tangential impulse at
``μ j``: it stops the sliding if it can, else it takes ``μ j`` against the slip
(:func:`friction_impulse`).

Several simultaneous contacts are resolved by *sequential impulses* (Gauss–Seidel over the
contact points, clamping the accumulated impulse at zero and the friction to its cone;
Catto 2005, "Iterative dynamics with temporal coherence"), vectorized over the bodies.
:class:`Ground` is a plane for boxes (its eight corners) and spheres (their lowest point);
:class:`SpherePairs` handles spheres touching spheres. Both are ``contact(b, dt)``
callables for :func:`course_lib.rigid.body.step`, with a ``project(b)`` that moves
penetrating bodies back out. Imports NumPy and the core.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from .quaternion import cross, rotate
from .quaternion import hat as _hat

#: Penetration tolerated before positions are corrected, as a fraction of a body's size.
ALLOWED = 1e-3
CORNERS = np.array([[i, j, k] for i in (-0.5, 0.5) for j in (-0.5, 0.5) for k in (-0.5, 0.5)])


def normal_impulse(mass, inv_inertia, r, normal, v, omega, restitution: float):
    """Normal impulse ``j`` (N s, ≥ 0) that a static surface of unit ``normal`` gives a body of
    ``mass`` (kg), inverse world inertia ``inv_inertia`` (3, 3), velocity ``v`` and world
    angular velocity ``omega`` touching it at offset ``r`` (m) from its centre of mass:
    ``−(1 + e) u_n / K_n`` while the point approaches (``u_n < 0``), else 0.
    Vectorized over leading axes."""
    r, n = np.asarray(r, float), np.asarray(normal, float)
    u_n = np.sum((np.asarray(v, float) + cross(omega, r)) * n, axis=-1)
    rn = cross(r, n)
    k_n = 1.0 / np.asarray(mass, float) + np.einsum("...i,...ij,...j->...", rn, inv_inertia, rn)
    return np.where(u_n < 0, -(1.0 + restitution) * u_n / k_n, 0.0)


def friction_impulse(mass, inv_inertia, r, normal, v, omega, j_n, mu: float) -> np.ndarray:
    """Coulomb friction impulse ``J_t`` (N s, (3,)) at one contact, after its normal impulse
    ``j_n`` (N s): the contact point slides with ``u_t = u − (u·n) n``, ``u = v + ω × r``;
    the impulse ``−|u_t| / K_t`` along ``t = u_t/|u_t|``, with ``K_t = 1/m + t·((I⁻¹(r × t)) × r)``,
    stops it, if that takes at most ``μ j_n``; else friction takes ``μ j_n`` against the
    slip. Zero when the point does not slide. Arguments as in :func:`normal_impulse`."""
    r, n = np.asarray(r, float), np.asarray(normal, float)
    u = np.asarray(v, float) + np.cross(omega, r)
    u_t = u - (u @ n) * n
    speed = float(np.linalg.norm(u_t))
    if speed == 0.0:
        return np.zeros(3)
    t = u_t / speed
    rt = np.cross(r, t)
    k_t = 1.0 / mass + rt @ np.asarray(inv_inertia, float) @ rt
    return -min(speed / k_t, mu * j_n) * t


def _coefficients(restitution, friction, iterations, rest_speed):
    e = _validate.finite_real("restitution", restitution)
    mu = _validate.finite_real("friction", friction)
    if not 0 <= e <= 1:
        raise ValueError(f"restitution must lie in [0, 1], got {e}")
    if mu < 0:
        raise ValueError(f"friction must be >= 0, got {mu}")
    rest = _validate.finite_real("rest_speed", rest_speed)
    if rest < 0:
        raise ValueError(f"rest_speed must be >= 0 (m/s), got {rest}")
    return e, mu, _validate.positive_int("iterations", iterations), rest


def _mv(A, x):
    return (A @ x[..., None])[..., 0]


def _relative(v, w, i, j, ri, rj):
    """Velocity (m/s) of the contact points on bodies ``j`` relative to those on ``i``."""
    u = -v[i] - cross(w[i], ri)
    on = j >= 0
    u[on] += v[j[on]] + cross(w[j[on]], rj[on])
    return u


def _jacobian(i, j, ri, rj, n_bodies):
    """``G`` (3C, 6N): the relative velocity of every contact from the bodies' ``(v, ω)``,
    ``u = (v_j + ω_j × r_j) − (v_i + ω_i × r_i)``, with ``ω × r = −r̂ ω``."""
    C = len(i)
    G = np.zeros((C, 3, n_bodies, 6))
    rows = np.arange(C)
    G[rows, :, i, :3] = -np.eye(3)
    G[rows, :, i, 3:] = _hat(ri)
    on = j >= 0
    G[rows[on], :, j[on], :3] = np.eye(3)
    G[rows[on], :, j[on], 3:] = -_hat(rj[on])
    return G.reshape(3 * C, 6 * n_bodies)


class _Impulses:
    """Sequential impulses on a list of contacts (see the module's docstring)."""

    #: The iteration stops early once no impulse changes by more than this, relatively.
    converged = 1e-13

    def __init__(self, restitution, friction, iterations, rest_speed, slop):
        self.e, self.mu, self.iterations, self.rest_speed = _coefficients(
            restitution, friction, iterations, rest_speed)
        self.slop = _validate.finite_real("slop", slop)
        self._warm: tuple[int, dict] = (0, {})

    def solve(self, b, i, j, ri, rj, n, gap, dt: float, before=None, keys=None) -> None:
        """Contacts ``c`` between bodies ``i[c]`` and ``j[c]`` (``−1``: the ground) at offsets
        ``ri``, ``rj`` (C, 3) (m), unit normals ``n`` pointing from ``i`` to ``j`` and gaps
        (m). A contact takes part if it closes within ``dt``; it bounces if it approached
        faster than ``rest_speed`` before this step's forces (``before``: the momenta
        ``(P, L)`` then; default the current ones), else it may close its gap but not
        pass it. Bouncing on the velocity before the kick keeps a resting body from
        returning, every step, the speed the step's gravity gave it.

        The contacts are visited in order (Gauss–Seidel) on the dense matrix
        ``W = G M⁻¹ Gᵀ`` (3C, 3C) that maps impulses to relative velocities, starting from
        the impulses the same contacts (``keys``, ints) took in the previous step of the
        same bodies (warm starting, Catto 2005): a resting contact then converges at once."""
        inv_m, inv_I = 1.0 / b.mass, b.inv_inertia
        v, w = b.v, _mv(inv_I, b.L)
        u_n = np.sum(_relative(v, w, i, j, ri, rj) * n, axis=1)
        near = np.minimum(gap, gap + dt * u_n) < self.slop
        if not np.any(near):
            return
        i, j, ri, rj, n, gap = i[near], j[near], ri[near], rj[near], n[near], gap[near]
        keys = np.flatnonzero(near) if keys is None else np.asarray(keys)[near]
        if before is not None:
            v, w = before[0] * inv_m[:, None], _mv(inv_I, before[1])
        u0 = np.sum(_relative(v, w, i, j, ri, rj) * n, axis=1)
        target = np.where(-u0 > self.rest_speed, -self.e * u0, -np.maximum(gap, 0.0) / dt)
        G = _jacobian(i, j, ri, rj, b.n)
        inv_M = np.zeros((b.n, 6, b.n, 6))
        bodies = np.arange(b.n)
        inv_M[bodies, :3, bodies, :3] = inv_m[:, None, None] * np.eye(3)
        inv_M[bodies, 3:, bodies, 3:] = inv_I
        inv_M = inv_M.reshape(6 * b.n, 6 * b.n)
        W = G @ inv_M @ G.T
        u = G @ np.concatenate((b.v, _mv(inv_I, b.L)), axis=1).ravel()
        owner, previous = self._warm
        J = np.zeros((len(i), 3))
        if owner == id(b):
            for c, key in enumerate(keys.tolist()):
                if key in previous:
                    J[c] = previous[key]
        J = self._gauss_seidel(W, u, n, target, self._admissible(J, n).ravel())
        self._warm = (id(b), dict(zip(keys.tolist(), J.reshape(-1, 3), strict=True)))
        dmomentum = (G.T @ J).reshape(b.n, 6)
        b.P = b.P + dmomentum[:, :3]
        b.L = b.L + dmomentum[:, 3:]

    def _admissible(self, J, n):
        """``J`` (C, 3) with a normal part ≥ 0 and its tangential part inside the cone."""
        lam = np.maximum(np.sum(J * n, axis=1), 0.0)
        Jt = J - np.sum(J * n, axis=1)[:, None] * n
        size = np.linalg.norm(Jt, axis=1)
        Jt = Jt * np.where(size > self.mu * lam, self.mu * lam / np.maximum(size, 1e-300), 1.0)[:, None]
        return lam[:, None] * n + Jt

    def _gauss_seidel(self, W, u, n, target, J):
        """Impulses ``J`` (3C,), from the start ``J``: each contact's normal impulse
        ``λ ≥ 0`` reaches its target normal velocity; its friction, capped at ``μ λ``,
        stops its sliding if it can."""
        C = len(n)
        u = u + W @ J
        lam = np.sum(J.reshape(C, 3) * n, axis=1)
        blocks = [W[3 * c:3 * c + 3, 3 * c:3 * c + 3] for c in range(C)]
        k_n = np.einsum("ci,cij,cj->c", n, np.array(blocks), n)
        for _ in range(self.iterations):
            change = 0.0
            for c in range(C):
                s = slice(3 * c, 3 * c + 3)
                new = max(lam[c] + (target[c] - float(u[s] @ n[c])) / k_n[c], 0.0)
                delta = (new - lam[c]) * n[c]
                lam[c] = new
                if self.mu > 0:
                    uc = u[s] + blocks[c] @ delta
                    ut = uc - float(uc @ n[c]) * n[c]
                    speed = float(np.sqrt(ut @ ut))
                    Jt = J[s] - float(J[s] @ n[c]) * n[c]
                    if speed > 0:
                        t = ut / speed
                        Jt = Jt - speed / float(t @ blocks[c] @ t) * t
                    size = float(np.sqrt(Jt @ Jt))
                    if size > self.mu * new:
                        Jt = Jt * (self.mu * new / size)
                    delta = delta + Jt - (J[s] - float(J[s] @ n[c]) * n[c])
                u += W[:, s] @ delta
                J[s] += delta
                change = max(change, float(np.abs(delta).max()))
            if change <= self.converged * float(np.abs(J).max()):
                break
        return J


def _smallest(b):
    """Smallest dimension of each body (m): its shortest side or its radius."""
    return b.size.min(axis=1) if b.shape == "box" else b.size


class Ground(_Impulses):
    """The half-space ``n·x ≥ offset`` (``normal`` any non-zero vector, ``offset`` in m).

    Boxes touch it with their corners, spheres with their lowest point; a point takes
    part when it would reach the plane (within ``slop``, m) during the step. Restitution
    ``e`` acts on points that approached faster than ``rest_speed`` (m/s) before the
    step's forces; slower points may close their gap but not pass the plane.
    """

    def __init__(self, normal=(0.0, 1.0, 0.0), offset: float = 0.0, restitution: float = 0.5,
                 friction: float = 0.5, iterations: int = 50, rest_speed: float = 0.05,
                 slop: float = 1e-9):
        super().__init__(restitution, friction, iterations, rest_speed, slop)
        n = _validate.vector("normal", normal, nonzero=True)
        self.normal = n / np.linalg.norm(n)
        self.offset = _validate.finite_real("offset", offset)

    def points(self, b):
        """World contact candidates of each body, (N, K, 3), and their offsets ``r``."""
        if b.shape == "box":
            r = rotate(b.q[:, None, :], CORNERS[None] * b.size[:, None, :])
        else:
            r = np.broadcast_to(-b.size[:, None, None] * self.normal, (b.n, 1, 3))
        return b.x[:, None, :] + r, r

    def depth(self, b):
        """Signed height of each contact candidate above the plane (m), (N, K)."""
        p, _ = self.points(b)
        return p @ self.normal - self.offset

    def __call__(self, b, dt: float, before=None):
        p, r = self.points(b)
        K = r.shape[1]
        gap = (p @ self.normal - self.offset).ravel()
        i = np.repeat(np.arange(b.n), K)
        n = np.broadcast_to(-self.normal, (len(i), 3))
        self.solve(b, i, np.full(len(i), -1), r.reshape(-1, 3), np.zeros((len(i), 3)), n, gap,
                   dt, before, keys=np.arange(len(i)))

    def project(self, b):
        """Lift every body that sinks deeper than :data:`ALLOWED` of its size back to that
        depth (lifting it all the way every step would feed a rocking box energy)."""
        allowed = ALLOWED * _smallest(b)
        lowest = self.depth(b).min(axis=1)
        b.x = b.x - np.minimum(lowest + allowed, 0.0)[:, None] * self.normal


class SpherePairs(_Impulses):
    """Contacts between the spheres of one :class:`~course_lib.rigid.body.Bodies` group.

    A pair takes part when its gap would close (within ``slop``, m) during the step; the
    pairs are visited in a fixed order, as the corners of :class:`Ground` are.
    """

    def __init__(self, restitution: float = 0.5, friction: float = 0.5, iterations: int = 50,
                 rest_speed: float = 0.05, slop: float = 1e-9):
        super().__init__(restitution, friction, iterations, rest_speed, slop)

    def pairs(self, b, reach: float = 0.0):
        """Pairs ``i < j`` closer than ``reach`` (m), their unit normals (i to j) and gaps (m)."""
        i, j = np.triu_indices(b.n, 1)
        d = b.x[j] - b.x[i]
        dist = np.linalg.norm(d, axis=1)
        gap = dist - b.size[i] - b.size[j]
        on = gap < reach
        return i[on], j[on], d[on] / dist[on, None], gap[on]

    def __call__(self, b, dt: float, before=None):
        if b.shape != "sphere":
            raise ValueError(f"SpherePairs needs spheres, got shape {b.shape!r}")
        reach = self.slop + 2.0 * dt * float(np.max(np.linalg.norm(b.v, axis=1)))
        i, j, n, gap = self.pairs(b, reach)
        if len(i):
            self.solve(b, i, j, b.size[i, None] * n, -b.size[j, None] * n, n, gap, dt, before,
                       keys=i * b.n + j)

    def project(self, b):
        """Push pairs that overlap by more than :data:`ALLOWED` of the smaller radius back
        to that overlap, along their normal, shared by inverse mass."""
        i, j, n, gap = self.pairs(b)
        allowed = ALLOWED * np.minimum(b.size[i], b.size[j])
        share = (1.0 / b.mass[i]) / (1.0 / b.mass[i] + 1.0 / b.mass[j])
        push = -np.minimum(gap + allowed, 0.0)[:, None] * n
        np.add.at(b.x, i, -share[:, None] * push)
        np.add.at(b.x, j, (1.0 - share)[:, None] * push)


def chain(*rules):
    """One contact rule that applies ``rules`` in turn (and projects with each)."""

    def contact(b, dt: float, before=None):
        for rule in rules:
            rule(b, dt, before)

    def project(b):
        for rule in rules:
            rule.project(b)

    contact.project = project
    return contact
