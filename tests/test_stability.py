"""Stability functions R(z) against closed forms and against the steppers themselves."""

import numpy as np
import pytest

import course_lib as cl

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

Z = np.array([-3.0, -1.0, -0.1, 0.5j, 1.3j, -0.4 + 0.8j, -2.2 - 1.1j, 0.3 + 0.2j])

CLOSED = {
    "forward_euler": lambda z: 1 + z,
    "midpoint": lambda z: 1 + z + z**2 / 2,
    "heun": lambda z: 1 + z + z**2 / 2,
    "rk4": lambda z: 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24,
    "backward_euler": lambda z: 1 / (1 - z),
    "trapezoidal": lambda z: (2 + z) / (2 - z),
}


@pytest.mark.parametrize("method", list(CLOSED))
def test_R_matches_closed_form(method):
    np.testing.assert_allclose(cl.amplification_factor(method, Z), CLOSED[method](Z), rtol=1e-14)


def _step_as_real_2x2(method, z):
    """Apply one step to y' = λy written as a real 2-vector (Re y, Im y); return R."""
    lam = complex(z)  # dt = 1
    A = np.array([[lam.real, -lam.imag], [lam.imag, lam.real]])
    y1 = getattr(cl, method)(lambda t, y: A @ y, 0.0, np.array([1.0, 0.0]), 1.0)
    return y1[0] + 1j * y1[1]


@pytest.mark.parametrize("method", list(CLOSED))
def test_R_matches_what_the_stepper_does(method):
    for z in Z:
        assert _step_as_real_2x2(method, z) == pytest.approx(
            complex(cl.amplification_factor(method, z)), rel=1e-12
        )


@pytest.mark.parametrize("method", ["symplectic_euler", "velocity_verlet"])
@pytest.mark.parametrize("z", [0.5j, 1.5j, 1.99j, 2.5j, 3.0j, -0.3, 0.2 + 0.7j])
def test_newtonian_R_is_largest_eigenvalue_of_the_step_matrix(method, z):
    # Test problem x'' = λ² x with dt = 1: build the step matrix column by column.
    lam2 = complex(z) ** 2
    f = lambda t, y: np.array([y[1], lam2 * y[0]])  # noqa: E731
    cols = [getattr(cl, method)(f, 0.0, e.astype(complex), 1.0) for e in np.eye(2)]
    eig = np.linalg.eigvals(np.column_stack(cols))
    assert abs(cl.amplification_factor(method, z)) == pytest.approx(np.abs(eig).max(), rel=1e-9)


def test_syllabus_values():
    assert cl.amplification_factor("forward_euler", -3.0) == -2.0
    theta = np.linspace(0.01, 1.99, 50)
    assert np.allclose(np.abs(cl.amplification_factor("symplectic_euler", 1j * theta)), 1.0)
    assert np.all(np.abs(cl.amplification_factor("velocity_verlet", 1j * np.array([2.01, 3]))) > 1)
    # forward Euler on the vortex: |R(i dt)| = sqrt(1 + dt²)
    dt = np.array([0.1, 0.5, 1.0])
    np.testing.assert_allclose(np.abs(cl.amplification_factor("forward_euler", 1j * dt)),
                               np.sqrt(1 + dt**2), rtol=1e-15)
    np.testing.assert_allclose(np.abs(cl.amplification_factor("trapezoidal", 1j * dt)), 1.0,
                               rtol=1e-15)


@pytest.mark.parametrize(
    "method,lam,expected",
    [
        ("forward_euler", -1.0, 2.0),
        ("forward_euler", -4.0, 0.5),
        ("midpoint", -1.0, 2.0),
        ("heun", -1.0, 2.0),
        ("rk4", 1j, 2 * np.sqrt(2)),
        ("symplectic_euler", 1j, 2.0),
        ("velocity_verlet", 3j, 2.0 / 3.0),
        ("forward_euler", 1j, 0.0),
        ("midpoint", 1j, 0.0),
        ("backward_euler", -1.0, np.inf),
        ("trapezoidal", 1j, np.inf),
    ],
)
def test_max_stable_dt(method, lam, expected):
    assert cl.max_stable_dt(method, lam) == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_rk4_real_axis_limit():
    # On the negative real axis RK4's R(z) never reaches -1; the interval ends where R
    # returns to +1, the real root of z³/24 + z²/6 + z/2 + 1 = 0.
    roots = np.roots([1 / 24, 1 / 6, 1 / 2, 1])
    edge = max(r.real for r in roots if abs(r.imag) < 1e-9 and r.real < 0)
    assert edge == pytest.approx(-2.785293563405, abs=1e-11)
    assert cl.max_stable_dt("rk4", -1.0) == pytest.approx(-edge, rel=1e-12)


def test_poles_are_infinite():
    assert np.isinf(cl.amplification_factor("backward_euler", 1.0))
    assert np.isinf(cl.amplification_factor("trapezoidal", 2.0))
