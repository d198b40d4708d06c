"""Checks for notebook 13, SPH liquids: the poly6 kernel with its 2D normalisation, the
density by summation, a pressure force that conserves momentum, IISPH's Jacobi solve and
the dam-break front against Martin & Moyce.

No answer may call the library (``allow=()``); what an exercise needs is handed over as an
argument (the kernel ``W(r, h)``, the operator ``apply_A``). The cases hold what breaks the
shortcuts: distances beyond the support and unsorted, particles unsorted with unequal masses
and one alone, pairs listed once each in no order, some pressures zero, a pressure system
whose solution needs the clamp ``p ≥ 0`` and a particle without neighbours, a column that
is not 1 m wide and a table that is not Martin & Moyce's. Answers are judged at their own
precision (float32 passes), and a long wrong array is summarised by one row.
"""

from __future__ import annotations

import numpy as np

from .. import neighbors
from ..sph import iisph, kernels, scenes
from . import Checker, exercise
from ._answers import as_array, call, close, rtol_for
from ._nb13_cases import front_cases, front_variant, jacobi_cases, jacobi_variant

_SEED = 1313


def cubic_2d(r, h):
    """Monaghan's cubic spline in 2D (1/m²), support ``2h``: the kernel handed to the
    density exercise."""
    return kernels.cubic(r, h, 2)


def _answer(ck: Checker, what: str, func, *args):
    """The answer as a float array, or None after recording why it is not one."""
    ok, got = call(ck, what, func, *args)
    if not ok:
        return None
    arr = as_array(got)
    if arr is None:
        ck.expect(False, what, f"expected an array of numbers, got {type(got).__name__}")
    elif arr.size and not np.all(np.isfinite(arr)):
        ck.expect(False, what, "your function returned NaN or inf",
                  "look for a division by zero or a value taken outside its range")
        return None
    return arr


_ARRAY_HINT = ("r is an array of any shape: `if r <= h` cannot decide for all of them at once; "
               "use np.where(r <= h, ..., 0.0) or clip h² - r² at 0")


