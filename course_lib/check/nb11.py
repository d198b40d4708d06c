"""Checks for notebook 11, cloth: one spring's Jacobian block, the explicit step limit, one
Baraff-Witkin solve by conjugate gradients, and the peak stretch of a run.

No answer may call the library (``allow=()``): ``cl.springs.jacobian_x``, which the first
exercise is about, and :class:`~course_lib.baraff_witkin.BaraffWitkin`, which the third
is about, are refused like every other library function; SciPy's ``cg`` is fine. A failure
is reported in one line (the largest difference and where), and a hint names a mistake
only when the answer is what that mistake gives: a clamped sideways term, 1 - ℓ/L, d for
u, a block scaled by the strain (Exercise 1); one mass for all, or eigvalsh on the
non-symmetric M⁻¹K (2); the leading h missing from b, or a solve that leaves a residual
(3, judged on the answer's own residual first; direct solvers and the other Krylov solvers
are refused, the exercise is conjugate gradients, and Δv has the shape of v0); ℓ/L, the
first or the last frame, one rest length for all, lengths measured from the first frame, a clamp at 0 (4).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg

from .. import springs
from ..baraff_witkin import BaraffWitkin
from . import Checker, Hint, apart, exercise
from . import _nb11_cases as _cases

_SEED = 1111


def _judge(ck: Checker, got, expected, what: str, *, rtol: float, atol: float,
           mistakes=None, hint: Hint = None, unit: str = "") -> bool:
    """Compare an answer with the expected number or array. A failure names the usual
    mistake it matches (``mistakes``: a dict hint -> wrong value, or (hint, wrong value)
    pairs; the first match, within a hundred times the tolerance, wins), else ``hint``, and
    says where
    the answer is furthest off in one line, not as a wall of numbers."""
    e = np.asarray(expected, dtype=float)
    try:
        a = np.asarray(got, dtype=float)
    except (TypeError, ValueError):
        wanted = "a number" if e.size == 1 else f"an array of shape {e.shape}"
        return ck.expect(False, what, f"expected {wanted}, got {type(got).__name__}", hint)
    if a.size == e.size == 1:
        a = a.reshape(e.shape)
    if a.shape != e.shape:
        return ck.expect(False, what, f"expected shape {e.shape}, got shape {a.shape}", hint)
    if not np.all(np.isfinite(a)):
        return ck.expect(False, what, "your answer holds NaN or inf",
                         "look for a division by zero or an unconverged solve")
    if np.allclose(a, e, rtol=rtol, atol=atol):
        return ck.expect(True, what)
    pairs = mistakes.items() if isinstance(mistakes, dict) else (mistakes or ())
    for mistake, wrong in pairs:       # a diagnosis, not a verdict: matched a hundred times looser
        w = np.asarray(wrong, dtype=float)
        if w.shape == a.shape and np.allclose(a, w, rtol=100 * rtol, atol=100 * atol):
            hint = mistake
            break
    if e.size == 1:
        return ck.expect(False, what, "expected {}, got {}".format(*apart(float(e), float(a))), hint)
    excess = np.abs(a - e) - (atol + rtol * np.abs(e))
    at = np.unravel_index(int(np.argmax(excess)), e.shape)
    where = ", ".join(str(int(k)) for k in at)
    shown_e, shown_a = apart(float(e[at]), float(a[at]))     # more digits when 6 print alike
    return ck.expect(False, what, f"{int(np.sum(excess > 0))} of {e.size} entries differ; the largest "
                     f"difference, {abs(a[at] - e[at]):.2g}{unit}, is at [{where}]: expected "
                     f"{shown_e}, got {shown_a}", hint)


def _jacobian_mistakes(d, k, rest, expected) -> dict:
    """The usual wrong blocks for one spring, with their hints (those equal to the right
    block on this spring, e.g. a clamp on a stretched spring, left out)."""
    length = np.linalg.norm(d)
    u = d / length
    uu, side = np.outer(u, u), np.eye(3) - np.outer(u, u)
    dd = np.outer(d, d)
    mistakes = {
        ("sign: moving x_i away from x_j along the spring makes F_i pull back harder",
         "∂F_i/∂x_i = -k[...] is negative along u"): -expected,
        ("you kept only the stiffness along the spring: a stretched spring also pulls a "
         "sideways displacement back", "add (1 - L/ℓ)(I - u uᵀ) for the sideways part")
        if length > rest else
        ("a compressed spring's sideways term, (1 - L/ℓ)(I - u uᵀ), is negative, and it belongs in "
         "∂F/∂x: did you leave it out, or clamp it at 0? Dropping it is a choice some solvers make "
         "for the solve (Choi & Ko 2002), not part of the derivative",
         "keep (1 - L/ℓ)(I - u uᵀ) with its sign: 1 - L/ℓ < 0 when ℓ < L"): -k * uu,
        ("the sideways stiffness acts across the spring only: (1 - L/ℓ) multiplies (I - u uᵀ), the "
         "projection across the spring, not the whole identity",
         "(1 - L/ℓ) I also adds (1 - L/ℓ) u uᵀ along the spring; the sideways term is "
         "(1 - L/ℓ)(I - u uᵀ), which is zero along u"): -k * (uu + (1 - rest / length) * np.eye(3)),
        ("check the sideways factor at ℓ = L: a spring at rest has no sideways stiffness",
         "the sideways factor is (1 - L/ℓ), not L/ℓ"): -k * (uu + rest / length * side),
        ("the sideways factor is the tension k(ℓ - L) divided by k ℓ",
         "the sideways factor is (1 - L/ℓ), not (1 - ℓ/L)"): -k * (uu + (1.0 - length / rest) * side),
        ("the sideways factor must be dimensionless", "the sideways factor is (1 - L/ℓ), "
         "not ℓ - L"): -k * (uu + (length - rest) * side),
        ("u uᵀ must be built from a unit vector", "use u = d/|d| in u uᵀ, not d itself"):
            -k * (dd + (1 - rest / length) * side),
        ("u uᵀ and I - u uᵀ need the unit vector u = d/|d|", "build both from u = d/|d|, not d"):
            -k * (dd + (1 - rest / length) * (np.eye(3) - dd)),
        ("along the spring the stiffness is the full k, whatever the stretch: only the "
         "sideways part scales with the stretch", "-k [u uᵀ + (1 - L/ℓ)(I - u uᵀ)]: the first term "
         "is not scaled"): -k * (1.0 - rest / length) * np.eye(3),
        ("along the spring the stiffness is the full k, whatever the stretch",
         "-k [u uᵀ + (1 - L/ℓ)(I - u uᵀ)]: nothing is scaled by the strain (ℓ - L)/L"):
            -k * (length - rest) / rest * np.eye(3),
    }
    return {h: w for h, w in mistakes.items() if not np.allclose(w, expected, rtol=1e-9, atol=1e-9)}


#: For an answer close to the right block but not equal to it (a finite difference).
_CLOSE_FORM = ("close, but not exact: is it a finite difference? The check wants Section 3's closed "
               "form, exact to round-off", "write the closed form, -k[u uᵀ + (1 - L/ℓ)(I - u uᵀ)]")


@exercise(allow=())
def spring_jacobian(ck: Checker, func) -> None:
    """``func(xi, xj, k, rest) -> (3, 3)``: ``∂F_i/∂x_i`` of one Hooke spring."""
    rng = np.random.default_rng(_SEED + 1)
    for what, d, k, rest in _cases.spring_cases():
        xj = rng.normal(size=3)
        xi = xj + d
        net = springs.SpringNetwork([0], [1], [rest], [k], [0.0], 2)
        expected = springs.jacobian_x(net, np.stack((xi, xj))).toarray()[:3, :3]
        got = func(xi.copy(), xj.copy(), k, rest)
        near = np.allclose(np.asarray(got, dtype=float), expected, rtol=1e-4, atol=1e-6) \
            if np.shape(got) == (3, 3) else False
        _judge(ck, got, expected, f"{what}: ℓ = {np.linalg.norm(d):.3f} m, L = {rest:g} m, k = {k:g} N/m",
               rtol=1e-9, atol=1e-9, mistakes=_jacobian_mistakes(d, k, rest, expected),
               hint=_CLOSE_FORM if near else None, unit=" N/m")
    # against central differences of the force
    xi, xj, k, rest = np.array([0.3, -0.2, 0.9]), np.array([-0.1, 0.4, 0.2]), 80.0, 0.5
    h = 1e-6
    fd = np.stack([(springs.spring_force_pair(xi + h * e, xj, k, rest)
                    - springs.spring_force_pair(xi - h * e, xj, k, rest)) / (2 * h) for e in np.eye(3)],
                  axis=1)
    got = np.asarray(func(xi.copy(), xj.copy(), k, rest), dtype=float)
    _judge(ck, got, fd, "matches central differences of the force", rtol=1e-6, atol=1e-6, unit=" N/m",
           mistakes=_jacobian_mistakes(xi - xj, k, rest, fd))
    square = got.shape == (3, 3)
    nearly = square and np.allclose(got, got.T, rtol=1e-6, atol=1e-9)
    _judge(ck, got, got.T if square else fd, "symmetric", rtol=1e-12, atol=1e-12,
           hint=_CLOSE_FORM if nearly else "each term, u uᵀ and I - u uᵀ, is symmetric")


@exercise(allow=())
def explicit_limit(ck: Checker, func) -> None:
    """``func(K, mass) -> dt_max``: symplectic Euler's limit from a stiffness matrix."""
    for what, c, mass in _cases.limit_cases():
        free = np.setdiff1d(np.arange(c.n), c.pinned)
        dofs = (free[:, None] * 3 + np.arange(3)).ravel()
        K = springs.stiffness_matrix(c.network, c.x0)[np.ix_(dofs, dofs)]
        m = mass[free]
        expected = 2.0 / springs.max_frequency(c.network, c.x0, mass, c.pinned)
        m3 = np.repeat(m, 3)
        lam = np.linalg.eigvalsh(K / np.sqrt(np.outer(m3, m3)))
        tiled = np.tile(m, 3)
        one_mass = ("with unequal masses no single mass will do", "with unequal masses no single "
                    "mass will do: scale each row and column of K by 1/√m of its own particle")
        mistakes = {
            ("include the masses: the frequencies solve K φ = ω² M φ",
             "include the masses: use the eigenvalues of M^(-1/2) K M^(-1/2)"):
                2.0 / np.sqrt(np.linalg.eigvalsh(K).max()),
            ("the eigenvalues are ω², not ω", "take a square root: dt_max = 2/√λ_max"):
                2.0 / lam.max(),
            ("check the stability condition of symplectic Euler (notebook 07)",
             "symplectic Euler is stable for ω dt < 2: dt_max = 2/ω_max, not 1/ω_max"):
                1.0 / np.sqrt(lam.max()),
            ("each particle owns three rows in a row (x, y, z)",
             "each particle owns three rows in a row (x, y, z): np.repeat(mass, 3), not np.tile"):
                2.0 / np.sqrt(np.linalg.eigvalsh(K / np.sqrt(np.outer(tiled, tiled))).max()),
        }
        one_sided = ("M⁻¹K is not symmetric when the masses differ, and eigvalsh reads only one "
                     "triangle of a matrix: it returns the eigenvalues of another matrix",
                     "scale the rows and the columns alike, by 1/√m each: M^(-1/2) K M^(-1/2) is "
                     "symmetric and has the eigenvalues of M⁻¹K")
        pairs = [*mistakes.items(), *((one_mass, 2.0 / np.sqrt(np.linalg.eigvalsh(K).max() / m_one))
                                      for m_one in (m.mean(), m.max(), m.min())),
                 (one_sided, 2.0 / np.sqrt(np.linalg.eigvalsh(K / m3[:, None]).max())),
                 (one_sided, 2.0 / np.sqrt(np.linalg.eigvalsh(K / m3[None, :]).max()))]
        pairs = [(h, w) for h, w in pairs if not np.isclose(w, expected, rtol=1e-8)]
        got = func(K.copy(), m.copy())
        _judge(ck, got, expected, f"{what}: {K.shape[0]} unknowns", rtol=1e-8, atol=0.0,
               mistakes=pairs, hint=("which matrix's largest eigenvalue is ω_max²? The modes solve "
                                     "K φ = ω² M φ", "the largest eigenvalue λ_max of "
                                     "M^(-1/2) K M^(-1/2) is ω_max²: dt_max = 2/√λ_max"))


