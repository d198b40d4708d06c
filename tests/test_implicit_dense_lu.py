"""The small-system fast path of NewtonSolver.factorize (LAPACK getrf/getrs called directly).

It must give the same bits as scipy's lu_factor/lu_solve (stored notebook outputs rely on
it), fall back for a residual of another dtype, and keep the singular-matrix error.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from course_lib.implicit import ConvergenceError, NewtonSolver


@pytest.mark.parametrize("n", [1, 2, 3, 7])
def test_direct_lapack_solve_matches_scipy_bit_for_bit(n):
    rng = np.random.default_rng(40 + n)
    for _ in range(20):
        J = rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-3, 3)
        a_dt = 10.0 ** rng.uniform(-4, 0)
        r = rng.normal(size=n)
        expected = sla.lu_solve(sla.lu_factor(np.eye(n) - a_dt * J), r)
        np.testing.assert_array_equal(NewtonSolver.factorize(J, a_dt, 0.0)(r), expected)


def test_complex_residual_on_a_real_matrix_uses_the_scipy_path():
    J = np.array([[0.0, 1.0], [-4.0, -0.1]])
    r = np.array([1.0 + 2.0j, -0.5j])
    x = NewtonSolver.factorize(J, 0.1, 0.0)(r)
    np.testing.assert_allclose((np.eye(2) - 0.1 * J) @ x, r, rtol=1e-14, atol=1e-14)


def test_singular_newton_matrix_still_raises():
    J = np.array([[10.0, 0.0], [0.0, 1.0]])   # I - 0.1 J has a zero row
    with pytest.raises(ConvergenceError, match="singular"):
        NewtonSolver.factorize(J, 0.1, 2.0)