@exercise(allow=())
def poly6_2d(ck: Checker, func) -> None:
    """``func(r, h) -> W``: ``σ (h² - r²)³`` for ``r ≤ h``, 0 beyond, normalised in 2D."""
    rng = np.random.default_rng(_SEED)
    for h in (0.1, 0.037):
        r = rng.permutation(np.concatenate([[0.0, 0.5 * h, h], rng.uniform(0, 1.6 * h, 9)]))
        r = r.reshape(3, 4)
        shape = np.clip(h * h - r * r, 0.0, None) ** 3
        mistakes = {
            ("that is the 3D constant; redo the integral over the plane",
             "∫₀ʰ σ (h² - r²)³ 2πr dr: substitute u = h² - r², du = -2r dr; 315/(64π h⁹) "
             "normalises the kernel in 3D"): 315 / (64 * np.pi * h**9) * shape,
            ("σ must scale with h: W is in 1/m², and (h² - r²)³ carries m⁶, so σ carries 1/h⁸",
             "write (h² - r²)³ = h⁶ (1 - q²)³ with q = r/h and redo the integral in q"):
                4 / (np.pi * h**2) * shape,
            ("σ must scale with h: W is in 1/m², and (h² - r²)³ carries m⁶ (σ = 4/π is right "
             "only for h = 1 m)"): 4 / np.pi * shape,
            ("the area element of the plane is 2πr dr, not dr",
             "∫ W dA = ∫₀ʰ W(r) 2πr dr; without 2πr you normalised a 1D half line"):
                35 / (16 * h**7) * shape,
            "a factor π is missing from σ (the plane's area element is 2πr dr)": 4 / h**8 * shape,
            ("beyond r = h the kernel must be 0, not σ (h² - r²)³",
             "(h² - r²)³ turns negative past the support: use np.where(r <= h, ..., 0) or "
             "clip h² - r² at 0"): 4 / (np.pi * h**8) * (h * h - r * r) ** 3,
        }
        what = f"h = {h} m: W at 12 distances in [0, 1.6 h], unsorted, as a 3 × 4 array"
        try:
            got = func(r.copy(), h)
        except ValueError as exc:
            if "truth value" in str(exc):
                ck.expect(False, what, f"your function raised ValueError: {exc}", _ARRAY_HINT)
                return
            raise
        if as_array(got) is None:
            ck.expect(False, what, f"expected an array of numbers, got {type(got).__name__}")
            return
        close(ck, got, kernels.poly6(r, h, 2), what, rtol=1e-10, atol=0.0, mistakes=mistakes)
    # the normalisation itself: Gauss-Legendre with 16 nodes is exact for W(r) r (degree 7)
    h = 0.05
    nodes, weights = np.polynomial.legendre.leggauss(16)
    r = 0.5 * h * (nodes + 1.0)
    got = _answer(ck, "∫ W dA = 1 over the plane (h = 0.05 m)", func, r, h)
    if got is None:
        return
    if got.shape != r.shape:
        ck.expect(False, "∫ W dA = 1 over the plane (h = 0.05 m)",
                  "could not evaluate W on an array of distances")
        return
    area = float(np.sum(0.5 * h * weights * got.astype(float) * 2 * np.pi * r))
    tol = rtol_for(got, 1e-10)
    ck.expect(abs(area - 1.0) <= tol, "∫ W dA = 1 over the plane (h = 0.05 m)",
              f"got 1 {'+' if area >= 1 else '-'} {abs(area - 1.0):.2g}",
              hint="choose σ so that ∫₀ʰ W(r) 2πr dr = 1")


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
    lattice_ok = None
    for what, n, lattice in (("a 10 × 10 lattice block, unequal masses", 100, True),
                             ("60 scattered particles, unequal masses, one alone", 60, False)):
        x, m = _particles(n, rng, lattice)
        r = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=-1)
        W = kernels.cubic(r, h, 2)
        expected = W @ m
        upper = np.triu(W, 1)
        mistakes = {
            ("each particle counts itself too: add m_i W(0, h)",
             "the sum runs over every j within the support, j = i included (a particle alone "
             "has ρ = m W(0), not 0)"): expected - m * W[0, 0],
            ("weight neighbour j by its own mass m_j, not by m_i",
             "ρ_i = Σ_j m_j W_ij: with equal masses the two agree, ours are unequal"):
                m * W.sum(axis=1),
            ("each pair adds to both particles: a pair listed once (i < j) must add to ρ_i and to ρ_j",
             "add m_j W_ij to ρ_i and m_i W_ij to ρ_j, e.g. with np.add.at or np.bincount"):
                m * W[0, 0] + upper @ m,
            "the cubic spline reaches 2h, not h: search for pairs within 2h":
                np.where(r < h, W, 0.0) @ m,
            "use each neighbour's own mass m_j, not one mean mass for all": W @ np.full(n, m.mean()),
        }
        args = (x.copy(), m.copy(), h, cubic_2d)
        got = _answer(ck, what, func, *args)
        if got is None:
            return
        if not (np.array_equal(args[0], x) and np.array_equal(args[1], m)):
            ck.expect(False, what, "your function changed x or m",
                      hint="build a new array for ρ instead of updating the inputs")
            continue
        hint = None
        single = m * W[0, 0] + 2 * (upper * m).max()      # self plus one pair term from each end
        if got.shape == expected.shape and np.all(got <= single) and np.any(got > 1.01 * m * W[0, 0]):
            # every particle got at most one term from each end of its pairs: buffered updates
            hint = ("rho[i] += ... with an index array i that repeats adds only one term per "
                    "particle (NumPy applies fancy-index updates once)",
                    "np.add.at(rho, i, values) adds every term; so does np.bincount(i, values, minlength=N)")
        elif not lattice and lattice_ok:
            hint = ("right on the sorted lattice, wrong on scattered particles: find neighbours "
                    "by distance (cKDTree), not by their place in the array")
        ok = close(ck, got, expected, what, rtol=1e-10, atol=0.0, hint=hint,
                   mistakes=None if hint else mistakes)
        lattice_ok = ok if lattice else lattice_ok


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
        last = np.zeros((n, 2))
        last[i] += m[j, None] * f                               # what buffered updates keep
        last[j] += -m[i, None] * f
        mean = -(2 * (p[i] + p[j]) / (rho[i] + rho[j]) ** 2)[:, None] * g
        naive = _scatter(i, -(m[j] * p[j] / rho[j])[:, None] * g, n) \
            + _scatter(j, (m[i] * p[i] / rho[i])[:, None] * g, n)
        over_rho = -((p / rho)[i] + (p / rho)[j])[:, None] * g
        mistakes = {
            ("each listed pair pushes both particles: particle j gets a push too",
             "∇_j W_ji = -∇_i W_ij: what does j receive from the pair (i, j)?"):
                _scatter(i, m[j, None] * f, n),
            ("the pair pushes i and j in opposite directions (Newton's third law): j's term has "
             "the opposite sign of i's"): _scatter(i, m[j, None] * f, n) + _scatter(j, m[i, None] * f, n),
            "sign: pressure pushes particles apart, a_i = -Σ_j m_j (...) ∇_i W_ij": -expected,
            ("a[i] += f with an index array i that repeats adds only one term per particle "
             "(NumPy applies fancy-index updates once)", "use np.add.at(a, i, f) or "
             "np.bincount per axis"): last,
            ("that is -(1/ρ_i) Σ_j m_j (p_j/ρ_j) ∇W_ij: a fine estimate of -∇p/ρ but not "
             "symmetric in the pair, so momentum drifts", "use p_i/ρ_i² + p_j/ρ_j², the same "
             "for both particles of a pair"): naive / rho[:, None],
            "divide each pressure by ρ², not ρ (p/ρ² has units of m⁵/(kg s²) in 2D)":
                _scatter(i, m[j, None] * over_rho, n) + _scatter(j, -m[i, None] * over_rho, n),
            "weight by the neighbour's mass m_j (for particle j: m_i), not by your own":
                _scatter(i, m[i, None] * f, n) + _scatter(j, -m[j, None] * f, n),
            "that is the force m_i a_i: return the acceleration, divide by m_i": m[:, None] * expected,
            ("2 p̄/ρ̄² is also symmetric, but this exercise asks for p_i/ρ_i² + p_j/ρ_j² "
             "(Monaghan 1992)"): _scatter(i, m[j, None] * mean, n) + _scatter(j, -m[i, None] * mean, n),
        }
        args = (i.copy(), j.copy(), g.copy(), m.copy(), rho.copy(), p.copy())
        what = f"{n} particles, {len(i)} pairs listed once in no order ({case + 1})"
        got = _answer(ck, what, func, *args)
        if got is None:
            return
        if not close(ck, got, expected, what, rtol=1e-10, atol=1e-10 * np.abs(expected).max(),
                     mistakes=mistakes):
            continue
        total = np.abs((m[:, None] * got).sum(axis=0)).max()
        scale = np.sum(m[:, None] * np.abs(got))
        ck.expect(total <= 64 * np.finfo(got.dtype).eps * scale,
                  f"({case + 1}) total force Σ m_i a_i = 0 to round-off (below 64 ε Σ m_i |a_i|): "
                  "momentum is conserved", f"|Σ m a| = {total:.3g} N/m against Σ m|a| = {scale:.3g}")


