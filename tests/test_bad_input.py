"""Bad input gets a clear TypeError/ValueError that names the argument."""

import inspect
import math
import re

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


# --- the sweep: every public entry point of the core, every kind of bad input ------------------
#
# Each entry point is called once with good arguments (which must work), then once per bad
# value of one argument; the call must raise TypeError or ValueError whose message names that
# argument, before any work (a NaN state must not be simulated, a bad count not looped over).
# The kinds of bad input are generated, not listed per function: non-finite numbers and
# states, states with a row or an axis missing, non-positive steps and counts, fractional
# counts, unknown method names, out-of-range particle indices.

NAN, INF = math.nan, math.inf


def _positive(_good):
    return {"zero": 0.0, "negative": -1.0, "nan": NAN, "inf": INF}


def _positive_or_inf(_good):
    return {"zero": 0.0, "negative": -1.0, "nan": NAN}


def _nonneg(_good):
    return {"negative": -1.0, "nan": NAN, "inf": INF}


def _finite(_good):
    return {"nan": NAN, "inf": INF}


def _count(_good):
    return {"zero": 0, "negative": -2, "fraction": 1.5}


def _size(_good):
    return {"negative": -2, "fraction": 1.5}


def _method(_good):
    return {"unknown": "no_such_method", "not_text": 3}


