"""Case data of notebook 03's checks (:mod:`course_lib.check.nb03`).

- exercise 1: the methods whose ``R(z)`` the check measures (:data:`HIDDEN_METHODS`, one of
  them updating a copy of ``y`` in place, so that a real state fails), where (:data:`Z_GRID`,
  :data:`Z_SCALAR`), and the table's ``R`` an answer may return instead (:data:`TABLE`);
- exercise 3: the fourteen matrices (:data:`MATRIX_CASES`) with the kind of mistake a wrong
  verdict on each points to, the hint of each kind (:data:`MATRIX_HINTS`), and wrong rules
  (a norm, the determinant) recognised by their verdicts (:data:`WRONG_RULES`,
  :func:`follows_rule`);
- exercise 2: the hint for runs too short to reach the blow-up bound (:func:`short_run_hint`),
  and :func:`limit_hint`, the mistake a search's recorded runs point to (its ``probe`` is
  :class:`course_lib.check.nb03.Probe`).

Imports NumPy, :func:`course_lib.check._answers.kutta3` and
:func:`course_lib.stability.amplification_factor`.
"""

from __future__ import annotations

import numpy as np

from ..stability import amplification_factor
from ._answers import kutta3
from .tolerance import escalate


def _two_half_steps(f, t, y, dt):
    """Two forward Euler steps of dt/2: R = (1 + z/2)². Written as a simulator that reuses
    its buffers writes it: it updates a copy of ``y`` in place, so the result keeps y's dtype
    (a real ``y`` cannot hold a complex R: NumPy refuses the cast)."""
    out = np.array(y, copy=True)
    out += 0.5 * dt * f(t, out)
    out += 0.5 * dt * f(t + 0.5 * dt, out)
    return out


def _theta_quarter(f, t, y, dt):
    """The implicit θ-method, θ = 1/4: R = (1 + 3z/4) / (1 - z/4).

    Solves ``u = y + dt (3/4 f(t, y) + 1/4 f(t + dt, u))`` exactly for an ``f`` linear in
    ``u`` (elementwise), from the residual at ``u = 0`` and ``u = 1``.
    """
    known = y + 0.75 * dt * f(t, y)

    def residual(u):
        return u - known - 0.25 * dt * f(t + dt, u)

    r0 = residual(np.zeros_like(known))
    r1 = residual(np.ones_like(known))
    return -r0 / (r1 - r0)


#: (name, stepper, exact R) of the methods the check measures.
HIDDEN_METHODS = [
    ("two forward Euler half steps", _two_half_steps, lambda z: (1 + z / 2) ** 2),
    ("Kutta's third-order method", kutta3, lambda z: 1 + z + z**2 / 2 + z**3 / 6),
    ("the implicit θ-method, θ = 1/4", _theta_quarter, lambda z: (1 + 0.75 * z) / (1 - 0.25 * z)),
]
#: R of the methods in the notebook's table, to name an answer that returns one of them.
TABLE = {"forward Euler's 1 + z": lambda z: 1 + z,
          "the midpoint's 1 + z + z²/2": lambda z: 1 + z + z**2 / 2,
          "RK4's Taylor polynomial": lambda z: 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24,
          "backward Euler's 1/(1 - z)": lambda z: 1 / (1 - z),
          "the trapezoid's (1 + z/2)/(1 - z/2)": lambda z: (1 + z / 2) / (1 - z / 2)}
COMPLEX_STATE = escalate(
    "this method updates a copy of y in place, so its result has y's dtype: a real state "
    "cannot hold a complex R(z). Start from a complex y",
    "np.ones(np.shape(z)) is float64, and out += 0.5 * dt * z * out cannot store the imaginary "
    "part of z = -1 + 1j (NumPy raises a casting error): write y0 = np.ones_like(z, "
    "dtype=complex) or np.ones(np.shape(z), dtype=complex)")


def cast_hint(exc: Exception):
    """The hint for an answer whose real state met a method that updates it in place."""
    return COMPLEX_STATE if isinstance(exc, TypeError) and "cast" in str(exc) else None


#: The points z (any shape) where R is measured.
Z_GRID = np.array([[-2.5, -1.0 + 1.0j, 0.3j], [2.0j, -0.5 - 2.0j, 0.8]])
Z_SCALAR = -1.5 + 0.5j