@exercise(allow=())
def jacobi(ck: Checker, func) -> None:
    """``func(apply_A, a_ii, source, p0, rho0, omega, tolerance, max_sweeps) -> (p, sweeps)``."""
    for what, A, diag, source, p0, rho0, omega, tol, cap in jacobi_cases():
        args = (diag, source, p0, rho0, omega, tol, cap)
        p_ref, n_ref = iisph.jacobi(lambda p, A=A: A @ p, *args)
        mistakes = {
            ("a free surface cannot pull: clamp the pressures at 0 after each update",
             "p ← max(0, p + ω r / a_ii), e.g. np.maximum(..., 0.0)"):
                jacobi_variant(A, *args, clamp=False),
            "relax the update: p + ω r / a_ii, with the ω handed to you":
                jacobi_variant(A, *args, relax=False),
            ("stop on the compression only, mean(max(-r, 0))/ρ₀: a particle below ρ₀ at the "
             "free surface is no error"): jacobi_variant(A, *args, test="residual"),
            ("measure the compression on this sweep's residual, before you update p; stop after "
             "the update"): jacobi_variant(A, *args, order="after"),
            ("a_ii is negative: a compressed particle (r < 0) must get a higher pressure, which "
             "p + ω r / a_ii gives"): jacobi_variant(A, *args, sign=-1.0),
        }
        with np.errstate(all="ignore"):
            ok, got = call(ck, what, func, lambda p, A=A: A @ np.asarray(p, dtype=float),
                           diag.copy(), source.copy(), p0.copy(), rho0, omega, tol, cap)
        if not ok:
            continue
        if not (isinstance(got, tuple | list) and len(got) == 2):
            ck.expect(False, what, f"expected a pair (p, sweeps), got {type(got).__name__}")
            continue
        p = as_array(got[0])
        if p is None or p.shape != p_ref.shape or not np.all(np.isfinite(p)):
            ck.expect(False, what, "p is not an array of N finite pressures",
                      ("a_ii < 0 for every particle with neighbours: divide only where a_ii < 0 "
                       "and leave a particle without neighbours (a_ii = 0) at p = 0",
                       "np.divide(omega, a_ii, out=np.zeros_like(a_ii), where=a_ii < 0)"))
            continue
        if np.any(p < 0):
            ck.expect(False, what, f"{int(np.sum(p < 0))} negative pressures", next(iter(mistakes)))
            continue
        hint = next((h for h, (pv, nv) in mistakes.items() if nv == got[1] and p.shape == pv.shape
                     and np.allclose(p, pv, rtol=1e-9, atol=1e-9 * np.abs(pv).max())), None)
        if close(ck, p, p_ref, f"{what}: the pressures", rtol=1e-9,
                 atol=1e-9 * np.abs(p_ref).max(), hint=hint):
            ck.expect(got[1] == n_ref, f"{what}: {n_ref} sweeps", f"you counted {got[1]!r}",
                      "count every sweep, the first one as 1, and stop after the sweep whose "
                      "residual meets the tolerance (or after max_sweeps)")


