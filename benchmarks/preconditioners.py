"""What a better preconditioner would buy the Baraff–Witkin step (an informational row).

The implicit step's cost is ``(CG iterations) × (one product with A + one application of
the preconditioner)`` plus the setup. Jacobi (what :class:`~course_lib.baraff_witkin.
BaraffWitkin` uses) is nearly free to apply but needs tens of iterations at ten times the
explicit limit; a stronger preconditioner needs fewer iterations but each application
costs more. This module measures both sides on the benchmark cloth, in units of one
explicit step, for the preconditioners SciPy has:

- Jacobi, ``diag(A)⁻¹``;
- incomplete LU (SuperLU's ILUTP, drop tolerance 1e-2);
- the exact sparse LU of ``A`` itself: one iteration, the best a factorization reused from
  an earlier step (a "lagged" preconditioner) could ever do.

``A`` is assembled from :mod:`course_lib.springs.jacobian` and checked equal (1e-12) to the
solver's matrix-free operator before anything is timed.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.timing import CPU
from course_lib.baraff_witkin import BaraffWitkin
from course_lib.springs import jacobian


def assembled(solver: BaraffWitkin, x, v, dt: float):
    """The filtered matrix ``S A S + I - S`` of one step as CSR, and the right side."""
    A_op, b, _ = solver.system(x, v, dt)
    n = b.size
    mass = np.repeat(solver.mass, x.shape[1])
    A = (sp.diags(mass) - dt * jacobian.jacobian_v(solver.network, x)
         - dt * dt * jacobian.jacobian_x(solver.network, x, definite=solver.definite))
    keep = np.ones(n)
    keep.reshape(x.shape)[solver.pinned] = 0.0
    S = sp.diags(keep)
    A = (S @ A @ S + sp.diags(1.0 - keep)).tocsr()
    probe = np.random.default_rng(1).standard_normal(n)
    want = A_op @ probe
    if not np.allclose(A @ probe, want, rtol=0.0, atol=1e-12 * np.abs(want).max()):
        raise AssertionError("the assembled matrix differs from the solver's operator")
    return A, b


def _seconds(f, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = CPU()
        f()
        times.append(CPU() - start)
    return float(np.median(times))


def study(solver: BaraffWitkin, x, v, dt: float, explicit_step: float, rtol: float) -> str:
    """One line: per preconditioner, CG iterations from zero, application and setup cost."""
    A, b = assembled(solver, x, v, dt)
    product = _seconds(lambda: A @ b, 20)
    parts = []
    def jacobi():
        diagonal = A.diagonal()
        return lambda r: r / diagonal

    candidates = {
        "Jacobi": jacobi,
        "ILU(1e-2)": lambda: spla.spilu(A.tocsc(), drop_tol=1e-2, fill_factor=3).solve,
        "exact LU": lambda: spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A").solve,
    }
    for name, build in candidates.items():
        setup = _seconds(build, 1)
        apply = build()
        cost = _seconds(lambda a=apply: a(b), 5)
        count = [0]
        M = spla.LinearOperator(A.shape, matvec=apply, dtype=float)
        spla.cg(A, b, rtol=rtol, atol=0.0, M=M, maxiter=10 * b.size,
                callback=lambda _, c=count: c.__setitem__(0, c[0] + 1))
        per_step = count[0] * (product + cost)
        parts.append(f"{name}: {count[0]} its × {(product + cost) / explicit_step:.1f} "
                     f"= {per_step / explicit_step:.0f}× (+ setup {setup / explicit_step:.0f}×)")
    return "from Δv = 0, in explicit steps: " + "; ".join(parts)
