"""Springs as distance constraints, in sets that share no particle (for Gauss–Seidel sweeps).

Position-based solvers (Müller et al. 2007; Macklin, Müller & Chentanez 2016) and Provot's
(1995) strain limiting correct one spring at a time: each correction moves the two ends
along the spring, in inverse proportion to their masses. Done in sequence that is
Gauss–Seidel, and a Python loop over springs. Springs that share no particle can be
corrected *at once* with the same result, so we split the springs into such independent
sets (a graph colouring: :func:`independent_sets`) and sweep set by set, each set one
whole-array operation (:class:`ColouredSprings`). A cloth grid needs about a dozen sets
(two per family of springs a fixed index offset apart).

Core module: imports NumPy only.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


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


class ColouredSprings:
    """The springs of a network as independent sets, with the data a sweep needs.

    Parameters
    ----------
    network : SpringNetwork
    inverse_mass : ndarray, shape (N,)
        ``1/m`` of every particle (1/kg), 0 for pinned particles (they never move).
    select : ndarray of bool, shape (M,), optional
        Which springs take part (default: every spring with ``k > 0``).

    Attributes
    ----------
    sets : list of dict
        Per set: spring indices ``s``, ends ``i``, ``j``, rest lengths ``rest``, stiffness
        ``k``, damping ``c`` and ``w = 1/m_i + 1/m_j`` (springs between two pinned
        particles are left out: nothing can move them).
    """

    def __init__(self, network, inverse_mass: np.ndarray, select: np.ndarray | None = None):
        keep = network.k > 0 if select is None else np.asarray(select, dtype=bool)
        w = inverse_mass[network.i] + inverse_mass[network.j]
        springs = np.flatnonzero(keep & (w > 0))
        self.n_springs = springs.size
        self.sets = []
        for members in independent_sets(network.i[springs], network.j[springs], network.n_particles):
            s = springs[members]
            i, j = network.i[s], network.j[s]
            self.sets.append({"s": s, "i": i, "j": j, "ends": np.concatenate((i, j)),
                              "rest": network.rest[s], "k": network.k[s], "c": network.c[s],
                              "w": w[s], "wi": inverse_mass[i][:, None],
                              "wj": inverse_mass[j][:, None]})

    def sweep(self, p: np.ndarray, rule: Callable) -> np.ndarray:
        """One Gauss–Seidel sweep over the sets, moving ``p`` (N, d) in place.

        For each set, ``rule(q, length, u, d)`` gets the set's data ``q`` (a dict, see
        :attr:`sets`; the rule may keep per-spring state in it), the current lengths
        ``ℓ`` (m), unit vectors ``u`` (``(n, d)``, 0 where the ends coincide) and spring
        vectors ``d = p_i - p_j``, and returns the multiplier change ``Δλ`` (kg m) of each
        spring; the ends then move by ``+Δλ u/m_i`` and ``-Δλ u/m_j``. Returns ``p``.
        """
        for q in self.sets:
            ends = p[q["ends"]]                  # one gather: the i ends, then the j ends
            m = q["s"].size
            d = ends[:m] - ends[m:]
            length = np.sqrt(np.einsum("sd,sd->s", d, d))
            inv = np.divide(1.0, length, out=np.zeros_like(length), where=length > 0.0)
            u = d * inv[:, None]
            step = u * rule(q, length, u, d)[:, None]
            ends[:m] += q["wi"] * step
            ends[m:] -= q["wj"] * step
            p[q["ends"]] = ends                  # no particle twice in a set: one scatter
        return p
