"""Fixed-radius neighbour search: every pair of points closer than a radius, in open space
or in a periodic box.

Holds :func:`pairs` (a k-d tree, :class:`scipy.spatial.cKDTree`, in about
``O(N log N + P)`` for ``P`` pairs), :func:`all_pairs` (the reference: every one of the
``N (N − 1)/2`` pairs tested, in blocks of rows) and the two helpers both build on,
:func:`wrap_positions` and :func:`minimum_image` (:func:`pairs_unchecked` and
:func:`wrap_unchecked` skip the checks, for a caller that validates once and steps many
times). Both searches return a :class:`Pairs`
and agree **exactly** (the same pairs, the same offset bits) on every configuration,
because they share one definition of a pair:

    ``i < j`` is a pair when ``|d|² <= radius²``, with ``d = minimum_image(w_j − w_i)``,

where ``w`` are the positions wrapped into the box (unchanged in open space) and ``|d|²``
is summed coordinate by coordinate in order (:func:`squared_norms`). The tree only
proposes candidates, with a radius widened by a few units of round-off (its own distance
arithmetic differs from ours in the last bits); the candidates are then judged by that
one definition. Coincident
points (``d = 0``) are pairs too: what a model does with them is the model's business.

Core module: imports NumPy and SciPy only. Units: positions, offsets, distances, radius
and box in metres (any length unit works, consistently).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from . import _validate

#: Row-block size bound of :func:`all_pairs`: at most this many offsets are held at once.
BLOCK_ENTRIES = 2_000_000


@dataclass(frozen=True)
class Pairs:
    """Pairs of points within a radius, one row per unordered pair.

    Attributes
    ----------
    i, j : ndarray of intp, shape (P,)
        Indices with ``i < j``; sorted by ``(i, j)`` unless asked otherwise.
    offset : ndarray, shape (P, dim)
        ``x_j − x_i`` (m), the minimum image in a periodic box.
    distance : ndarray, shape (P,)
        ``|offset|`` (m).
    """

    i: np.ndarray
    j: np.ndarray
    offset: np.ndarray
    distance: np.ndarray

    def __len__(self) -> int:
        return int(self.i.size)


def _positions(x) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"x must be an array of numbers of shape (N, dim), got {type(x).__name__}") from None
    if arr.ndim != 2 or arr.shape[1] < 1:
        raise ValueError(f"x must have shape (N, dim), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError("x must be finite; it contains NaN or inf")
    return arr


def _radius(radius) -> float:
    try:
        r = float(radius)
    except (TypeError, ValueError):
        raise TypeError(f"radius must be a real number, got {type(radius).__name__}") from None
    if not (np.isfinite(r) and r > 0 and np.isfinite(r * r) and r * r >= np.finfo(float).tiny):
        raise ValueError(f"radius must be > 0 with a finite, normal radius² (m²), got {radius!r}")
    return r


def _box(box, dim: int, radius: float) -> np.ndarray | None:
    """``box`` as a ``(dim,)`` array of sides (None for open space), validated."""
    if box is None:
        return None
    try:
        sides = np.broadcast_to(np.asarray(box, dtype=float), (dim,)).copy()
    except (TypeError, ValueError):
        raise ValueError(f"box must be None, a number or {dim} numbers (m), got {box!r}") from None
    if not (np.all(np.isfinite(sides)) and np.all(sides > 2.0 * radius)):
        raise ValueError(f"every side of box must be finite and exceed 2 × radius = {2 * radius!r} "
                         f"(so that at most one image of a point is within radius), got {box!r}")
    return sides


def wrap_positions(x, box) -> np.ndarray:
    """Positions wrapped into ``[0, box)`` on every axis (a copy; ``x`` if ``box`` is None).

    Parameters
    ----------
    x : array_like, shape (N, dim)
        Positions (m), any real values.
    box : None, float or array_like of shape (dim,)
        Side(s) of the periodic box (m).
    """
    x = _validate.real_array("x", x)
    if box is None:
        return x
    sides = np.broadcast_to(_validate.real_array("box", box), x.shape[-1:])
    if np.any(sides <= 0):
        raise ValueError(f"box must be > 0 on every axis (m), got {box!r}")
    return wrap_unchecked(x, sides)


def wrap_unchecked(x: np.ndarray, sides: np.ndarray) -> np.ndarray:
    """:func:`wrap_positions` without its checks, for a caller that validated ``x`` (a
    finite float array) and ``sides`` (positive, shape ``(dim,)``) once and wraps many times
    (:mod:`.boids` steps a flock)."""
    w = np.mod(x, sides)
    # a tiny negative coordinate rounds to exactly `box`; its image at 0 is the same point
    return np.where(w >= sides, 0.0, w)


def minimum_image(d, box) -> np.ndarray:
    """Offsets ``d`` (m, shape ``(..., dim)``) moved to their nearest periodic image,
    ``d − box · round(d / box)`` per axis; unchanged if ``box`` is None."""
    d = np.asarray(d, dtype=float)
    if box is None:
        return d
    sides = np.broadcast_to(np.asarray(box, dtype=float), d.shape[-1:])
    return d - sides * np.round(d / sides)


def squared_norms(d) -> np.ndarray:
    """``|d|²`` over the last axis (shape ``d.shape[:-1]``, m²), summed coordinate by
    coordinate in order: the same bits for a row wherever it sits in an array (a SIMD
    reduction may round differently with the array's length and alignment). An offset
    too large to square gives ``inf`` (no warning): it is never within a radius."""
    d = np.asarray(d, dtype=float)
    with np.errstate(over="ignore"):
        out = d[..., 0] * d[..., 0]
        for k in range(1, d.shape[-1]):
            out = out + d[..., k] * d[..., k]
    return out


def _empty(dim: int) -> Pairs:
    none = np.zeros(0, dtype=np.intp)
    return Pairs(none, none.copy(), np.zeros((0, dim)), np.zeros(0))


def _judged(w, i, j, radius, sides, sort) -> Pairs:
    """The candidate pairs ``(i, j)`` that the one definition accepts."""
    with np.errstate(over="ignore"):       # offsets beyond the float range: not pairs
        d = minimum_image(np.take(w, j, axis=0) - np.take(w, i, axis=0), sides)
    dist2 = squared_norms(d)
    keep = dist2 <= radius * radius
    i, j, d, dist2 = i[keep], j[keep], d[keep], dist2[keep]
    if sort:
        order = np.lexsort((j, i))
        i, j, d, dist2 = i[order], j[order], d[order], dist2[order]
    return Pairs(i, j, d, np.sqrt(dist2))


def pairs(x, radius: float, box=None, *, sort: bool = True) -> Pairs:
    """Every pair of points at most ``radius`` apart, found with a k-d tree.

    Parameters
    ----------
    x : array_like, shape (N, dim)
        Positions (m), finite. In a periodic box they may lie outside it.
    radius : float
        Search radius (m), > 0; a pair at exactly ``radius`` is included.
    box : None, float or array_like of shape (dim,), optional
        Sides (m) of a periodic box ``[0, box)``, each > 2 × radius; None for open space.
    sort : bool, optional
        Sort the pairs by ``(i, j)`` (default) as :func:`all_pairs` returns them.

    Returns
    -------
    Pairs
        ``i < j``, offsets ``x_j − x_i`` (minimum image) and distances: exactly what
        :func:`all_pairs` returns (same pairs, same bits).
    """
    x = _positions(x)
    r = _radius(radius)
    return pairs_unchecked(x, r, _box(box, x.shape[1], r), sort)


def pairs_unchecked(x: np.ndarray, r: float, sides: np.ndarray | None, sort: bool) -> Pairs:
    """:func:`pairs` without its checks, for a caller that validated ``x`` (a finite float
    ``(N, dim)`` array), ``r`` (> 0) and ``sides`` (None, or positive sides each > 2 r, shape
    ``(dim,)``) once and searches many times (:mod:`.boids` steps a flock)."""
    if len(x) < 2:
        return _empty(x.shape[1])
    w = x if sides is None else wrap_unchecked(x, sides)
    # the tree rounds its distances its own way: widen its radius by a few units of
    # round-off of the coordinates, then judge every candidate by the shared definition
    scale = float(np.max(np.abs(w))) + (0.0 if sides is None else float(sides.max())) + r
    widened = r + 16.0 * x.shape[1] * np.finfo(float).eps * scale
    tree = cKDTree(w, boxsize=None if sides is None else sides)
    cand = tree.query_pairs(widened, output_type="ndarray").astype(np.intp)
    i, j = cand[:, 0], cand[:, 1]
    return _judged(w, np.minimum(i, j), np.maximum(i, j), r, sides, sort)


def all_pairs(x, radius: float, box=None) -> Pairs:
    """The reference search: every pair ``i < j`` tested, ``N (N − 1)/2`` of them, in blocks
    of rows (at most :data:`BLOCK_ENTRIES` offsets at a time). Same parameters and result
    as :func:`pairs`, sorted by ``(i, j)``; the cost grows as ``N²``."""
    x = _positions(x)
    r = _radius(radius)
    sides = _box(box, x.shape[1], r)
    n = len(x)
    if n < 2:
        return _empty(x.shape[1])
    w = wrap_positions(x, sides)
    rows = max(1, BLOCK_ENTRIES // n)
    found = []
    for start in range(0, n - 1, rows):
        block = np.arange(start, min(start + rows, n - 1))
        with np.errstate(over="ignore"):
            d = minimum_image(w[None, :, :] - w[block, None, :], sides)
        near = (squared_norms(d) <= r * r) & (np.arange(n)[None, :] > block[:, None])
        a, b = np.nonzero(near)
        found.append((block[a], b))
    i = np.concatenate([f[0] for f in found]).astype(np.intp)
    j = np.concatenate([f[1] for f in found]).astype(np.intp)
    return _judged(w, i, j, r, sides, sort=False)
