"""Checks for notebook 13, SPH liquids: the poly6 kernel with its 2D normalisation, the
density by summation, and a pressure force that conserves momentum.

No answer may call the library (``allow=()``); the density exercise is handed its kernel
``W(r, h)`` as an argument. The cases hold what breaks the shortcuts: distances beyond the
support and unsorted, particles unsorted with unequal masses and one alone, pairs listed
once each in no order, some pressures zero.
"""

from __future__ import annotations

import numpy as np

from .. import neighbors
from ..sph import kernels
from . import Checker, exercise

_SEED = 1313


def cubic_2d(r, h):
    """Monaghan's cubic spline in 2D (1/m²), support ``2h``: the kernel handed to the
    density exercise."""
    return kernels.cubic(r, h, 2)


def _call(ck: Checker, func, what: str, *args):
    """The answer as a float array, or None (recorded as a failure) if it is not one."""
    got = func(*args)
    try:
        return np.asarray(got, dtype=float)
    except (TypeError, ValueError):
        ck.expect(False, what, f"expected an array of numbers, got {type(got).__name__}")
        return None


@exercise(allow=())
def poly6_2d(ck: Checker, func) -> None:
    """``func(r, h) -> W``: ``σ (h² - r²)³`` for ``r ≤ h``, 0 beyond, normalised in 2D."""
    rng = np.random.default_rng(_SEED)
    for h in (0.1, 0.037):
        r = rng.permutation(np.concatenate([[0.0, 0.5 * h, h], rng.uniform(0, 1.6 * h, 9)]))
        r = r.reshape(3, 4)
        expected = kernels.poly6(r, h, 2)
        shape = np.clip(h * h - r * r, 0.0, None) ** 3
        mistakes = {
            ("that is the 3D constant; redo the integral over the plane",
             "in 2D, ∫₀ʰ σ (h² - r²)³ 2πr dr = σ π h⁸ / 4, so σ = 4/(π h⁸); 315/(64π h⁹) "
             "normalises the kernel in 3D"): 315 / (64 * np.pi * h**9) * shape,
            ("σ must carry a 1/h⁸ so that W keeps 1/m² units as h changes",
             "(h² - r²)³ is h⁶ (1 - q²)³ with q = r/h: σ = 4/(π h⁸) with (h² - r²)³, or "
             "4/(π h²) with (1 - q²)³"): 4 / (np.pi * h**2) * shape,
            ("the area element of the plane is 2πr dr, not dr",
             "∫ W dA = ∫₀ʰ W(r) 2πr dr; without 2πr you normalised a 1D half line"):
                35 / (16 * h**7) * shape,
            "a factor π is missing from σ (the plane's area element is 2πr dr)":
                4 / h**8 * shape,
            ("beyond r = h the kernel must be 0, not σ (h² - r²)³",
             "(h² - r²)³ turns negative past the support: use np.where(r <= h, ..., 0) or "
             "clip h² - r² at 0"): 4 / (np.pi * h**8) * (h * h - r * r) ** 3,
        }
        got = _call(ck, func, f"h = {h} m", r.copy(), h)
        if got is None:
            return
        ck.close(got, expected, f"h = {h} m: W at 12 distances in [0, 1.6 h], unsorted, "
                 "as a 3 × 4 array", rtol=1e-10, atol=0.0, mistakes=mistakes)
    # the normalisation itself: Gauss-Legendre with 16 nodes is exact for W(r) r (degree 7)
    h = 0.05
    nodes, weights = np.polynomial.legendre.leggauss(16)
    r = 0.5 * h * (nodes + 1.0)
    got = _call(ck, func, "normalisation", r, h)
    if got is None or got.shape != r.shape:
        ck.expect(False, "∫ W dA = 1", "could not evaluate W on an array of distances")
        return
    area = float(np.sum(0.5 * h * weights * got * 2 * np.pi * r))
    ck.expect(abs(area - 1.0) < 1e-10, "∫ W dA = 1 over the plane (h = 0.05 m)",
              f"got {area:.6g}", hint="choose σ so that ∫₀ʰ W(r) 2πr dr = 1")


def _particles(n: int, rng, lattice: bool):
    if lattice:               # a sorted lattice block, as a scene makes it
        side = int(np.sqrt(n))
        g = (np.arange(side) + 0.5) * 0.02
        x = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    else:                     # scattered, in no order, one particle far from the others
        x = rng.uniform(0.0, 0.2, (n, 2))
        x[rng.integers(n)] = [0.6, 0.6]
    return x, rng.uniform(0.3, 0.6, len(x))