# --- one Baraff-Witkin solve ------------------------------------------------------------


#: Relative residual below which a wrong Δv is called unconverged (a loose rtol), not wrong:
#: CG stops at ||r|| <= rtol ||b||, and every structural mistake leaves 1e-3 or more here
#: unless it gives the right Δv anyway (tests/test_nb11_hints.py).
_CONVERGED = 1e-4

#: Direct solvers, refused in the Baraff-Witkin solve: the exercise is conjugate gradients
#: (a factorization is exact here, but it is not what the prompt asks, nor what scales).
DIRECT_SOLVERS = ("scipy.sparse.linalg._dsolve", "scipy.linalg", scipy.sparse.linalg.spsolve,
                  scipy.sparse.linalg.splu, scipy.sparse.linalg.factorized, np.linalg.solve,
                  np.linalg.inv, np.linalg.lstsq, np.linalg.pinv, np.linalg.tensorsolve)
#: The other Krylov solvers, refused by name (GMRES was refused only for the BLAS it calls,
#: and the message named that): the exercise asks for conjugate gradients.
OTHER_KRYLOV = tuple(getattr(scipy.sparse.linalg, name) for name in (
    "gmres", "lgmres", "gcrotmk", "bicg", "bicgstab", "cgs", "qmr", "tfqmr", "minres", "lsqr",
    "lsmr") if hasattr(scipy.sparse.linalg, name)) + tuple(
    # the modules that hold no CG, also watched while the answer runs (an import inside it)
    f"scipy.sparse.linalg._isolve.{m}" for m in ("lgmres", "_gcrotmk", "tfqmr", "minres", "lsqr", "lsmr"))