def _state(good, rows=True):
    """Non-finite entries; with ``rows``, one row fewer (and a flattened array, if 2-D)."""
    good = np.asarray(good, dtype=float)
    out = {}
    for label, value in (("nan", NAN), ("inf", INF)):
        bad = good.copy()
        bad.flat[bad.size // 2] = value
        out[label] = bad
    out["text"] = np.full(good.shape, "a")
    if rows and good.ndim >= 1 and len(good) > 1:
        out["row_missing"] = good[:-1]
    if rows and good.ndim >= 2:
        out["flattened"] = good.reshape(-1)
    return out


def _finite_state(good):
    return _state(good, rows=False)


def _positive_values(_good):
    """Values that must be > 0 (masses that also set N: no length is wrong)."""
    return {"zero": 0.0, "negative": [1.0, -1.0], "nan": [NAN, 1.0]}


def _records(good):
    """Records (a trajectory may hold NaN rows after a blow-up): text or complex numbers."""
    good = np.asarray(good, dtype=float)
    return {"text": np.full(good.shape, "a"), "complex": good + 1j}


def _field_points(good):
    """A field is evaluated at every stage of a run: NaN propagates (the run stops on it)."""
    return {"text": np.full(np.shape(good), "a"), "three_d": np.ones((3, 3))}


def _samples(good):
    """Sampled values (NaN allowed: a run stopped by a blow-up): text, complex, one short."""
    return {**_records(good), "row_missing": np.asarray(good, dtype=float)[:-1]}


def _masses(good):
    good = np.asarray(good, dtype=float)
    out = {"zero": np.zeros_like(good), "negative": -np.ones_like(good), "nan": np.full_like(good, NAN)}
    if good.ndim == 1 and len(good) > 1:
        out["row_missing"] = good[:-1]
    return out


def _vector(good):
    good = np.asarray(good, dtype=float)
    return {"nan": np.full_like(good, NAN), "empty": good[:0]}


def _vector_of_its_length(good):
    return {**_vector(good), "too_short": np.asarray(good, dtype=float)[:-1]}


def _points(good):
    """Non-finite, text or flattened points (N, d), N free."""
    return {k: v for k, v in _state(good).items() if k != "row_missing"}


def _indices(n):
    return lambda _good: {"out_of_range": [n], "fraction": [0.5]}


HAIR_X, HAIR_NET = cl.springs.hair_chain(n=5, length=0.1, k_edge=200.0, k_bend=1.0)
HAIR_N = len(HAIR_X)
CHAIN_DT = 1e-3


def _bodies():
    return cl.rigid.make("box", 1.0, (1.0, 0.5, 0.2), [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])


def _particle_system():
    system = cl.particles.ParticleSystem(dim=3)
    system.add(x=np.zeros((2, 3)), lifetime=1.0)
    return system


RNG = np.random.default_rng(0)
FLOCK_X, FLOCK_V = np.array([[0.0, 0.0], [1.0, 0.5], [3.0, 3.0]]), np.array([[1.0, 0.0], [0.0, 1.0],
                                                                              [1.0, 1.0]])
T_SAMPLES = np.linspace(0.0, 1.0, 11)
H_SAMPLES = 1.0 - 2.0 * T_SAMPLES


class E:
    """An entry point: ``call(**arguments)`` with good ``arguments`` and, per argument, the
    kind of bad values to try."""

    def __init__(self, name, call, good, **kinds):
        self.name, self.call, self.good, self.kinds = name, call, good, kinds

    def run(self, **changes):
        return self.call(**{**self.good, **changes})

    def good_value(self, arg):
        if arg in self.good:
            return self.good[arg]
        default = inspect.signature(self.call).parameters[arg].default
        return None if default is inspect.Parameter.empty else default


def _hair(fn):
    return lambda **k: fn(**k)


ENTRIES = [
    # integrators, steppers, stability
    E("integrate", cl.integrate, {"f": decay, "y0": [1.0, 2.0], "t_span": (0.0, 1.0), "dt": 0.1,
                                  "method": "rk4"}, y0=_finite_state, dt=_positive, method=_method),
    E("step", cl.step, {"method": "rk4", "f": decay, "t": 0.0, "y": [1.0, 2.0], "dt": 0.1},
      y=_finite_state, dt=_positive, t=_finite, method=_method),
    E("amplification_factor", cl.amplification_factor, {"method": "heun", "z": -0.5}, method=_method),
    E("is_stable", cl.stability.is_stable, {"method": "heun", "z": -0.5, "tol": 1e-12},
      method=_method, tol=_nonneg),
    E("max_stable_dt", cl.stability.max_stable_dt, {"method": "heun", "lam": -2.0, "dt_max": INF},
      method=_method, lam=_finite, dt_max=_positive_or_inf),
    E("bisect_stable_dt", cl.stability.bisect_stable_dt,
      {"is_stable": lambda dt: dt < 0.3, "lo": 0.1, "hi": 1.0, "rtol": 1e-3},
      lo=_positive, hi=_positive, rtol=_positive),
    # fields, systems, forces
    E("vortex", cl.fields.vortex, {"t": 0.0, "X": np.ones((3, 2))}, X=_field_points),
    E("radial", cl.fields.radial, {"t": 0.0, "X": np.ones((3, 2))}, X=_field_points),
    E("constant_wind", cl.fields.constant_wind, {"velocity": (7.0, 2.0)}, velocity=_vector),
    E("grid", cl.fields.grid, {"extent": 2.0, "n": 5}, extent=_positive, n=_count),
    E("scaled", cl.fields.scaled, {"field": cl.fields.vortex, "factor": 2.0}, factor=_finite),
    E("newtonian", cl.newtonian, {"force": lambda t, x, v: 0 * x, "mass": [1.0, 2.0]}, mass=_positive_values),
    E("oscillator", cl.systems.oscillator, {"omega": 1.0, "damping": 0.0}, omega=_positive,
      damping=_finite),
    E("oscillator_energy", cl.systems.oscillator_energy, {"y": np.ones((4, 2)), "omega": 1.0},
      y=_records, omega=_positive),
    E("stack_state", cl.systems.stack_state, {"x": np.ones((3, 2)), "v": np.ones((3, 2))},
      x=_state, v=_state),
    E("constant_gravity", cl.forces.constant_gravity, {"mass": [1.0, 2.0], "g": (0.0, -9.81, 0.0)},
      mass=_positive_values, g=_vector),
    E("gravity_force", cl.forces.gravity_force, {"mass": [1.0, 2.0], "g": (0.0, -9.81, 0.0)},
      mass=_positive_values, g=_vector),
    E("drag", cl.forces.drag, {"b": 0.1, "c": 0.1, "wind": 0.0}, b=_nonneg, c=_nonneg, wind=_finite),
    E("linear_drag_force", cl.forces.linear_drag_force, {"v": np.ones((2, 3)), "b": 0.1},
      v=_finite_state, b=_nonneg),
    E("quadratic_drag_force", cl.forces.quadratic_drag_force, {"v": np.ones((2, 3)), "c": 0.1},
      v=_finite_state, c=_nonneg),
    E("viscous_damping", cl.forces.viscous_damping, {"c": 0.1}, c=_nonneg),
    E("lorentz_force", cl.forces.lorentz_force, {"v": np.ones((2, 3)), "q": 1.0, "B": (0, 0, 1.0)},
      v=_finite_state, q=_finite, B=_vector),
    E("magnetic", cl.forces.magnetic, {"q": 1.0, "B": (0, 0, 1.0)}, q=_finite, B=_vector),
    E("nbody_gravity", cl.forces.nbody_gravity, {"mass": [1.0, 2.0], "G": 1.0, "softening": 0.1},
      mass=_positive_values, G=_positive, softening=_nonneg),
    E("nbody_gravity_force", cl.forces.nbody_gravity_force,
      {"x": np.eye(3)[:2], "mass": [1.0, 2.0], "G": 1.0, "softening": 0.1},
      x=_state, mass=_masses, G=_positive, softening=_nonneg),
    E("nbody_energy", cl.forces.nbody_energy,
      {"y": np.stack((np.eye(3)[:2], np.zeros((2, 3)))), "mass": [1.0, 2.0], "G": 1.0},
      y=_records, mass=_masses, G=_positive),
    E("attractor", cl.forces.attractor, {"center": (0.0, 0.0, 0.0), "strength": 1.0, "softening": 0.1},
      center=_vector, strength=_finite, softening=_nonneg),
    # springs
    E("SpringNetwork", cl.springs.SpringNetwork,
      {"i": [0, 1], "j": [1, 2], "rest": 1.0, "k": 10.0, "c": 0.0, "n_particles": 3},
      rest=_nonneg, k=_nonneg, c=_nonneg, n_particles=_count),
    E("anchored_spring", cl.springs.anchored_spring, {"k": 10.0, "m": 1.0, "c": 0.0},
      k=_positive, m=_positive, c=_nonneg, rest=_positive, stretch=_finite),
    E("chain_max_frequency", cl.springs.chain_max_frequency, {"n_free": 4, "k": 10.0, "m": 1.0},
      n_free=_count, k=_positive, m=_positive),
    E("chain_pairs", cl.springs.chain_pairs, {"n": 4, "offset": 1}, n=_count, offset=_count),
    E("cloth_grid", cl.springs.cloth_grid, {"nx": 3, "ny": 3, "spacing": 0.1},
      nx=_count, ny=_count, spacing=_positive, k_struct=_nonneg, c=_nonneg),
    E("critical_damping", cl.springs.critical_damping, {"k": 10.0, "m": 1.0}, k=_positive, m=_positive),
    E("damped_oscillator", cl.springs.damped_oscillator, {"t": T_SAMPLES, "k": 10.0, "m": 1.0, "c": 0.5},
      t=_finite_state, k=_positive, m=_positive, c=_nonneg, x0=_finite, v0=_finite),
    E("hair_chain", cl.springs.hair_chain, {"n": 4, "length": 0.1, "k_edge": 100.0},
      n=_count, length=_positive, k_edge=_positive, k_bend=_nonneg),
    E("spring_force_pair", cl.springs.spring_force_pair,
      {"x1": (0.0, 0.0, 0.0), "x2": (1.5, 0.0, 0.0), "k": 10.0, "rest": 1.0},
      x1=_vector, x2=_vector, k=_nonneg, rest=_nonneg),
    E("jacobian_x", cl.springs.jacobian_x, {"network": HAIR_NET, "x": HAIR_X}, x=_state),
    E("jacobian_v", cl.springs.jacobian_v, {"network": HAIR_NET, "x": HAIR_X}, x=_state),
    E("stiffness_matrix", cl.springs.stiffness_matrix, {"network": HAIR_NET, "x": HAIR_X}, x=_state),
    E("max_frequency", cl.springs.max_frequency,
      {"network": HAIR_NET, "x": HAIR_X, "mass": 1e-3, "pinned": [0]},
      x=_state, mass=_masses, pinned=_indices(HAIR_N)),
    E("newtonian_jacobian", cl.springs.newtonian_jacobian, {"network": HAIR_NET, "mass": 1e-3, "pinned": [0]},
      mass=_masses, pinned=_indices(HAIR_N)),
    # strands, hair, statics
    E("helix", cl.strands.helix, {"n": 6, "length": 0.1, "radius": 0.005},
      n=_count, length=_positive, radius=_nonneg, turn=_finite, root=_vector_of_its_length,
      axis=_vector_of_its_length),
    E("strand_network", cl.strands.strand_network, {"x0": HAIR_X, "k_edge": 100.0, "k_bend": 1.0},
      x0=_points, k_edge=_positive, k_bend=_nonneg, k_twist=_nonneg, c_edge=_nonneg, c_bend=_nonneg),
    E("twist", cl.strands.twist, {"x": HAIR_X, "angle": 0.1, "cut": 2}, x=_points, angle=_finite,
      cut=_count),
    E("hair.simulate", cl.hair.simulate,
      {"x0": HAIR_X, "network": HAIR_NET, "frames": 2, "substeps": 4, "fps": 30.0, "mass": 1e-3,
       "pinned": (0,)},
      x0=_state, v0=_state, frames=_count, substeps=_count, fps=_positive, mass=_masses,
      pinned=_indices(HAIR_N), damping=_nonneg, gravity=_vector_of_its_length, blowup_bound=_positive),
    E("hair.symplectic_euler_run", cl.hair.symplectic_euler_run,
      {"x0": HAIR_X, "network": HAIR_NET, "dt": CHAIN_DT, "n_steps": 4, "mass": 1e-3, "pinned": (0,)},
      x0=_state, v0=_state, dt=_positive, n_steps=_count, mass=_masses, pinned=_indices(HAIR_N),
      damping=_nonneg, gravity=_vector_of_its_length, blowup_bound=_positive),
    E("hair.chain_dt_max", cl.hair.chain_dt_max,
      {"network": HAIR_NET, "x0": HAIR_X, "mass": 1e-3, "pinned": (0,), "n_steps": 20},
      x0=_state, mass=_masses, pinned=_indices(HAIR_N), n_steps=_count, amplitude=_positive,
      rtol=_positive),
    E("hair.strand_system", cl.hair.strand_system, {"network": HAIR_NET, "mass": 1e-3, "pinned": (0,)},
      mass=_masses, pinned=_indices(HAIR_N), damping=_nonneg, gravity=_vector),
    E("hair.static_shape", cl.hair.static_shape,
      {"x0": HAIR_X, "network": HAIR_NET, "mass": 1e-3, "pinned": (0, 1)},
      x0=_state, mass=_masses, pinned=_indices(HAIR_N), gravity=_vector_of_its_length, rtol=_positive,
      max_iter=_count),
    E("hair.hairstyle", cl.hair.hairstyle, {"n_strands": 2, "n": 5},
      n_strands=_count, center=_vector_of_its_length, radius=_positive, curl_radius=_nonneg),
    E("hair.head_collision", cl.hair.head_collision, {"center": (0.0, 0.0, 0.0), "radius": 0.1},
      center=_vector, radius=_positive),
    E("equilibrium", cl.statics.equilibrium,
      {"x0": HAIR_X, "network": HAIR_NET, "mass": 1e-3, "pinned": (0, 1)},
      x0=_state, mass=_masses, pinned=_indices(HAIR_N), gravity=_vector_of_its_length, rtol=_positive,
      max_iter=_count),
    E("curvature", cl.statics.curvature, {"network": HAIR_NET, "x": HAIR_X, "pinned": (0,)},
      x=_state, pinned=_indices(HAIR_N)),
    E("free_coordinates", cl.statics.free_coordinates, {"n": 4, "dim": 3, "pinned": (0,)},
      n=_count, dim=_count, pinned=_indices(4)),
    # particles
    E("ParticleSystem", cl.particles.ParticleSystem, {"dim": 3, "capacity": 8}, dim=_count,
      capacity=_count),
    E("ParticleSystem.add", lambda **k: _particle_system().add(**k),
      {"x": np.zeros((2, 3)), "v": np.zeros((2, 3)), "lifetime": 1.0, "age": 0.0},
      x=_points, v=_finite_state, lifetime=_positive, age=_nonneg),  # v broadcasts to (k, dim)
    E("ParticleSystem.step", lambda **k: _particle_system().step(**k), {"dt": 0.1}, dt=_positive),
    E("ParticleSystem.advect", lambda **k: _particle_system().advect(**k),
      {"t": 0.0, "dt": 0.1, "field": lambda t, x: 0 * x}, t=_finite, dt=_positive),
    E("Emitter", cl.particles.Emitter, {"count": 5.0, "lifetime": 1.0},
      count=_nonneg, count_variance=_nonneg, radius=_nonneg, speed=_finite, speed_variance=_nonneg,
      spread=_nonneg, lifetime=_positive, lifetime_variance=_nonneg, center=_vector),
    E("around", cl.particles.around, {"mean": 1.0, "variance": 0.5, "size": 3, "rng": RNG},
      mean=_finite, variance=_nonneg, size=_size),
    E("reeves_count", cl.particles.reeves_count, {"mean": 3.0, "variance": 1.0, "rng": RNG},
      mean=_finite, variance=_nonneg),  # a negative mean gives no particle (a count that dips)
    E("sample_shape", cl.particles.sample_shape, {"shape": "disc", "k": 3, "rng": RNG, "radius": 1.0},
      shape=_method, k=_size, radius=_nonneg, center=_vector, normal=_vector),
    E("sample_directions", cl.particles.sample_directions, {"k": 3, "rng": RNG, "spread": 0.1},
      k=_size, direction=_vector, spread=_nonneg),
    E("survival", cl.particles.survival, {"age": [0.1, 0.5], "lifetime": 1.0, "lifetime_variance": 0.1},
      age=_finite_state, lifetime=_positive, lifetime_variance=_nonneg),
    E("expected_population", cl.particles.expected_population,
      {"mean_counts": [1.0, 2.0, 3.0], "dt": 0.1, "lifetime": 1.0},
      mean_counts=_finite_state, dt=_positive, lifetime=_positive, lifetime_variance=_nonneg),
    E("steady_population", cl.particles.steady_population, {"mean_count": 2.0, "dt": 0.1, "lifetime": 1.0},
      mean_count=_nonneg, dt=_positive, lifetime=_positive, lifetime_variance=_nonneg),
    # boids, neighbours
    E("Rules", cl.boids.Rules, {}, separation=_finite, radius=_positive, min_speed=_nonneg,
      max_speed=_positive_or_inf),
    E("boids.step", cl.boids.step, {"x": FLOCK_X, "v": FLOCK_V, "dt": 0.1, "rules": cl.boids.Rules()},
      x=_state, v=_state, dt=_positive, method=_method),
    E("boids.steering", cl.boids.steering, {"x": FLOCK_X, "v": FLOCK_V, "rules": cl.boids.Rules()},
      x=_state, v=_state, method=_method),
    E("boids.all_pairs", cl.boids.all_pairs, {"x": FLOCK_X, "v": FLOCK_V, "rules": cl.boids.Rules()},
      x=_state, v=_state),
    E("boids.tree_pairs", cl.boids.tree_pairs, {"x": FLOCK_X, "v": FLOCK_V, "rules": cl.boids.Rules()},
      x=_state, v=_state),
    E("clamp_speed", cl.boids.clamp_speed, {"v": FLOCK_V, "min_speed": 0.5, "max_speed": 2.0},
      v=_finite_state, min_speed=_nonneg, max_speed=_positive_or_inf),
    E("flee", cl.boids.flee, {"x": FLOCK_X, "predator": (0.5, 0.5), "radius": 2.0, "strength": 1.0},
      x=_points, predator=_vector, radius=_positive, strength=_finite),
    E("avoid", cl.boids.avoid, {"x": FLOCK_X, "v": FLOCK_V, "centers": [[5.0, 5.0]], "radii": [1.0],
                                "lookahead": 2.0, "strength": 1.0},
      x=_state, v=_state, centers=_finite_state, radii=_masses, lookahead=_positive, strength=_finite),
    E("nearest_distances", cl.boids.nearest_distances, {"x": FLOCK_X}, x=_points),
    E("polarization", cl.boids.polarization, {"v": FLOCK_V}, v=_points),
    E("random_flock", cl.boids.random_flock, {"n": 4, "box": 10.0, "speed": 1.0, "rng": RNG},
      n=_count, box=_positive, speed=_nonneg),
    E("random_polarization", cl.boids.random_polarization, {"n": 4}, n=_count),
    E("random_nearest_distance", cl.boids.random_nearest_distance, {"n": 4, "box": 10.0},
      n=_count, box=_positive),
    E("neighbors.pairs", cl.neighbors.pairs, {"x": FLOCK_X, "radius": 1.5}, x=_points, radius=_positive),
    E("neighbors.all_pairs", cl.neighbors.all_pairs, {"x": FLOCK_X, "radius": 1.5}, x=_points,
      radius=_positive),
    E("wrap_positions", cl.neighbors.wrap_positions, {"x": FLOCK_X, "box": 10.0}, x=_finite_state,
      box=_positive),
    # the implicit step, collisions, events
    E("BaraffWitkin", cl.baraff_witkin.BaraffWitkin, {"network": HAIR_NET, "mass": 1e-3, "pinned": [0],
                                                         "gravity": (0.0, -9.81, 0.0)},
      mass=_masses, pinned=_indices(HAIR_N), gravity=_vector, rtol=_positive, maxiter=_count),
    E("BaraffWitkin.step", lambda **k: cl.baraff_witkin.BaraffWitkin(HAIR_NET, 1e-3, pinned=[0]).step(**k),
      {"x": HAIR_X, "v": np.zeros_like(HAIR_X), "dt": 0.01, "t": 0.0},
      x=_state, v=_state, dt=_positive, t=_finite),
    E("BaraffWitkin.run", lambda **k: cl.baraff_witkin.BaraffWitkin(HAIR_NET, 1e-3, pinned=[0]).run(**k),
      {"x0": HAIR_X, "v0": np.zeros_like(HAIR_X), "dt": 0.01, "n_steps": 2},
      x0=_state, v0=_state, dt=_positive, n_steps=_count),
    E("baraff_witkin_step", cl.baraff_witkin.baraff_witkin_step,
      {"network": HAIR_NET, "x": HAIR_X, "v": np.zeros_like(HAIR_X), "dt": 0.01, "mass": 1e-3,
       "pinned": [0]},
      x=_state, v=_state, dt=_positive, mass=_masses, pinned=_indices(HAIR_N), rtol=_positive),
    E("plane", cl.collisions.plane, {}, normal=_vector, offset=_finite, restitution=_finite,
      friction=_nonneg),
    E("sphere", cl.collisions.sphere, {}, center=_vector, radius=_positive, restitution=_finite,
      friction=_nonneg),
    E("self_contact", cl.collisions.self_contact, {"thickness": 0.01, "mass": [1.0, 1.0]},
      thickness=_positive, mass=_positive_values, iterations=_count),
    E("crossing_linear", cl.events.crossing_linear, {"t0": 0.0, "h0": 1.0, "t1": 1.0, "h1": -1.0},
      t0=_finite, h0=_finite, t1=_finite, h1=_finite, level=_finite),
    E("crossing_ballistic", cl.events.crossing_ballistic, {"h": 1.0, "v": 0.0, "a": -9.81},
      h=_finite, v=_finite, a=_finite, level=_finite),
    E("first_crossing", cl.events.first_crossing, {"t": T_SAMPLES, "h": H_SAMPLES},
      t=_state, h=_samples, level=_finite, rule=_method),
    E("upward_crossings", cl.events.upward_crossings, {"t": T_SAMPLES, "s": -H_SAMPLES},
      t=_state, s=_samples, level=_finite),
    E("measured_period", cl.events.measured_period,
      {"t": np.linspace(0, 4, 81), "s": np.sin(np.linspace(0, 4, 81) * 2 * np.pi)},
      t=_state, s=_samples, level=_finite),
    E("local_maxima", cl.events.local_maxima, {"t": T_SAMPLES, "h": np.sin(3 * T_SAMPLES)},
      t=_state, h=_samples),
    E("fit_circle", cl.events.fit_circle, {"points": [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]},
      points=_points),
    # rigid bodies
    E("rigid.make", cl.rigid.make, {"shape": "box", "mass": 1.0, "size": (1.0, 0.5, 0.2),
                                    "x": [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]},
      shape=_method, mass=_masses, size=_finite_state, x=_points, v=_finite_state, omega=_finite_state),
    E("rigid.free_body", cl.rigid.free_body, {"inertia": (1.0, 2.0, 3.0), "omega0": (0.1, 1.0, 0.1),
                                              "dt": 0.01, "steps": 3, "q0": (1.0, 0.0, 0.0, 0.0)},
      inertia=_masses, omega0=_state, dt=_positive, steps=_count, method=_method, q0=_vector_of_its_length),
    E("rigid.simulate", lambda **k: cl.rigid.simulate(_bodies(), **k), {"dt": 0.01, "steps": 2, "every": 1,
                                                                      "method": "rk4"},
      dt=_positive, steps=_count, every=_count, method=_method),
    E("rigid.step", lambda **k: cl.rigid.step(_bodies(), **k), {"dt": 0.01, "method": "rk4"}, dt=_positive,
      method=_method),
]
CLOTH = cl.cloth.sheet(n=3, size=0.2)
SPH_X = np.array([[0.0, 0.0], [0.05, 0.0], [0.0, 0.05], [0.05, 0.05]]) + 0.1
SPH_PARAMS = cl.sph.Params(spacing=0.05, sound_speed=20.0)


def _solver(cls, **options):
    return cls(HAIR_NET, 1e-3, pinned=[0], gravity=(0.0, -9.81, 0.0), **options)


#: The cloth, large-step and SPH modules (their owners' validation is swept the same way).
ENTRIES += [
    E("cloth.sheet", cl.cloth.sheet, {"n": 3, "size": 0.2}, n=_count, size=_positive, total_mass=_positive,
      k_struct=_positive, c=_nonneg, height=_finite),
    E("cloth.simulate", cl.cloth.simulate, {"cloth": CLOTH, "method": "symplectic_euler", "frames": 1,
                                            "substeps": 2, "fps": 30.0, "x0": CLOTH.x0, "v0": 0 * CLOTH.x0},
      method=_method, frames=_count, substeps=_count, fps=_positive, x0=_state, v0=_state,
      gravity=_vector_of_its_length, rtol=_positive, blowup_bound=_positive),
    E("cloth.explicit_dt_max", cl.cloth.explicit_dt_max, {"cloth": CLOTH, "n_steps": 20},
      n_steps=_count, rtol=_positive),
    E("XPBD", lambda **k: _solver(cl.largestep.XPBD, **k), {"iterations": 1, "substeps": 1},
      iterations=_count, substeps=_count),
    E("XPBD.step", lambda **k: _solver(cl.largestep.XPBD).step(**k),
      {"x": HAIR_X, "v": np.zeros_like(HAIR_X), "dt": 0.01, "t": 0.0}, x=_state, v=_state, dt=_positive,
      t=_finite),
    E("FastMassSpring", lambda **k: _solver(cl.largestep.FastMassSpring, **k), {"iterations": 3, "memory": 2},
      iterations=_count, memory=_size),
    E("FastMassSpring.step", lambda **k: _solver(cl.largestep.FastMassSpring, iterations=2).step(**k),
      {"x": HAIR_X, "v": np.zeros_like(HAIR_X), "dt": 0.01, "t": 0.0}, x=_state, v=_state, dt=_positive,
      t=_finite),
    E("StrainLimiter", lambda **k: cl.largestep.StrainLimiter(HAIR_NET, 1e-3, **k), {"max_strain": 0.1},
      max_strain=_positive),
    E("sph.Params", cl.sph.Params, {"spacing": 0.05}, spacing=_positive, rho0=_positive, kernel=_method,
      support_ratio=_positive, viscosity=_nonneg, cfl=_positive, gravity=_vector),
    E("sph.Simulation", cl.sph.Simulation, {"x": SPH_X, "params": SPH_PARAMS, "v": 0 * SPH_X},
      x=_points, v=_state, method=_method, t=_finite),
    E("sph.Simulation.step", lambda **k: cl.sph.Simulation(SPH_X, SPH_PARAMS, method="wcsph").step(**k),
      {"dt": 1e-4}, dt=_positive),
    E("sph.Simulation.run", lambda **k: cl.sph.Simulation(SPH_X, SPH_PARAMS, method="wcsph").run(**k),
      {"t_end": 2e-4, "frame_dt": 1e-4, "max_steps": 10}, t_end=_positive, frame_dt=_positive,
      max_steps=_count),
    E("sph.dam_break", cl.sph.dam_break, {"n_particles": 50, "t_end": 1e-3, "method": "wcsph"},
      n_particles=_count, t_end=_positive, method=_method, a=_positive),
    E("sph.water_column", cl.sph.water_column, {"width": 0.1, "depth": 0.1, "spacing": 0.025},
      width=_positive, depth=_positive, spacing=_positive, method=_method),
    E("sph.front_errors", cl.sph.front_errors, {"t": np.linspace(0.0, 1.0, 5), "z": np.linspace(1.0, 2.0, 5),
                                                "a": 0.1},
      t=_finite_state, z=_samples, a=_positive, delay=_nonneg, g=_positive),
    E("sph.ritter_front", cl.sph.ritter_front, {"T": np.linspace(0.0, 1.0, 5)}, T=_finite_state),
]
ENTRY = {e.name: e for e in ENTRIES}


def _cases():
    for e in ENTRIES:
        for arg, kind in e.kinds.items():
            for label, value in kind(e.good_value(arg)).items():
                yield pytest.param(e.name, arg, value, id=f"{e.name}-{arg}-{label}")


@pytest.mark.parametrize("name", list(ENTRY))
def test_every_entry_point_works_with_good_input(name):
    ENTRY[name].run()


@pytest.mark.parametrize(("name", "arg", "value"), list(_cases()))
def test_every_entry_point_names_the_bad_argument(name, arg, value):
    with pytest.raises((TypeError, ValueError)) as err:
        ENTRY[name].run(**{arg: value})
    assert re.search(rf"(?<![\w.]){re.escape(arg)}(?!\w)", str(err.value)), \
        f"{name}: the message does not name {arg!r}: {err.value}"


# --- particles and boids: the gaps a fifth blind read found (notebooks 09 and 10) -----------

def _system(n=4, dim=3, **kw):
    from course_lib import particles as P
    ps = P.ParticleSystem(dim=dim, capacity=8, **kw)
    if n:
        ps.add(x=np.zeros((n, dim)), v=np.ones((n, dim)), lifetime=1.0)
    return ps


@pytest.mark.parametrize("bad", [[0.0, np.inf, 0.0], [np.nan, 0.0, 0.0], np.full((4, 3), -np.inf)])
@pytest.mark.parametrize("as_callable", [False, True])
def test_particle_step_refuses_a_non_finite_acceleration(bad, as_callable):
    ps = _system()
    before = ps["v"].copy()
    with pytest.raises(ValueError, match="acceleration must be finite"):
        ps.step(0.1, (lambda system: np.asarray(bad)) if as_callable else bad)
    assert np.array_equal(ps["v"], before)                 # refused before anything moved


@pytest.mark.parametrize("bad", [[0.0, 1.0], np.zeros((3, 3)), np.zeros((4, 2)), np.zeros((2, 4, 3))])
def test_particle_step_names_a_wrong_shape_acceleration(bad):
    with pytest.raises(ValueError, match=r"acceleration must have shape \(4, 3\)"):
        _system().step(0.1, bad)


def test_particle_step_takes_an_acceleration_that_broadcasts_and_an_empty_system():
    ps = _system()
    ps.step(0.1, [0.0, -9.81, 0.0])
    ps.step(0.1, lambda system: -system["v"])
    empty = _system(n=0)
    empty.step(0.1, lambda system: -system["v"])              # (0, 3): nothing to check
    empty.step(0.1, [0.0, -9.81, 0.0])
    with pytest.raises(TypeError, match="acceleration"):
        ps.step(0.1, "down")


@pytest.mark.parametrize("huge", [1e308, -1e308])
def test_particle_step_stops_a_blow_up_and_says_so(huge):
    """Finite input that overflows (a blow-up) stops the run with a message, not inf."""
    from course_lib.integrators import BlowUpError
    ps = _system()
    ps["v"][...] = huge
    with pytest.raises(BlowUpError, match="blew up in step"):
        ps.step(10.0, [0.0, huge, 0.0])
    ps2 = _system(dim=2)
    with pytest.raises(BlowUpError, match="blew up in advect"):
        ps2.advect(0.0, 10.0, lambda t, x: np.full_like(x, huge))


@pytest.mark.parametrize("shape", ["x", 3.0, (3.0,), (-1,), (True,), None, {"a": 1}])
def test_particle_attributes_must_be_shapes(shape):
    from course_lib import particles as P
    with pytest.raises(TypeError, match=r"attributes\['c'\] must be the shape of one particle's value"):
        P.ParticleSystem(attributes={"c": shape})


def test_particle_attributes_accept_tuples_and_lists():
    from course_lib import particles as P
    ps = P.ParticleSystem(attributes={"c": (3,), "t": (), "m": [2, 2]})
    assert ps.shapes["c"] == (3,) and ps.shapes["t"] == () and ps.shapes["m"] == (2, 2)


@pytest.mark.parametrize("rng", [None, 2026, np.random.RandomState(1), "seed"])
def test_reeves_count_needs_a_generator(rng):
    from course_lib import particles as P
    with pytest.raises(TypeError, match="rng must be a numpy Generator"):
        P.reeves_count(5.0, 1.0, rng)


@pytest.mark.parametrize("n", [1, 0, -3])
def test_random_nearest_distance_needs_two_points(n):
    from course_lib import boids as B
    with pytest.raises(ValueError, match="n must be"):
        B.random_nearest_distance(n, 20.0)
    assert B.random_nearest_distance(2, 20.0) > 0


def test_avoid_pushes_a_boid_at_an_obstacle_centre_out():
    """A boid exactly at a centre is pushed out across its heading (its left in 2D), at rest
    along the first axis; off the centre, straight out, as before."""
    from course_lib import boids as B
    centers, radii = np.array([[5.0, 5.0], [10.0, 2.0]]), np.array([1.0, 0.5])
    x = np.array([[5.0, 5.0], [10.0, 2.0], [10.0, 2.0], [5.3, 5.0]])
    v = np.array([[1.0, 0.0], [0.0, 2.0], [0.0, 0.0], [0.0, 1.0]])
    a = B.avoid(x, v, centers, radii, lookahead=2.0, strength=3.0)
    assert np.allclose(a, [[0.0, 3.0], [-3.0, 0.0], [3.0, 0.0], [3.0, 0.0]])
    a3 = B.avoid(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.zeros((1, 3)), [1.0], 2.0, 3.0)
    assert np.allclose(np.linalg.norm(a3), 3.0) and abs(a3[0, 2]) < 1e-12     # across u