@exercise(allow=())
def density(ck: Checker, func) -> None:
    """``func(x, m, h, W) -> rho``: ``ρ_i = Σ_j m_j W(|x_i - x_j|, h)``, ``j = i`` included."""
    rng = np.random.default_rng(_SEED + 1)
    h = 0.024
    for what, n, lattice in (("60 scattered particles, unequal masses, one alone", 60, False),
                             ("a 10 × 10 lattice block, unequal masses", 100, True)):
        x, m = _particles(n, rng, lattice)
        r = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=-1)
        W = kernels.cubic(r, h, 2)
        expected = W @ m
        upper = np.triu(W, 1)
        mistakes = {
            ("each particle counts itself too: add m_i W(0, h)",
             "the sum runs over every j within the support, j = i included: ρ_i = m_i W(0) + "
             "Σ_{j≠i} m_j W_ij (a particle alone has ρ = m W(0), not 0)"):
                expected - m * W[0, 0],
            ("weight neighbour j by its own mass m_j, not by m_i",
             "ρ_i = Σ_j m_j W_ij: with equal masses the two agree, ours are unequal"):
                m * W.sum(axis=1),
            ("each pair adds to both particles: a pair listed once (i < j) must add m_j W_ij "
             "to ρ_i and m_i W_ij to ρ_j", "query_pairs lists each pair once; scatter it to "
             "both ends, e.g. np.add.at(rho, i, m[j] * w) and np.add.at(rho, j, m[i] * w)"):
                m * W[0, 0] + upper @ m,
        }
        args = (x.copy(), m.copy(), h, cubic_2d)
        got = _call(ck, func, what, *args)
        if got is None:
            return
        if not (np.array_equal(args[0], x) and np.array_equal(args[1], m)):
            ck.expect(False, what, "your function changed x or m",
                      hint="build a new array for ρ instead of updating the inputs")
            continue
        ck.close(got, expected, what, rtol=1e-10, atol=0.0, mistakes=mistakes)


def _pair_case(rng, n: int = 80):
    x = rng.uniform(0.0, 0.12, (n, 2))
    found = neighbors.pairs(x, 0.048, sort=False)
    order = rng.permutation(len(found))                       # pairs in no order
    i, j = found.i[order], found.j[order]
    swap = rng.random(len(i)) < 0.5                           # and either way round
    i, j = np.where(swap, j, i), np.where(swap, i, j)
    d = x[i] - x[j]
    r = np.linalg.norm(d, axis=1)
    grad = d * (kernels.cubic_dr(r, 0.024, 2) / r)[:, None]
    m = rng.uniform(0.3, 0.6, n)
    rho = rng.uniform(900.0, 1100.0, n)
    p = np.where(rng.random(n) < 0.2, 0.0, rng.uniform(0.0, 2e4, n))
    return i, j, grad, m, rho, p


def _scatter(index, values, n):
    return np.stack([np.bincount(index, values[:, k], minlength=n) for k in range(values.shape[1])],
                    axis=1)


@exercise(allow=())
def pressure_acceleration(ck: Checker, func) -> None:
    """``func(i, j, gradW, m, rho, p) -> a``: ``a_i = -Σ_j m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_i W_ij``,
    each listed pair acting on both particles."""
    rng = np.random.default_rng(_SEED + 2)
    for case in range(2):
        i, j, g, m, rho, p = _pair_case(rng)
        n = len(m)
        q = p / rho**2
        f = -(q[i] + q[j])[:, None] * g
        expected = _scatter(i, m[j, None] * f, n) + _scatter(j, -m[i, None] * f, n)
        only_i = _scatter(i, m[j, None] * f, n)
        last = np.zeros((n, 2))
        last[i] += m[j, None] * f                               # what buffered updates keep
        last[j] += -m[i, None] * f
        naive = _scatter(i, -(m[j] * p[j] / rho[j])[:, None] * g, n) \
            + _scatter(j, (m[i] * p[i] / rho[i])[:, None] * g, n)
        mistakes = {
            ("each listed pair pushes both particles: add the opposite push to j",
             "a pair (i, j) appears once; a_j gets -m_i (p_i/ρ_i² + p_j/ρ_j²) ∇_j W_ji = "
             "+m_i (...) ∇_i W_ij"): only_i,
            "sign: pressure pushes particles apart, a_i = -Σ_j m_j (...) ∇_i W_ij": -expected,
            ("a[i] += f with repeated indices adds only one term per particle (NumPy buffers "
             "fancy-index updates)", "use np.add.at(a, i, f) or np.bincount per axis"): last,
            ("that is -(1/ρ_i) Σ_j m_j (p_j/ρ_j) ∇W_ij: a fine estimate of -∇p/ρ but not "
             "symmetric in the pair, so momentum drifts", "use p_i/ρ_i² + p_j/ρ_j², the same "
             "for both particles of a pair"): naive / rho[:, None],
            "divide each pressure by ρ², not ρ (p/ρ² has units of m⁵/(kg s²) in 2D)":
                _scatter(i, m[j, None] * -((p / rho)[i] + (p / rho)[j])[:, None] * g, n)
                + _scatter(j, m[i, None] * ((p / rho)[i] + (p / rho)[j])[:, None] * g, n),
            "weight by the neighbour's mass m_j (for particle j: m_i), not by your own":
                _scatter(i, m[i, None] * f, n) + _scatter(j, -m[j, None] * f, n),
        }
        args = (i.copy(), j.copy(), g.copy(), m.copy(), rho.copy(), p.copy())
        what = f"{n} particles, {len(i)} pairs listed once in no order ({case + 1})"
        got = _call(ck, func, what, *args)
        if got is None:
            return
        if not ck.close(got, expected, what, rtol=1e-10, atol=1e-10 * np.abs(expected).max(),
                        mistakes=mistakes):
            continue
        total = np.abs((m[:, None] * got).sum(axis=0)).max()
        scale = np.sum(m[:, None] * np.abs(got))
        ck.expect(total <= 64 * np.finfo(float).eps * scale,
                  f"({case + 1}) total force Σ m_i a_i = 0 to round-off (momentum conserved)",
                  f"|Σ m a| = {total:.3g} N/m against Σ m|a| = {scale:.3g}")
