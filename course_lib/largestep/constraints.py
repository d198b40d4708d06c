"""Springs as distance constraints, in sets that share no particle (for Gauss–Seidel sweeps).

Position-based solvers (Müller et al. 2007; Macklin, Müller & Chentanez 2016) and Provot's
(1995) strain limiting correct one spring at a time: each correction moves the two ends
along the spring, in inverse proportion to their masses. Done in sequence that is
Gauss–Seidel, and a Python loop over springs. Springs that share no particle can be
corrected *at once* with the same result, so we split the springs into such independent
sets (a graph colouring) and sweep set by set, each set a few whole-array operations
(:class:`ColouredSprings`).

Where the springs sit matters for speed as much as how many sets there are. A chain or
grid joins particles a fixed index offset ``o`` apart (a *band* of the network's
:class:`~course_lib.springs.layout.SpringLayout`); its pairs ``(p, p + o)`` split into two
independent sets, ``p`` in the even blocks ``[0, o), [2o, 3o), …`` and in the odd ones, and
each set's two ends are *strided views* of the positions (no gather, no scatter, the
corrections written in place). A cloth grid has six offsets, so twelve sets. Springs
outside the bands are coloured greedily (:func:`independent_sets`) and gathered by index.
Positions are stored component-major, ``(d, N)``, so every operation runs over long rows.

Core module: imports NumPy only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: Added to a squared length (m²) before dividing by it: where the two ends coincide the
#: direction is undefined, and the correction, a finite multiple of the zero spring
#: vector, comes out as zero.
TINY = 1e-200


def independent_sets(i: np.ndarray, j: np.ndarray, n: int) -> list[np.ndarray]:
    """Split springs ``(i[s], j[s])`` over ``n`` particles into sets in which no two springs
    share a particle; returns the spring indices of each set.

    Greedy, with whole-array rounds: within a set, every spring whose ends are still free
    and that comes first (in the order below) at both of its ends joins; this repeats until
    no spring can join, then the next set starts. Springs are ordered by index offset
    ``|i - j|``, then by the parity of ``min(i, j) // offset``, so that the springs of a
    chain or grid fall into two sets per offset (every other block of ``offset`` springs).
    """
    i, j = np.asarray(i, dtype=np.intp), np.asarray(j, dtype=np.intp)
    m = i.size
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    offset = np.maximum(hi - lo, 1)
    rank = np.empty(m, dtype=np.intp)
    rank[np.lexsort((lo, (lo // offset) % 2, offset))] = np.arange(m)
    remaining = np.arange(m)
    sets = []
    while remaining.size:
        free = np.ones(n, dtype=bool)
        chosen = []
        candidates = remaining
        while candidates.size:
            first = np.full(n, m, dtype=np.intp)
            np.minimum.at(first, i[candidates], rank[candidates])
            np.minimum.at(first, j[candidates], rank[candidates])
            r = rank[candidates]
            pick = candidates[(first[i[candidates]] == r) & (first[j[candidates]] == r)]
            free[i[pick]] = False
            free[j[pick]] = False
            chosen.append(pick)
            candidates = candidates[free[i[candidates]] & free[j[candidates]]]
        members = np.sort(np.concatenate(chosen))
        sets.append(members)
        remaining = np.setdiff1d(remaining, members, assume_unique=True)
    return sets


class SpringSet:
    """Springs sharing no particle: per-slot data and the two ends in a position buffer.

    A *band set* has slots ``p = first + 2 o b + r`` (``b`` over blocks, ``r < o``), each the
    pair ``(p, p + o)``, possibly unused (no spring there, or one left out): its per-slot
    arrays have the shape of its views, and unused slots have ``wi = wj = 0`` so they never
    move anything. A *gathered set* has explicit ends ``i``, ``j``.

    Attributes
    ----------
    spring : ndarray of int
        The network's index of the spring in each slot, -1 where unused.
    rest, k, c, wi, wj, w : ndarray
        Per slot: rest length (m), stiffness (N/m), damping (N s/m), inverse masses of the
        ``i`` (``lo``) and ``j`` (``hi``) ends and their sum (1/kg); 0 where unused.
    used : ndarray of bool
    uniform : bool
        In every used slot the two ends weigh the same, or one of them is pinned.
    held : ndarray of int
        The pinned particles (``w = 0``) that are ends of used slots (``held_at``: the same
        as a slice where they are evenly spaced).
    """

    def __init__(self, spring: np.ndarray, network, inverse_mass: np.ndarray, band=None,
                 ends=None):
        self.band, self.ends = band, ends       # (offset, parity, n_blocks, transposed) or (i, j)
        self.spring = spring
        self.used = spring >= 0
        s = np.where(self.used, spring, 0)
        if ends is None:
            lo, hi = self._slot_pairs()
        else:
            lo, hi = ends
        for name in ("rest", "k", "c"):
            setattr(self, name, np.where(self.used, getattr(network, name)[s], 0.0))
        self.wi = np.where(self.used, inverse_mass[np.minimum(lo, inverse_mass.size - 1)], 0.0)
        self.wj = np.where(self.used, inverse_mass[np.minimum(hi, inverse_mass.size - 1)], 0.0)
        self.w = self.wi + self.wj
        self.symmetric = bool(np.array_equal(self.wi, self.wj))   # equal masses, no pin
        # Equal masses but for pinned ends (w = 0): a fused sweep may move both ends by the
        # free end's 1/m and put the pinned ends back (see XPBD._sweep).
        self.uniform = bool(np.all(~self.used | (self.wi == self.wj) | (self.wi == 0)
                                   | (self.wj == 0)))
        self.held = np.unique(np.r_[lo[self.used & (self.wi == 0)],
                                    hi[self.used & (self.wj == 0)]]).astype(np.intp)
        step = np.diff(self.held)
        # the same as a slice where it can be one (the usual few pins): a faster copy
        self.held_at = slice(int(self.held[0]), int(self.held[-1]) + 1, int(step[0]) if step.size
                             else 1) if self.held.size and np.all(step == step[:1]) else self.held
        self.shape = spring.shape
        self._views: dict = {}

    def _slot_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        o, parity, blocks, transposed = self.band
        b, r = np.meshgrid(np.arange(blocks), np.arange(o), indexing="ij")
        lo = 2 * o * b + parity * o + r
        if transposed:
            lo = lo.T
        return lo, lo + o

    def views(self, buffer: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ``lo`` and ``hi`` ends of a band set in ``buffer`` (d, N + padding): views."""
        key = id(buffer)
        if key not in self._views:
            o, parity, blocks, transposed = self.band
            dim = buffer.shape[0]
            pad = buffer[:, :2 * o * (blocks + parity)].reshape(dim, blocks + parity, 2, o)
            # parity 0: blocks 0, 2, 4, … against 1, 3, 5, …; parity 1: 1, 3, … against 2, 4, …
            lo, hi = (pad[:, :, 0], pad[:, :, 1]) if parity == 0 else (pad[:, :-1, 1], pad[:, 1:, 0])
            if transposed:
                lo, hi = lo.transpose(0, 2, 1), hi.transpose(0, 2, 1)
            self._views[key] = (buffer, lo, hi)       # keep the buffer alive with its id
        return self._views[key][1:]

    def difference(self, buffer: np.ndarray, out: np.ndarray) -> np.ndarray:
        """Spring vectors ``x_lo - x_hi`` of every slot, ``(d, *shape)``, into ``out``."""
        if self.ends is None:
            lo, hi = self.views(buffer)
            return np.subtract(lo, hi, out=out)
        return np.subtract(buffer[:, self.ends[0]], buffer[:, self.ends[1]], out=out)

    def move(self, buffer: np.ndarray, d: np.ndarray, f: np.ndarray, work: np.ndarray) -> None:
        """``x_lo -= wi f d`` and ``x_hi += wj f d`` in ``buffer`` (``work`` is scratch of the
        shape of ``d``)."""
        if self.ends is None:
            lo, hi = self.views(buffer)
            lo -= np.multiply(d, f * self.wi, out=work)
            hi += work if self.symmetric else np.multiply(d, f * self.wj, out=work)
        else:
            buffer[:, self.ends[0]] -= np.multiply(d, f * self.wi, out=work)
            buffer[:, self.ends[1]] += np.multiply(d, f * self.wj, out=work)


