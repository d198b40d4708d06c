"""Hardening of the stability limits (issue 7 §2); each test failed before its fix.

``max_stable_dt`` returned 0 whenever the true limit was small (it scanned a grid of
``|λ| dt`` from 0.01), and a search limit instead of ``inf`` for A-stable methods; and the
symplectic pair was called stable at ``ω dt = 2``, where its step matrix is a Jordan block.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import course_lib as cl
from course_lib.systems import oscillator

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding

SCALES = [10.0**e for e in range(-8, 9)]


def rk4_real_edge() -> float:
    """The real root of 1 + z/2 + z²/6 + z³/24 (where RK4's R returns to 1), polished."""
    z = min(r.real for r in np.roots([1 / 24, 1 / 6, 1 / 2, 1]) if abs(r.imag) < 1e-9)
    for _ in range(5):
        z -= (1 + z / 2 + z * z / 6 + z**3 / 24) / (0.5 + z / 3 + z * z / 8)
    return -z


def test_the_lightly_damped_mode_of_the_issue():
    lam = -1e-3 + 1j
    assert cl.max_stable_dt("forward_euler", lam) == pytest.approx(2e-3 / abs(lam) ** 2,
                                                                   rel=1e-13)


@pytest.mark.parametrize("scale", SCALES)
def test_closed_forms_at_every_scale(scale):
    lam = scale * (-1e-3 + 1j)
    assert cl.max_stable_dt("forward_euler", lam) == pytest.approx(
        2 * abs(lam.real) / abs(lam) ** 2, rel=1e-12)
    assert cl.max_stable_dt("rk4", 1j * scale) == pytest.approx(2 * np.sqrt(2) / scale, rel=1e-12)
    assert cl.max_stable_dt("rk4", -scale) == pytest.approx(rk4_real_edge() / scale, rel=1e-12)
    for method in ("forward_euler", "midpoint", "heun"):
        assert cl.max_stable_dt(method, -scale) == pytest.approx(2.0 / scale, rel=1e-12)
    for method in ("symplectic_euler", "velocity_verlet"):
        assert cl.max_stable_dt(method, 1j * scale) == pytest.approx(2.0 / scale, rel=1e-15)
    for method in sorted(cl.IMPLICIT_METHODS):
        assert cl.max_stable_dt(method, lam) == np.inf
        assert cl.max_stable_dt(method, -scale) == np.inf
        assert cl.max_stable_dt(method, 1j * scale) == np.inf


@settings(max_examples=200, deadline=None)
@given(damping=st.floats(1e-9, 1.0), angle=st.floats(0.0, 1.0), exponent=st.floats(-8, 8))
def test_forward_euler_limit_is_two_re_lambda_over_abs_lambda_squared(damping, angle, exponent):
    # λ = s(-d + i b) anywhere in the left half-plane, at any scale s
    lam = 10.0**exponent * complex(-damping, angle)
    expected = 2 * abs(lam.real) / abs(lam) ** 2
    assert cl.max_stable_dt("forward_euler", lam) == pytest.approx(expected, rel=1e-12)


@settings(max_examples=150, deadline=None)
@given(method=st.sampled_from(["midpoint", "heun", "rk4"]), re=st.floats(-1.0, -1e-7),
       im=st.floats(-1.0, 1.0), exponent=st.integers(-8, 8))
def test_limit_is_where_abs_R_reaches_one_and_scales_with_lambda(method, re, im, exponent):
    lam = complex(re, im)
    dt = cl.max_stable_dt(method, lam)
    assert 0 < dt < np.inf
    assert abs(cl.amplification_factor(method, lam * dt)) == pytest.approx(1.0, abs=1e-14)
    inside = np.abs(cl.amplification_factor(method, lam * dt * np.linspace(0.01, 1, 500)))
    assert inside.max() <= 1 + 1e-14
    assert abs(cl.amplification_factor(method, lam * dt * (1 + 1e-6))) > 1
    s = 10.0**exponent
    assert cl.max_stable_dt(method, s * lam) * s == pytest.approx(dt, rel=1e-12)


@pytest.mark.parametrize("method", cl.METHODS)
def test_growing_modes_have_no_stable_step(method):
    assert cl.max_stable_dt(method, 0.5 + 0.1j) == 0.0
    if method not in cl.IMPLICIT_METHODS:
        assert cl.max_stable_dt(method, 1e-3 + 1j) == 0.0


def test_dt_max_caps_and_lam_is_checked():
    assert cl.max_stable_dt("backward_euler", -1.0, dt_max=1e3) == 1e3
    assert cl.max_stable_dt("forward_euler", -1.0, dt_max=0.5) == 0.5
    for lam, err in [(0, ValueError), (np.nan, ValueError), (np.inf * 1j, ValueError),
                     ("1j", TypeError), (None, TypeError)]:
        with pytest.raises(err, match="lam"):
            cl.max_stable_dt("rk4", lam)
    with pytest.raises(ValueError, match="dt_max"):
        cl.max_stable_dt("rk4", 1j, dt_max=0.0)


# --- ω dt = 2 is not stable for the symplectic pair -----------------------------------------


@pytest.mark.parametrize("method", sorted(cl.NEWTONIAN_METHODS))
def test_omega_dt_2_is_not_stable(method):
    assert not cl.is_stable(method, 2j)
    assert not cl.is_stable(method, -2j)
    assert cl.is_stable(method, 1.999j) and cl.is_stable(method, 0.5j)
    assert not cl.is_stable(method, 2.001j)
    np.testing.assert_array_equal(cl.is_stable(method, 1j * np.array([1.0, 1.99, 2.0, 2.5])),
                                  [True, True, False, False])
    # at the limit itself the run grows linearly: a Jordan block with eigenvalue -1
    # (started off its one eigenvector)
    omega = 3.0
    traj = cl.integrate(oscillator(omega), [1.0, 0.5], (0.0, 2000 * 2 / omega), 2 / omega, method)
    size = np.max(np.abs(traj.y), axis=1)
    assert size[2000] > 100 * size[0]
    assert size[2000] / size[1000] == pytest.approx(2.0, rel=0.01)   # linear, not exponential


@pytest.mark.parametrize("method", sorted(set(cl.METHODS) - cl.NEWTONIAN_METHODS))
def test_scalar_methods_are_bounded_on_their_boundary(method):
    # |R| = 1 exactly: the run neither grows nor decays (forward Euler at dt = 2/k flips sign)
    edge = {"forward_euler": -2.0, "midpoint": -2.0, "heun": -2.0, "rk4": -rk4_real_edge(),
            "backward_euler": 2.0, "trapezoidal": 1j}[method]
    assert cl.is_stable(method, edge)
