"""Bad input gets a clear TypeError/ValueError that names the argument."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import course_lib as cl
from course_lib import fields

decay = lambda t, y: -y  # noqa: E731

bad_dt = st.one_of(
    st.floats(max_value=0.0, allow_nan=False),
    st.just(math.nan), st.just(math.inf), st.just(-math.inf),
)


@settings(max_examples=60, deadline=None)
@given(dt=bad_dt, method=st.sampled_from(cl.METHODS))
def test_non_positive_or_non_finite_dt_is_rejected(dt, method):
    y0 = [1.0, 0.0]
    with pytest.raises(ValueError, match="dt"):
        cl.integrate(decay, y0, (0.0, 1.0), dt, method)
    with pytest.raises(ValueError, match="dt"):
        cl.step(method, decay, 0.0, y0, dt)


@settings(max_examples=40, deadline=None)
@given(name=st.text(min_size=1, max_size=20).filter(lambda s: s not in cl.METHODS))
def test_unknown_method_lists_valid_names(name):
    with pytest.raises(ValueError) as err:
        cl.integrate(decay, 1.0, (0.0, 1.0), 0.1, name)
    msg = str(err.value)
    assert "method" in msg and all(m in msg for m in cl.METHODS)
    with pytest.raises(ValueError, match="forward_euler"):
        cl.amplification_factor(name, 0.5)


@settings(max_examples=40, deadline=None)
@given(
    shape=st.lists(st.integers(1, 4), min_size=1, max_size=3),
    bad=st.sampled_from([math.nan, math.inf, -math.inf]),
    where=st.integers(0, 1000),
)
def test_non_finite_initial_state_is_rejected(shape, bad, where):
    y0 = np.ones(shape)
    y0.flat[where % y0.size] = bad
    with pytest.raises(ValueError, match="y0 must be finite"):
        cl.integrate(decay, y0, (0.0, 1.0), 0.1)


@settings(max_examples=40, deadline=None)
@given(shape=st.lists(st.integers(1, 4), min_size=1, max_size=3),
       extra=st.integers(1, 3))
def test_rhs_returning_the_wrong_shape_is_named(shape, extra):
    y0 = np.ones(shape)
    wrong = lambda t, y: np.ones(y.size + extra)  # noqa: E731
    with pytest.raises(ValueError, match=r"f\(t, y\) must return an array of the state's shape"):
        cl.integrate(wrong, y0, (0.0, 1.0), 0.1)


@pytest.mark.parametrize("y0", [[], "abc", [[1, 2], [3]], None, {"a": 1}])
def test_malformed_y0(y0):
    with pytest.raises((TypeError, ValueError), match="y0"):
        cl.integrate(decay, y0, (0.0, 1.0), 0.1)


@pytest.mark.parametrize("dt", ["0.1", None, True, [0.1]])
def test_dt_of_wrong_type(dt):
    with pytest.raises(TypeError, match="dt"):
        cl.integrate(decay, 1.0, (0.0, 1.0), dt)


@pytest.mark.parametrize("span", [(1.0, 0.0), (0.0, 0.0), (0.0, math.nan), (0.0,), 5.0])
def test_bad_t_span(span):
    with pytest.raises((TypeError, ValueError), match="t_span"):
        cl.integrate(decay, 1.0, span, 0.1)


def test_dt_longer_than_span():
    with pytest.raises(ValueError, match="dt"):
        cl.integrate(decay, 1.0, (0.0, 1.0), 5.0)


def test_f_not_callable():
    with pytest.raises(TypeError, match="f must be callable"):
        cl.integrate(np.ones(2), [1.0, 2.0], (0.0, 1.0), 0.1)


@pytest.mark.parametrize("method", sorted(cl.NEWTONIAN_METHODS))
def test_symplectic_methods_need_newtonian_layout(method):
    with pytest.raises(ValueError, match=r"Newtonian state y0 = \(x, v\)"):
        cl.integrate(decay, np.ones(3), (0.0, 1.0), 0.1, method)
    # right shape, but f is not x' = v (a vector field on the plane):
    with pytest.raises(ValueError, match=r"dx/dt = v"):
        cl.integrate(fields.vortex, [0.0, 1.0], (0.0, 1.0), 0.1, method)


def test_jac_only_for_implicit_and_checked():
    with pytest.raises(ValueError, match="jac"):
        cl.integrate(decay, 1.0, (0.0, 1.0), 0.1, "rk4", jac=lambda t, y: -np.eye(1))
    with pytest.raises(ValueError, match="jac must return shape"):
        cl.integrate(decay, [1.0, 2.0], (0.0, 1.0), 0.1, "backward_euler",
                     jac=lambda t, y: np.eye(3))


def test_on_blowup_choice():
    with pytest.raises(ValueError, match="on_blowup"):
        cl.integrate(decay, 1.0, (0.0, 1.0), 0.1, on_blowup="ignore")


def test_fields_reject_wrong_dimension():
    with pytest.raises(ValueError, match=r"X must have shape \(\.\.\., 2\)"):
        fields.vortex(0.0, np.ones((4, 3)))
    with pytest.raises(ValueError, match="velocity"):
        fields.constant_wind((1.0, 2.0, 3.0))


def test_newtonian_system_rejects_bad_mass():
    with pytest.raises(ValueError, match="mass"):
        cl.newtonian(lambda t, x, v: 0 * x, [1.0, -1.0])
    with pytest.raises(TypeError, match="force must be callable"):
        cl.newtonian("gravity", 1.0)
