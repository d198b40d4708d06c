"""Notebook 11, Exercise 3 (one Baraff-Witkin solve): hints from the evidence (fourth read).

A Δv from conjugate gradients stopped at a loose tolerance is close to the right one, and
on an undamped cloth or one of equal masses several structural mistakes give the right Δv
too: such an answer must hear only "Not yet: tighten rtol", never a structural hint
(the damping term on an undamped cloth, the masses' rows on equal masses). A structural
mistake must still be named, even where its residual is small (np.tile on the stiff
cloth leaves 2e-5). Another Krylov solver is refused by its own name, not for the BLAS
it calls.
"""

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.linalg

import course_lib as cl
from course_lib.check import FAILURES, evaluate
from course_lib.check import nb11 as check

STRUCTURAL = ("h ∂F/∂v term", "three rows", "where the start velocity takes", "minus sign",
              "not the new velocity", "units of the right side", "compare your A and b")


def notebook_answer(source: str, name: str = "bw_velocity_change"):
    """A function defined the way a notebook cell defines it (module ``__main__``)."""
    namespace = {"__name__": "__main__", "np": np, "cl": cl, "scipy": scipy}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


def judged(answer, attempt: int = 0) -> tuple[str, list[str]]:
    """(status, failure messages) of ``answer``, as after ``attempt`` wrong tries."""
    key = check.bw_velocity_change.key
    FAILURES.pop(key, None)
    if attempt:
        FAILURES[key] = attempt
    verdict = evaluate(check.bw_velocity_change, answer)
    FAILURES.pop(key, None)
    return verdict["status"], verdict["failed_cases"]


def cg_answer(matrix="M - h * dFdv - h * h * dFdx", masses="np.repeat(mass, 3)",
              solve="scipy.sparse.linalg.cg(A, b, rtol={rtol}, maxiter=10 * b.size)[0]",
              rtol="1e-10"):
    return notebook_answer(f"""
def bw_velocity_change(mass, dFdx, dFdv, F0, v0, h):
    M = scipy.sparse.diags({masses})
    A = ({matrix}).tocsr()
    b = h * (F0.ravel() + h * (dFdx @ v0.ravel()))
    dv = {solve.format(rtol=rtol)}
    return dv.reshape(v0.shape)
""")


HAND_CG = """\
def hand_cg(A, b, tol):
    x = np.zeros_like(b)
    r = b.copy()
    p = r.copy()
    rr = r @ r
    while np.sqrt(rr) > tol * np.linalg.norm(b):
        q = A @ p
        a = rr / (p @ q)
        x += a * p
        r -= a * q
        rr, old = r @ r, rr
        p = r + rr / old * p
    return x
"""


def hand_cg_answer(tol):
    source = HAND_CG + f"""
def bw_velocity_change(mass, dFdx, dFdv, F0, v0, h):
    A = (scipy.sparse.diags(np.repeat(mass, 3)) - h * dFdv - h * h * dFdx).tocsr()
    b = h * (F0.ravel() + h * (dFdx @ v0.ravel()))
    return hand_cg(A, b, {tol!r}).reshape(v0.shape)
"""
    return notebook_answer(source)


@pytest.mark.parametrize("answer", [
    pytest.param(lambda: cg_answer(rtol="1e-6"), id="cg rtol 1e-6 (the reviewer's)"),
    pytest.param(lambda: cg_answer(rtol="1e-5"), id="cg at SciPy's default rtol"),
    pytest.param(lambda: cg_answer(rtol="3e-7"), id="cg rtol 3e-7"),
    pytest.param(lambda: hand_cg_answer(1e-6), id="hand-written CG stopped at 1e-6"),
    pytest.param(lambda: hand_cg_answer(2e-5), id="hand-written CG stopped at 2e-5"),
])
def test_a_loose_tolerance_hears_only_tighten_rtol(answer):
    fn = answer()
    status, failed = judged(fn)
    assert status == "incorrect" and failed, failed
    for line in failed:                     # every failing case: the converge nudge, alone
        assert "Not yet: tighten rtol" in line, line
        assert not any(s in line for s in STRUCTURAL), line
    assert any("rtol=1e-10" in line for line in judged(fn, attempt=1)[1])


def test_the_right_solve_passes():
    assert judged(cg_answer())[0] == "correct"
    assert judged(hand_cg_answer(1e-12))[0] == "correct"


def test_structural_mistakes_are_still_named_where_they_show():
    # the damping term left out: named on the damped cases, and never on an undamped one
    status, failed = judged(cg_answer(matrix="M - h * h * dFdx"))
    assert status == "incorrect" and failed
    assert all("damped" in line.split(":")[0] and "undamped" not in line.split(":")[0]
               for line in failed), failed
    assert all("h ∂F/∂v term" in line and "tighten rtol" not in line for line in failed), failed
    # np.tile for the masses: equal masses hide it; unequal ones show it, the stiff cloth too
    # (its residual there is only 2e-5, below the converge threshold)
    status, failed = judged(cg_answer(masses="np.tile(mass, 3)"))
    assert [line.split(":")[0] for line in failed] == [
        "5 × 5 cloth, damped, masses from 1 to 5 g, moving",
        "5 × 5 stiff cloth (k = 30000 N/m), damped, moving"], failed
    assert all("three rows" in line and "tighten rtol" not in line for line in failed), failed


@pytest.mark.parametrize("solver", ["gmres", "lgmres", "bicgstab", "minres", "cgs", "tfqmr"])
def test_another_krylov_solver_is_refused_by_name(solver):
    body = ("    A = scipy.sparse.diags(np.repeat(mass, 3)) - h * dFdv - h * h * dFdx\n"
            "    b = h * (F0.ravel() + h * (dFdx @ v0.ravel()))\n")
    head = "def bw_velocity_change(mass, dFdx, dFdv, F0, v0, h):\n"
    sources = [head + body
               + f"    return scipy.sparse.linalg.{solver}(A, b, rtol=1e-12)[0].reshape(v0.shape)",
               f"from scipy.sparse.linalg import {solver} as krylov\n" + head + body
               + "    return krylov(A, b, rtol=1e-12)[0].reshape(v0.shape)"]
    for source in sources:
        status, failed = judged(notebook_answer(source))
        assert status == "incorrect", failed
        assert failed[0].startswith(f"uses the reference: your function calls scipy.sparse.linalg.{solver}")
        assert "blas" not in failed[0].lower(), failed[0]
    if solver in ("lgmres", "minres", "tfqmr"):       # modules without CG: watched while running too
        inside = head + f"    from scipy.sparse.linalg import {solver} as krylov\n" + body \
            + "    return krylov(A, b, rtol=1e-12)[0].reshape(v0.shape)"
        status, failed = judged(notebook_answer(inside))
        assert status == "incorrect", failed
        assert failed[0].startswith(f"uses the reference: your function calls scipy.sparse.linalg.{solver}")