#: (description, M, bounded, why, kind): the kind names the mistake a wrong verdict on it
#: points to (see :data:`MATRIX_HINTS`).
MATRIX_CASES = [
    ("rotation by 0.3 rad", [[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]], True,
     "|μ| = 1, two distinct eigenvalues", "circle"),
    ("symplectic Euler at ω dt = 2, [[-3, 2], [-2, 1]]", [[-3.0, 2.0], [-2.0, 1.0]], False,
     "double eigenvalue -1 with one eigenvector: a Jordan block, M^n grows like n", "jordan"),
    ("-I", [[-1.0, 0.0], [0.0, -1.0]], True, "double eigenvalue -1, but two eigenvectors",
     "circle"),
    ("shear [[1, 1], [0, 1]]", [[1.0, 1.0], [0.0, 1.0]], False, "Jordan block at +1", "jordan"),
    ("[[0.5, 100], [0, 0.5]]", [[0.5, 100.0], [0.0, 0.5]], True,
     "spectral radius 0.5: a large transient, then decay", "transient"),
    ("diag(1.01, 0.2)", [[1.01, 0.0], [0.0, 0.2]], False, "an eigenvalue 1.01 > 1", "outside"),
    ("forward Euler on the vortex, dt = 0.5", [[1.0, -0.5], [0.5, 1.0]], False,
     "|μ| = √1.25 > 1", "outside"),
    ("diag(1, -1)", [[1.0, 0.0], [0.0, -1.0]], True, "|μ| = 1, distinct", "circle"),
    ("[[0.9, 0.9], [-0.9, 0.9]]", [[0.9, 0.9], [-0.9, 0.9]], False, "|μ| = 0.9 √2 > 1",
     "outside"),
    ("[[1, 0.5], [0, 0.5]]", [[1.0, 0.5], [0.0, 0.5]], True, "eigenvalues 1 and 0.5, distinct",
     "circle"),
    ("diag(1.00001, 0.5)", [[1.00001, 0.0], [0.0, 0.5]], False,
     "an eigenvalue 1.00001 > 1: M^n grows 10-fold only after 230 000 steps, but it grows",
     "slow"),
    ("[[0.99999, 1], [0, 0.99999]]", [[0.99999, 1.0], [0.0, 0.99999]], True,
     "a Jordan block inside the circle: M^n rises to 37 000 (near n = 100 000), then decays",
     "slow"),
    ("[[0.999, 1e306], [0, 0.999]]", [[0.999, 1e306], [0.0, 0.999]], True,
     "a Jordan block inside the circle: M^n rises to 3.7e308 near n = 1000, past the largest "
     "float (1.8e308), then decays", "overflow"),
    ("[[0.9999, 1e305], [0, 0.9998]]", [[0.9999, 1e305], [0.0, 0.9998]], True,
     "eigenvalues 0.9999 and 0.9998: M^n rises to 2.5e308 near n = 7000, past the largest "
     "float, then decays", "overflow"),
]
#: The hint for a wrong verdict on a matrix of each kind, in order of priority.
MATRIX_HINTS = {
    "jordan": escalate(
        "spectral radius ≤ 1 is not enough: an eigenvalue on the unit circle with fewer "
        "eigenvectors than its multiplicity (a Jordan block) makes M^n grow like n",
        "symplectic Euler at ω dt = 2, M = [[-3, 2], [-2, 1]], has μ = -1 twice, but M + I = "
        "[[-2, 2], [-2, 2]] has rank 1: one eigenvector, so M^n = (-1)^n (I - n (M + I)) and "
        "M^10 = [[21, -20], [20, -19]]. For each μ with |μ| = 1 count the eigenvectors, "
        "2 - np.linalg.matrix_rank(M - μ I), against μ's multiplicity"),
    "outside": escalate(
        "an eigenvalue of modulus above 1 makes M^n grow, however slowly: compare each |μ| "
        "with 1, not the trace, the determinant or a norm",
        "diag(1.01, 0.2) has det 0.202 and trace 1.21, yet μ = 1.01 makes M^1000 about "
        "21 000: compare np.abs(np.linalg.eigvals(M)).max() with 1"),
    "circle": escalate(
        "|μ| = 1 neither grows nor decays: on the unit circle the powers stay bounded when each "
        "eigenvalue there has a full set of eigenvectors",
        "-I has μ = -1 twice and two eigenvectors (M - μ I = 0, rank 0): (-I)^n = ±I stays "
        "bounded, and so does a rotation (|μ| = 1, distinct). Call M unbounded on the circle "
        "only when 2 - np.linalg.matrix_rank(M - μ I) is less than μ's multiplicity"),
    "transient": escalate(
        "a large entry or norm is only a transient: what decides the long run is the spectral "
        "radius",
        "[[0.5, 100], [0, 0.5]]^n has the corner entry 100 n 0.5^(n-1): 100 at n = 1 and 2, 75 "
        "at n = 3, below 1e-5 by n = 30. Its eigenvalues are 0.5: decide from "
        "np.abs(np.linalg.eigvals(M)).max()"),
    "overflow": escalate(
        "a harmless matrix whose transient passes the largest float (1.8e308): its powers "
        "overflow to inf or NaN, yet it decays. Decide from the eigenvalues, which never form "
        "those powers",
        "[[0.999, 1e306], [0, 0.999]]^n has the corner entry 1e306 n 0.999^(n-1), about "
        "3.7e308 near n = 1000: inf in floating point, though it decays afterwards. Its "
        "eigenvalues are 0.999 < 1: np.linalg.eigvals(M) needs no power of M"),
    "slow": ("a slow growth (|μ| = 1.00001) or a long transient fooled your test: compare "
             "|μ| with 1 at round-off level",
             "a few powers of M cannot decide it: growth by 1.00001 per step shows only after "
             "hundreds of thousands of steps, a transient may rise for 100 000 steps, and the "
             "powers of a harmless matrix may overflow. Decide from the eigenvalues, with a "
             "tolerance at round-off level (about 1e-7 for a Jordan block's split "
             "eigenvalues), not wider"),
}
#: The two matrices above whose powers mislead any affordable number of steps.
SLOW_CASES = ("diag(1.00001, 0.5)", "[[0.99999, 1], [0, 0.99999]]")
#: Lines of Python an answer may run per matrix: an analysis needs a few dozen.
POWERS_LINE_BUDGET = 500