@exercise(allow=(), forbid=DIRECT_SOLVERS + OTHER_KRYLOV)
def bw_velocity_change(ck: Checker, func) -> None:
    """``func(mass, dFdx, dFdv, F0, v0, h) -> (N, 3)``: Δv of one Baraff-Witkin step, by
    conjugate gradients (direct solvers are refused, :data:`DIRECT_SOLVERS`)."""
    h = 1.0 / 30.0
    for what, net, x, v, mass in _cases.solve_cases():
        dFdx, dFdv = springs.jacobian_x(net, x).tocsr(), springs.jacobian_v(net, x).tocsr()
        F0 = net.forces(x, v).copy()
        # the exact linearization (definite=False keeps every geometric term), solved tightly
        solver = BaraffWitkin(net, mass, rtol=1e-13, definite=False, warm_start=False)
        expected = solver.step(x, v, h)[1] - v
        m3 = np.repeat(mass, 3)
        dense_x, dense_v = dFdx.toarray(), dFdv.toarray()

        def solve(A, b, shape=x.shape):
            return np.linalg.solve(A, b).reshape(shape)

        right = F0.ravel() + h * (dense_x @ v.ravel())          # F0 + h ∂F/∂x v0
        mistakes = {
            ("the damping force also depends on the end velocity: keep the h ∂F/∂v term",
             "A = M - h ∂F/∂v - h² ∂F/∂x"): solve(np.diag(m3) - h * h * dense_x, h * right),
            ("the force at the end of the step also depends on where the start velocity takes "
             "the particles", "b = h (F0 + h ∂F/∂x v0)"):
                solve(np.diag(m3) - h * dense_v - h * h * dense_x, h * F0.ravel()),
            ("sign: ∂F/∂x is negative definite for springs, so -h² ∂F/∂x adds stiffness",
             "A = M - h ∂F/∂v - h² ∂F/∂x, with the minus sign"):
                solve(np.diag(m3) - h * dense_v + h * h * dense_x, h * right),
            ("each particle's mass sits on its three rows (x, y, z)",
             "use np.repeat(mass, 3), not np.tile"):
                solve(np.diag(np.tile(mass, 3)) - h * dense_v - h * h * dense_x, h * right),
            ("return the change of velocity, not the new velocity", "return Δv = v1 - v0"):
                expected + v,
            ("check the units of the right side: ∂F/∂x v0 is in N/s", "b = h (F0 + h ∂F/∂x v0): "
             "the force's change over the step is h ∂F/∂x v0"):
                solve(np.diag(m3) - h * dense_v - h * h * dense_x, h * (F0.ravel() + dense_x @ v.ravel())),
            ("check the units of the right side: A Δv is a momentum (kg m/s), so b is an impulse, "
             "force × time", "b = h (F0 + h ∂F/∂x v0): the leading h is missing"):
                solve(np.diag(m3) - h * dense_v - h * h * dense_x, right),
        }
        got = func(mass.copy(), dFdx.copy(), dFdv.copy(), F0.copy(), v.copy(), h)
        try:
            got = np.asarray(got, dtype=float)
        except (TypeError, ValueError):
            ck.expect(False, what, f"expected an array of shape {x.shape}, got {type(got).__name__}")
            continue
        if got.shape != x.shape and got.size == x.size:
            ck.expect(False, what, f"expected Δv of shape {x.shape}, like v0, got shape {got.shape}",
                      hint=("return Δv with the shape of v0: one row per particle",
                            "CG works on flat vectors of 3N coordinates: reshape its answer with "
                            "dv.reshape(v0.shape)"))
            continue
        scale = np.abs(expected).max()
        A = np.diag(m3) - h * dense_v - h * h * dense_x
        shaped = got.shape == x.shape and np.all(np.isfinite(got))
        residual = (np.linalg.norm(h * right - A @ got.ravel()) / np.linalg.norm(h * right)
                    if shaped else np.inf)
        # a mistake is diagnosed only when the answer is far nearer to it than to the right Δv:
        # on an undamped cloth, or with equal masses, several mistakes give the right Δv
        off = np.linalg.norm(got - expected) if shaped else np.inf
        mistakes = {m: w for m, w in mistakes.items()
                    if not shaped or np.linalg.norm(got - np.reshape(w, got.shape)) < 0.1 * off}
        if residual < _CONVERGED and not mistakes:      # the residual first: a loose tolerance
            hint = ("your Δv solves the system, but only roughly: is the solve converged? Not yet: "
                    "tighten rtol",
                    f"your Δv leaves a relative residual of {residual:.0e}: conjugate gradients "
                    "stop at their tolerance, so pass rtol=1e-10 (SciPy's default, 1e-5, leaves "
                    "errors of about κ × 1e-5)")
        else:
            hint = ("compare your A and b with Section 3's system term by term: what do the "
                    "failing cases have in common (damping, motion, unequal masses)?",)
        _judge(ck, got, expected, what, rtol=1e-6, atol=1e-7 * scale, mistakes=mistakes, hint=hint,
               unit=" m/s")