@exercise(allow=())
def front_errors(ck: Checker, func) -> None:
    """``func(t, z, a, table, delay) -> errors``: ``Z_run(T - ΔT)/Z - 1`` at the table's times."""
    for what, t, z, a, table, delay in front_cases():
        expected = scenes.front_errors(t, z, a, table, delay)
        args = (t, z, a, table, delay)
        mistakes = {
            ("Martin & Moyce's time for their n² = 2 column is T = t √(2g/a)",
             "they scale time by n √(g/a) with n = √2"): front_variant(*args, time="g/a"),
            ("z is measured from the back wall, so Z = z/a (1 at the start), not from the "
             "column's face"): front_variant(*args, origin="face"),
            ("a delayed run is at T the front it had at T - ΔT: interpolate at T - ΔT",
             "np.interp(T_table - delay, T_run, Z_run)"): front_variant(*args, sign=1.0),
            "the error is relative to the measurement: Z_run / Z_table - 1":
                front_variant(*args, relative="table"),
            "return the relative error Z_run / Z_table - 1, not the difference":
                front_variant(*args, relative="difference"),
            "use g = 9.81 m/s²": front_variant(*args, g=9.8),
            ("interpolate the run between its steps (np.interp) instead of taking the "
             "nearest step"): front_variant(*args, sample="nearest"),
        }
        got = _answer(ck, what, func, t.copy(), z.copy(), a, table.copy(), delay)
        if got is None:
            return
        if got.shape != expected.shape:
            ck.expect(False, what, f"expected {len(table)} errors, one per row of the table, got "
                      f"shape {got.shape}", "compare at the times of the table handed to you, "
                      "which need not be Martin & Moyce's")
            continue
        close(ck, got, expected, what, rtol=1e-9, atol=1e-12, mistakes=mistakes)