#: Wrong rules a student may write, by the quantity each compares with 1 (bounded iff it is
#: at most 1), with the hint for an answer whose verdicts are exactly that rule's.
WRONG_RULES = [
    (lambda M: float(np.linalg.norm(M, 2)),
     escalate(
         "a norm above 1 does not mean growth: [[0.5, 100], [0, 0.5]] has norm 100, yet its "
         "powers decay to zero. Decide from the eigenvalues",
         "‖M‖ ≤ 1 is enough for bounded powers but far from needed: a large norm may be only a "
         "transient ([[0.5, 100], [0, 0.5]]^n rises to about 100, then decays; its eigenvalues "
         "are 0.5 and 0.5). Write mu = np.linalg.eigvals(M); bounded iff max|mu| ≤ 1 + 1e-7 and "
         "every |mu| ≈ 1 has as many eigenvectors as its multiplicity "
         "(np.linalg.matrix_rank(M - mu I) = 2 - multiplicity)")),
    (lambda M: float(abs(np.linalg.det(M))),
     ("|det M| is the product of the eigenvalues' moduli: diag(1.01, 0.2) has det 0.2, yet "
      "its powers grow. Compare each |μ| with 1",
      "|det M| ≤ 1 lets one eigenvalue exceed 1 if the other is small (diag(1.01, 0.2)), and "
      "det = 1 with a double eigenvalue -1 may be a Jordan block (symplectic Euler at "
      "ω dt = 2 grows like n). Compare each |μ| with 1, and count the eigenvectors on the "
      "unit circle")),
]


def follows_rule(quantity, verdicts: dict) -> bool:
    """Whether an answer's ``verdicts`` (matrix description -> bool) are those of "bounded iff
    quantity(M) <= 1" on every matrix it judged (a quantity that round-off has moved off 1
    by less than 1e-6 may go either way; one of exactly 1 is at most 1)."""
    for what, M, *_ in MATRIX_CASES:
        if what in verdicts:
            q = quantity(np.array(M, dtype=float))
            if not 0.0 < abs(q - 1.0) < 1e-6 and (q <= 1.0) != verdicts[what]:
                return False
    return True


#: Fewer steps than this per run is too short a run for a bound of a million times |y0| or
#: more: just above the limit a run grows by only a few per cent per step.
SHORT_RUN = 200


def short_run_hint(step: float, n: int, grew: float, r: float):
    """Hint for a run of ``n`` < :data:`SHORT_RUN` steps of ``step`` s that grew
    ``grew``-fold (max|y| / max|y0|) and still counted as stable: the steps are the mistake
    (the same bound passes with long runs). ``r`` is |R| per step 2 % above the limit: the
    fuller hint says how many steps such a run needs to grow that much, and names the bound
    too when it is absurd."""
    nudge = (f"your run at dt = {step:.4g} s took only {n} steps: too few for a run above the "
             f"limit to reach your blow-up bound (it grew to {grew:.1e} max|y0| and still "
             "counted as stable)")
    more = "run thousands of steps, so that even a slow growth passes your bound"
    if r > 1 + 1e-9:
        more = (f"2 % above the limit |R| = {r:.4f} per step, so a run needs about "
                f"{np.log(grew) / np.log(r):.0f} steps to grow {grew:.0e}-fold and pass your "
                "bound: run at least that many steps")
    if grew > 1e15:
        more += ("; and lower the bound: no stable run of these systems grows more than a few "
                 "times |y0|, so 1000 max|y0| is far enough")
    return escalate(nudge, more)