# --- the peak stretch of a run --------------------------------------------------------------


@exercise(allow=())
def peak_strain(ck: Checker, func) -> None:
    """``func(x, i, j, rest) -> float``: the largest ``(ℓ - L)/L`` over frames and springs."""
    for what, x, s in _cases.strain_cases():
        length = np.linalg.norm(x[:, s.j] - x[:, s.i], axis=-1)        # (frames, springs)
        strain = (length - s.rest) / s.rest
        expected = float(strain.max())
        mistakes = [
            (("compression is not stretch: take the largest (ℓ - L)/L, keeping its sign",
              "np.max((ℓ - L) / L), not np.max(|ℓ - L| / L)"), float(np.abs(strain).max())),
            (("a strain can be negative: when every spring is compressed, the largest strain is "
              "below 0", "return np.max((ℓ - L) / L) as it is, without clamping it at 0"),
             max(0.0, expected)),
            (("the stretch can peak before the last frame", "take the largest over every frame"),
             float(strain[-1].max())),
            (("the stretch can peak in any frame, the first too", "take the largest over every frame"),
             float(strain[0].max())),
            (("strain is relative to the rest length L", "(ℓ - L) / L, not (ℓ - L) / ℓ"),
             float(((length - s.rest) / length).max())),
            (("strain is 0 at rest: (ℓ - L)/L, not ℓ/L", "subtract 1: (ℓ - L)/L = ℓ/L - 1"),
             float((length / s.rest).max())),
            (("each spring has its own rest length", "divide by rest[s] of each spring, not one "
              "rest length for all"), float(((length - s.rest.mean()) / s.rest.mean()).max())),
            (("each spring has its own rest length, rest[s]: the springs of a cloth differ (shear "
              "springs are √2 times longer, bend springs twice)", "compare each spring's length "
              "with its own rest length rest[s], not with rest[0]"),
             float(((length - s.rest[0]) / s.rest[0]).max())),
            (("`rest` is given: strain is measured from the rest length, not from the first "
              "frame's lengths", "(ℓ - L)/L with L = rest[s]: a cloth can be stretched or "
              "compressed already in the first frame"),
             float(((length - length[0]) / length[0]).max())),
            (("a strain is a fraction", "return the fraction (0.05), not the percentage (5)"),
             100 * expected),
            (("the largest over the springs, not their mean", "np.max over frames and springs"),
             float(strain.mean(axis=1).max())),
        ]
        mistakes = [(h, w) for h, w in mistakes if not np.isclose(w, expected, rtol=1e-9)]
        got = func(x.copy(), s.i.copy(), s.j.copy(), s.rest.copy())
        _judge(ck, got, expected, f"{what}: {len(s.rest)} springs", rtol=1e-9, atol=1e-12,
               mistakes=mistakes)
