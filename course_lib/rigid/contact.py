"""Contact by impulses: restitution and Coulomb friction, against the ground and between spheres.

A contact at the point ``p`` of a body (offset ``r = p − x`` from its centre of mass) with
normal ``n`` changes the body's velocity there by an impulse ``J``: ``Δv = J/m``,
``Δω = I⁻¹(r × J)``. The point's velocity ``u = v + ω × r`` changes along ``n`` by
``K_n j`` for ``J = j n``, with the *effective inverse mass*

    K_n = 1/m + n · ((I⁻¹ (r × n)) × r)

(plus the other body's terms in a two-body contact). Newton's law of restitution asks for
``u_n' = −e u_n``, so the normal impulse is ``j = −(1 + e) u_n / K_n`` (Baraff 2001;
Mirtich 1996). Coulomb friction caps the tangential impulse at ``μ j``: it stops the
sliding if it can, else it takes ``μ j`` against the slip.

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
from .inertia import world_tensor
from .quaternion import cross, rotate

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


def _hat(r):
    """Cross-product matrices ``r̂`` (``r̂ a = r × a``), shape (..., 3, 3)."""
    out = np.zeros((*r.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -r[..., 2], r[..., 1]
    out[..., 1, 0], out[..., 1, 2] = r[..., 2], -r[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -r[..., 1], r[..., 0]
    return out


def _mv(A, x):
    return (A @ x[..., None])[..., 0]


class _Slot:
    """Contacts of distinct bodies ``i`` with bodies ``j`` (``j = −1``: the ground), with the
    matrices that map an impulse to velocity changes, precomputed for the solve."""

    def __init__(self, i, j, ri, rj, n, inv_m, inv_I):
        self.i, self.n, self.other = i, n, j >= 0
        self.j = j[self.other]
        self.hi, self.hj = _hat(ri), _hat(rj[self.other])
        self.inv_mi, self.inv_mj = inv_m[i][:, None], inv_m[self.j][:, None]
        self.Ai, self.Aj = inv_I[i] @ self.hi, inv_I[self.j] @ self.hj     # Δω per impulse
        K = inv_m[i][:, None, None] * np.eye(3) - self.hi @ self.Ai        # Δu per impulse
        K[self.other] += inv_m[self.j][:, None, None] * np.eye(3) - self.hj @ self.Aj
        self.K = K
        self.k_n = np.einsum("ni,nij,nj->n", n, K, n)
        self.target = np.zeros(len(i))
        self.lam, self.J = np.zeros(len(i)), np.zeros((len(i), 3))

    @staticmethod
    def relative(v, w, i, j, ri, rj):
        """Velocity of the contact points on ``j`` relative to those on ``i`` (m/s)."""
        u = -v[i] - cross(w[i], ri)
        on = j >= 0
        u[on] += v[j[on]] + cross(w[j[on]], rj[on])
        return u

    def velocity(self, v, w):
        """Velocity of the contact point on ``j`` relative to the one on ``i`` (m/s)."""
        u = _mv(self.hi, w[self.i]) - v[self.i]
        u[self.other] += v[self.j] - _mv(self.hj, w[self.j])
        return u

    def apply(self, v, w, J):
        """Impulse ``J`` on ``j``, ``−J`` on ``i`` (bodies within a slot are distinct)."""
        v[self.i] -= self.inv_mi * J
        w[self.i] -= _mv(self.Ai, J)
        Jo = J[self.other]
        v[self.j] += self.inv_mj * Jo
        w[self.j] += _mv(self.Aj, Jo)


class _Impulses:
    """Sequential impulses on contact slots (see the module's docstring)."""

    #: The iteration stops early once no impulse changes by more than this, relatively.
    converged = 1e-13

    def __init__(self, restitution, friction, iterations, rest_speed, slop):
        self.e, self.mu, self.iterations, self.rest_speed = _coefficients(
            restitution, friction, iterations, rest_speed)
        self.slop = _validate.finite_real("slop", slop)

    def solve(self, b, slots, dt: float, before=None) -> None:
        """``slots``: list of ``(i, j, ri, rj, n, gap)``: body rows, offsets (m), unit normals
        pointing from ``i`` to ``j`` and gaps (m); contacts within one slot involve
        distinct bodies. A contact takes part if it closes within ``dt``; it bounces if it
        approached faster than ``rest_speed`` before this step's forces (``before``: the
        momenta ``(P, L)`` then; default the current ones), else it may close its gap but
        not pass it. Bouncing on the velocity before the kick keeps a resting body from
        returning, every step, the speed the step's gravity gave it."""
        inv_m, inv_I = 1.0 / b.mass, b.inv_inertia
        v, w = b.v, _mv(inv_I, b.L)
        v0, w0 = (v, w) if before is None else (before[0] * inv_m[:, None], _mv(inv_I, before[1]))
        work = []
        for i, j, ri, rj, n, gap in slots:
            u_n = np.sum((_Slot.relative(v, w, i, j, ri, rj)) * n, axis=1)
            near = np.minimum(gap, gap + dt * u_n) < self.slop
            if not np.any(near):
                continue
            slot = _Slot(i[near], j[near], ri[near], rj[near], n[near], inv_m, inv_I)
            u0 = np.sum(_Slot.relative(v0, w0, slot.i, j[near], ri[near], rj[near]) * slot.n, axis=1)
            bounce = -u0 > self.rest_speed
            slot.target = np.where(bounce, -self.e * u0, -np.maximum(gap[near], 0.0) / dt)
            work.append(slot)
        if not work:
            return
        for _ in range(self.iterations):
            change, scale = 0.0, 0.0
            for slot in work:
                u = slot.velocity(v, w)
                lam = np.maximum(slot.lam + (slot.target - np.sum(u * slot.n, axis=1)) / slot.k_n, 0.0)
                slot.apply(v, w, (lam - slot.lam)[:, None] * slot.n)
                change = max(change, float(np.max(np.abs(lam - slot.lam))))
                slot.lam = lam
                scale = max(scale, float(np.max(lam)))
                if self.mu == 0:
                    continue
                u = slot.velocity(v, w)
                ut = u - np.sum(u * slot.n, axis=1)[:, None] * slot.n
                speed = np.sqrt(np.sum(ut * ut, axis=1))
                t = ut / np.maximum(speed, 1e-300)[:, None]
                k_t = np.where(speed > 0, np.einsum("ni,nij,nj->n", t, slot.K, t), 1.0)
                J = slot.J - (speed / k_t)[:, None] * t
                size = np.sqrt(np.sum(J * J, axis=1))
                cap = self.mu * lam
                J = J * np.where(size > cap, cap / np.maximum(size, 1e-300), 1.0)[:, None]
                slot.apply(v, w, J - slot.J)
                change = max(change, float(np.max(np.abs(J - slot.J))))
                slot.J = J
            if change <= self.converged * scale:
                break
        b.P = b.mass[:, None] * v
        b.L = _mv(world_tensor(b.R, b.moments), w)


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
                 friction: float = 0.5, iterations: int = 10, rest_speed: float = 0.05,
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
        gap = p @ self.normal - self.offset
        rows = np.arange(b.n)
        n = np.broadcast_to(-self.normal, (b.n, 3))
        ground, none = np.full(b.n, -1), np.zeros((b.n, 3))
        self.solve(b, [(rows, ground, r[:, k], none, n, gap[:, k]) for k in range(r.shape[1])], dt, before)

    def project(self, b):
        """Lift every body that sinks deeper than :data:`ALLOWED` of its size back to that
        depth (lifting it all the way every step would feed a rocking box energy)."""
        allowed = ALLOWED * _smallest(b)
        lowest = self.depth(b).min(axis=1)
        b.x = b.x - np.minimum(lowest + allowed, 0.0)[:, None] * self.normal


class SpherePairs(_Impulses):
    """Contacts between the spheres of one :class:`~course_lib.rigid.body.Bodies` group.

    A pair takes part when its gap would close (within ``slop``, m) during the step; the
    pairs are visited one after the other in a fixed order, as the corners of
    :class:`Ground` are.
    """

    def __init__(self, restitution: float = 0.5, friction: float = 0.5, iterations: int = 10,
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
        self.solve(b, [(i[k:k + 1], j[k:k + 1], b.size[i[k:k + 1], None] * n[k:k + 1],
                        -b.size[j[k:k + 1], None] * n[k:k + 1], n[k:k + 1], gap[k:k + 1])
                       for k in range(len(i))], dt, before)

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