def _growth(A, method: str, dt: float) -> float:
    """|R| per step of the fastest-growing mode at step ``dt``."""
    return float(max(abs(amplification_factor(method, lam * dt)) for lam in np.linalg.eigvals(A)))


def limit_hint(probe, A, method: str, dt: float, limit: float):
    """The mistake the recorded runs point to, for a measured limit ``dt`` off by > 2 %."""
    runs = probe.runs()
    if not runs:
        return escalate("find the limit by experiment: your function ran no simulation of "
                        "dy/dt = f(t, y) from y0",
                        "f records every call, and none started from y0: run trial steps "
                        "below dt_hi with traj = cl.integrate(f, y0, (0.0, 2000 * dt), dt, "
                        "method) and keep the largest dt whose traj.stable is True")
    if dt > limit:  # a run above the limit passed as stable: which one, and why?
        # the run at the answer itself, or the nearest one below it: one the search judged
        # stable (the nearest above it may be the unstable end of the last bracket)
        below_answer = [r for r in runs if r[0] <= dt * (1 + 1e-9)] or runs
        step, n, _ = min(below_answer, key=lambda r: abs(r[0] / dt - 1))
        if abs(step / dt - 1) > 0.05:  # no run near the answer to read (e.g. not recorded)
            return escalate(
                "a run just above the limit grows slowly: check how many steps your runs take, "
                "and that your blow-up bound is not far above a stable run's size",
                f"2 % above the limit |R| = {_growth(A, method, 1.02 * limit):.4f} per step: "
                "at 1.01 per step a run needs ln(1000)/ln(1.01) ≈ 694 steps to grow 1000-fold. "
                "Run thousands of steps, with a bound of about 1000 max|y0|")
        grew = probe.state_growth(step, n)  # max|y_k| / max|y0| over the run's own states
        if grew > 1e6 and n < SHORT_RUN:  # a high bound passes with long runs: steps first
            return short_run_hint(step, n, grew, _growth(A, method, 1.02 * limit))
        if grew > 1e6:
            return (f"your run at dt = {step:.4g} s reached {grew:.1e} max|y0| and still counted "
                    "as stable: the blow-up bound is too high",
                    f"your run at dt = {step:.4g} s reached {grew:.1e} max|y0| (the largest "
                    "max|y| of its states) and still counted as stable: the blow-up bound is too "
                    "high (without one, only overflow stops a run). No stable run of these "
                    "systems grows more than a few times |y0|: a bound of 1000 max|y0| is far "
                    "enough")
        return (f"your run at dt = {step:.4g} s took {n} steps: too few for a run above the "
                "limit to grow past the bound",
                f"your run at dt = {step:.4g} s took {n} steps: there |R| = "
                f"{_growth(A, method, step):.4f} per step, and in {n} steps its states "
                f"reached {grew:.3g} max|y0|, not enough to pass the bound. Just above the "
                "limit |R| is barely above 1: run thousands of steps, so that a slow growth "
                "reaches the bound")
    below = [r for r in runs if dt * (1 + 1e-9) < r[0] < limit]
    if not below:  # no stable run was mistaken: the search stopped short of the limit
        above = [r[0] for r in runs if r[0] > dt * (1 + 1e-9)]
        gap = f"your answer is {1 - dt / limit:.0%} below the limit"
        if not above:
            return escalate(f"{gap}, and your search ran no step above it: move up from your "
                            "last stable step until a run blows up, then narrow the bracket",
                            f"from {dt:.4g} s multiply the step by 1.1 until a run is unstable "
                            f"({1.1 * dt:.4g} s, {1.21 * dt:.4g} s, ...), then bisect between "
                            "the last stable step and the first unstable one")
        mid = 0.5 * (dt + min(above))
        return escalate(f"{gap}: your search tried no step between {dt:.4g} s (stable) and "
                        f"{min(above):.4g} s (unstable). Narrow that bracket, e.g. by bisection, "
                        "until the two are within 1 %",
                        f"try the middle, {mid:.4g} s: if that run is stable it becomes the low "
                        "end, else the high end; repeat while high / low > 1.01 (about "
                        f"{int(np.ceil(np.log2(np.log(min(above) / dt) / np.log(1.01))))} "
                        "halvings here)")
    step, n, _ = min(below)
    size = probe.state_growth(step, n)
    return (f"your run at dt = {step:.4g} s is stable (|R| = {_growth(A, method, step):.5f} ≤ 1) "
            "but counted as unstable: a stable run may grow for a while before it decays",
            f"your run at dt = {step:.4g} s is stable (|R| = {_growth(A, method, step):.5f} ≤ 1) "
            f"but counted as unstable; run to the end, its states reach {size:.3g} max|y0| on "
            "the way, since a stable "
            "run of a damped spring can swing above its start before it decays. Put the bound "
            "far above that, e.g. 1000 max|y0|")
