"""Where each spring's numbers live during a force evaluation: bands and a gathered rest.

A force evaluation needs, for every spring, the difference ``x_a - x_b`` of its two ends,
and at the end it adds each spring's force onto both particles. Done naively that is a
*gather* (``x[i]``) and a *scatter* (``np.add.at``) per step, which cost far more in NumPy
than the arithmetic between them.

Chains and grids have structure that avoids both: their springs join particles a fixed
index *offset* apart (a hair strand: 1, 2, 3; an ``nx``-wide cloth: 1, 2, ``nx - 1``,
``nx``, ``nx + 1``, ``2 nx``). All springs of one offset ``o`` are a *band*: the pairs
``(p, p + o)`` for ``p = 0 … N - o - 1``, whose differences are one whole-array operation
``x[:-o] - x[o:]`` and whose forces are added back with two shifted slices. A band keeps a
slot for every pair, used or not; unused slots get ``k = c = 0`` and carry no force.

An offset becomes a band when its springs fill at least half of its slots; every other
spring (random networks, long-range links, duplicates) is *gathered*: ``np.take`` for the
differences and a sparse incidence matrix for the sums. Per-spring arrays are stored
component-major, ``(d, S)`` over the ``S`` slots, so every operation runs over long rows.

Core module: imports NumPy and SciPy only.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def sum_rows(a: np.ndarray, out: np.ndarray) -> np.ndarray:
    """``out = a[0] + a[1] + …``: the sum over the few long rows of ``a`` (faster than
    ``np.sum(a, axis=0)``)."""
    if len(a) == 1:
        np.copyto(out, a[0])
        return out
    np.add(a[0], a[1], out=out)
    for row in a[2:]:
        out += row
    return out


#: An offset becomes a band when its springs use at least this fraction of its slots.
MIN_FILL = 0.5


class SpringLayout:
    """Slots for the springs ``(i, j)`` over ``n`` particles: bands first, then the rest.

    Attributes
    ----------
    bands : list of (offset, start, stop)
        Slots ``start:stop`` hold the pairs ``(p, p + offset)``, ``p = 0, 1, …``.
    lo, hi : ndarray of int
        Ends of the gathered springs (slots ``gathered_start:``), ``lo < hi``.
    slot : ndarray of int, shape (M,)
        The slot of each spring.
    sign : ndarray, shape (M,)
        +1 if spring ``s`` runs from its lower-indexed end (``i < j``), else -1: the slot
        stores ``x_lo - x_hi``, which is ``sign * (x_i - x_j)``.
    n_slots : int
    """

    def __init__(self, i: np.ndarray, j: np.ndarray, n: int, min_fill: float | None = None):
        min_fill = MIN_FILL if min_fill is None else min_fill
        lo, hi = np.minimum(i, j), np.maximum(i, j)
        offset = hi - lo
        self.n = n
        self.sign = np.where(i < j, 1.0, -1.0)
        self.slot = np.empty(i.size, dtype=np.intp)
        self.bands = []
        banded = np.zeros(i.size, dtype=bool)
        start = 0
        offsets, counts = np.unique(offset, return_counts=True)
        for o, count in zip(offsets.tolist(), counts.tolist(), strict=True):
            if count < min_fill * (n - o):
                continue
            members = np.flatnonzero(offset == o)
            # A pair listed twice keeps one slot in the band; the copy is gathered.
            _, first = np.unique(lo[members], return_index=True)
            members = members[first]
            self.slot[members] = start + lo[members]
            banded[members] = True
            self.bands.append((o, start, start + n - o))
            start += n - o
        rest = np.flatnonzero(~banded)
        self.gathered_start = start
        self.slot[rest] = start + np.arange(rest.size)
        self.lo, self.hi = lo[rest], hi[rest]
        self.n_slots = start + rest.size
        cols = np.arange(rest.size)
        # Incidence of the gathered springs: +1 at (lo, s), -1 at (hi, s).
        self.incidence = sp.csr_matrix(
            (np.r_[np.ones(rest.size), -np.ones(rest.size)],
             (np.r_[self.lo, self.hi], np.r_[cols, cols])), shape=(n, rest.size))
        self.incidence_abs = abs(self.incidence)

    def to_slots(self, values: np.ndarray) -> np.ndarray:
        """Per-spring values ``(M,)`` laid out per slot ``(S,)``; unused slots get 0."""
        out = np.zeros(self.n_slots)
        out[self.slot] = values
        return out

    def differences(self, rows: np.ndarray, out: np.ndarray, work: tuple | None = None) -> np.ndarray:
        """``x_lo - x_hi`` in every slot, from particle values given as rows ``(d, N)`` (a
        transposed view is fine).

        ``out`` has shape ``(d, S)``; ``work`` holds three arrays for the gathered springs:
        a contiguous copy of ``rows`` and the values at the ``lo`` and ``hi`` ends.
        """
        for o, a, b in self.bands:
            np.subtract(rows[:, :-o], rows[:, o:], out=out[:, a:b])
        if self.lo.size:
            if work is None:
                work = (np.empty(rows.shape), *(np.empty((rows.shape[0], self.lo.size)),) * 2)
            contiguous, at_lo, at_hi = work
            if rows.flags.c_contiguous:
                contiguous = rows
            else:                                      # np.take wants contiguous rows
                np.copyto(contiguous, rows)
            np.take(contiguous, self.lo, axis=1, out=at_lo, mode="clip")
            np.take(contiguous, self.hi, axis=1, out=at_hi, mode="clip")
            np.subtract(at_lo, at_hi, out=out[:, self.gathered_start:])
        return out

    def accumulate(self, f: np.ndarray, out: np.ndarray, same_sign: bool = False) -> np.ndarray:
        """Add each slot's vector onto its particles: ``+f`` at ``lo`` and ``-f`` at ``hi``
        (``+f`` at both with ``same_sign=True``). ``f`` is ``(d, S)``, ``out`` ``(d, N)`` (a
        transposed view of an ``(N, d)`` array is fine)."""
        out.fill(0.0)
        add_hi = np.add if same_sign else np.subtract
        for o, a, b in self.bands:
            out[:, :-o] += f[:, a:b]
            add_hi(out[:, o:], f[:, a:b], out=out[:, o:])
        if self.lo.size:
            matrix = self.incidence_abs if same_sign else self.incidence
            for q in range(f.shape[0]):
                out[q] += matrix @ f[q, self.gathered_start:]
        return out