class ColouredSprings:
    """The springs of a network as independent sets, swept in place on component-major
    positions.

    Parameters
    ----------
    network : SpringNetwork
    inverse_mass : ndarray, shape (N,)
        ``1/m`` of every particle (1/kg), 0 for pinned particles (they never move).
    select : ndarray of bool, shape (M,), optional
        Which springs take part (default: every spring with ``k > 0``). Springs between two
        pinned particles are left out: nothing can move them.

    Attributes
    ----------
    sets : list of SpringSet
        In sweep order: two per band (by increasing offset), then the gathered sets.
    n_springs : int
        Springs taking part.
    padding : int
        Columns a position buffer needs beyond the ``N`` particles (:meth:`buffer`).
    """

    def __init__(self, network, inverse_mass: np.ndarray, select: np.ndarray | None = None):
        inverse_mass = np.asarray(inverse_mass, dtype=float)
        keep = network.k > 0 if select is None else np.asarray(select, dtype=bool).copy()
        keep &= (inverse_mass[network.i] + inverse_mass[network.j]) > 0
        self.n_springs = int(keep.sum())
        self.n = n = network.n_particles
        layout = network.layout
        slot_spring = np.full(layout.n_slots, -1)
        slot_spring[layout.slot[keep]] = np.flatnonzero(keep)
        self.sets: list[SpringSet] = []
        self.padding = 0
        for o, a, _b in layout.bands:
            blocks = -(-n // (2 * o))
            self.padding = max(self.padding, 2 * o * blocks - n + o)
            per_p = np.full(2 * o * blocks, -1)
            per_p[:n - o] = slot_spring[a:a + n - o]
            grid = per_p.reshape(blocks, 2, o)
            transposed = o < blocks                     # the long axis innermost
            for parity, spring in ((0, grid[:, 0]), (1, grid[:-1, 1])):
                if (spring >= 0).any():
                    band = (o, parity, spring.shape[0], transposed)
                    spring = spring.T.copy() if transposed else spring.copy()
                    self.sets.append(SpringSet(spring, network, inverse_mass, band=band))
        gathered = np.flatnonzero(keep & (layout.slot >= layout.gathered_start))
        for members in independent_sets(network.i[gathered], network.j[gathered], n):
            s = gathered[members]
            self.sets.append(SpringSet(s, network, inverse_mass, ends=(network.i[s], network.j[s])))
        self._work: dict = {}

    def buffer(self, dim: int) -> np.ndarray:
        """A new zeroed position buffer ``(dim, N + padding)``: particles in the first ``N``
        columns, the padding never moved (its slots are unused)."""
        return np.zeros((dim, self.n + self.padding))

    def work(self, q: SpringSet, dim: int) -> tuple[np.ndarray, np.ndarray]:
        """Two scratch arrays ``(dim, *q.shape)`` for set ``q`` (reused between calls)."""
        key = (id(q), dim)
        if key not in self._work:
            self._work[key] = (np.empty((dim, *q.shape)), np.empty((dim, *q.shape)))
        return self._work[key]

    def bound(self, buffer: np.ndarray) -> list[tuple]:
        """Per set, ``(q, d, work, lo, hi)``: scratch arrays and the ends' views in
        ``buffer`` (``None`` for a gathered set), made once per buffer."""
        key = ("bound", id(buffer))
        if key not in self._work:
            self._work[key] = [(q, *self.work(q, buffer.shape[0]),
                                *(q.views(buffer) if q.ends is None else (None, None)))
                               for q in self.sets]
        return self._work[key]

    def sweep(self, buffer: np.ndarray, rule: Callable) -> np.ndarray:
        """One Gauss–Seidel sweep over the sets, moving the positions in ``buffer``
        (``(d, N + padding)``, from :meth:`buffer`) in place.

        For each set, ``rule(q, d, squared)`` gets the set ``q`` (a :class:`SpringSet`; the
        rule may keep per-slot state on it), the spring vectors ``d = x_lo - x_hi``
        (``(d, *q.shape)``) and their squared lengths ``ℓ²`` (m²), and returns per slot
        ``f = -Δλ/ℓ`` (kg): the ends then move by ``-f d/m_lo`` and ``+f d/m_hi``, i.e. by
        ``Δλ u/m`` along the unit vector ``u``, as in every position-based method. A rule
        divides by ``ℓ² + TINY`` (see :data:`TINY`). Returns ``buffer``.
        """
        for q, d, work, lo, hi in self.bound(buffer):
            if lo is None:
                q.difference(buffer, d)
                q.move(buffer, d, rule(q, d, np.einsum("k...,k...->...", d, d)), work)
                continue
            np.subtract(lo, hi, out=d)                  # the set's SpringSet.move, inlined
            f = rule(q, d, np.einsum("k...,k...->...", d, d))
            lo -= np.multiply(d, f * q.wi, out=work)
            hi += work if q.symmetric else np.multiply(d, f * q.wj, out=work)
        return buffer

    def load(self, buffer: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Copy positions ``x`` (N, d) into ``buffer`` (component-major); returns it."""
        buffer[:, :self.n] = x.T
        return buffer
