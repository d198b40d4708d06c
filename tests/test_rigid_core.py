"""course_lib.rigid: quaternions, inertia tensors, torque-free spin and its exact solution.

Tolerances are derived: a quantity a method keeps exactly may drift by a few units of
round-off per step (``steps × c × eps``); a quadrature rule exact for the integrand agrees
to round-off; a second-order error halves its step and quarters.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from course_lib import rigid
from course_lib.integrators import BlowUpError
from course_lib.rigid import _spin, exact, free, inertia
from course_lib.rigid import quaternion as quat

EPS = np.finfo(float).eps
RNG = np.random.default_rng(1401)


def _unit(n):
    return quat.normalize(RNG.normal(size=(n, 4)))


# --- quaternions -------------------------------------------------------------------------


def test_product_composes_rotations_and_rotate_matches_the_matrix():
    p, q = _unit(6), _unit(6)
    r = RNG.normal(size=(6, 3))
    Rp, Rq = quat.to_matrix(p), quat.to_matrix(q)
    assert np.allclose(quat.to_matrix(quat.multiply(p, q)), Rp @ Rq, atol=1e-14)
    assert np.allclose(quat.rotate(q, r), np.einsum("nij,nj->ni", Rq, r), atol=1e-14)
    assert np.allclose(np.einsum("nji,njk->nik", Rq, Rq), np.eye(3), atol=1e-14)   # orthogonal
    assert np.allclose(np.linalg.det(Rq), 1.0, atol=1e-14)                           # proper
    assert not np.allclose(quat.multiply(p, q), quat.multiply(q, p))                 # order matters
    assert np.allclose(quat.cross(r, r[::-1]), np.cross(r, r[::-1]), rtol=0, atol=1e-15)


def test_axis_angle_and_rotation_vector():
    axis, angle = np.array([1.0, 2.0, -2.0]), 0.9
    q = quat.from_axis_angle(axis, angle)
    assert np.allclose(q, quat.from_rotvec(angle * axis / 3.0), atol=1e-15)
    assert np.allclose(quat.rotate(q, axis), axis, atol=1e-14)                     # axis stays put
    assert np.allclose(quat.from_rotvec(np.zeros(3)), quat.IDENTITY)
    with pytest.raises(ValueError, match="non-zero"):
        quat.from_axis_angle(np.zeros(3), 1.0)
    with pytest.raises(ValueError, match="non-zero quaternion"):
        quat.normalize(np.zeros(4))


def test_explicit_step_length_growth_and_cayley_angle():
    """Without renormalisation |q| grows by √(1 + |ω|²Δt²/4) a step (exactly, since
    |p ⊗ q| = |p||q|); renormalised, the step rotates by 2 atan(|ω|Δt/2) about ω."""
    q = _unit(1)[0]
    omega, dt = np.array([0.3, -4.0, 2.0]), 0.05
    raw = q + 0.5 * dt * quat.multiply(np.r_[0.0, omega], q)
    w = np.linalg.norm(omega)
    assert np.linalg.norm(raw) == pytest.approx(np.sqrt(1 + (w * dt) ** 2 / 4), rel=4 * EPS)
    assert np.allclose(quat.step(q, omega, dt, renormalise=False), raw, rtol=0, atol=4 * EPS)
    stepped = quat.step(q, omega, dt)
    turn = quat.multiply(stepped, quat.conjugate(q))
    assert np.allclose(turn, quat.from_axis_angle(omega, 2 * np.arctan(w * dt / 2)), atol=1e-15)
    # the body-frame form is the same rotation
    body = quat.rotate(quat.conjugate(q), omega)
    assert np.allclose(quat.body_step(q, body, dt), stepped, atol=1e-15)
    assert np.allclose(quat.exp_step(q, body, dt), quat.multiply(quat.from_rotvec(dt * omega), q), atol=1e-15)


# --- inertia -----------------------------------------------------------------------------


def _gauss_box(mass, sides):
    """∫ (|r|² 1 − r rᵀ) dm over a uniform box by 2-point Gauss–Legendre per axis: exact
    for the quadratic integrand."""
    nodes, weights = np.polynomial.legendre.leggauss(2)
    pts = np.stack(np.meshgrid(*(0.5 * s * nodes for s in sides), indexing="ij"), -1).reshape(-1, 3)
    w = np.einsum("i,j,k->ijk", weights, weights, weights).ravel() / 8.0 * mass
    return np.einsum("n,nij->ij", w, np.sum(pts**2, 1)[:, None, None] * np.eye(3)
                     - pts[:, :, None] * pts[:, None, :])


@pytest.mark.parametrize("sides", [(0.3, 0.2, 0.1), (0.1, 0.3, 0.2), (0.2, 0.1, 0.4), (1.0, 1.0, 1.0)])
def test_box_moments_against_quadrature(sides):
    got = inertia.box_moments(2.5, sides)
    assert np.allclose(np.diag(got), _gauss_box(2.5, np.array(sides)), rtol=8 * EPS, atol=0)


def test_sphere_and_cylinder_against_quadrature():
    from scipy.integrate import tplquad
    m, r, h = 3.0, 0.2, 0.5
    rho = m / (np.pi * r * r * h)
    # cylinder along z, in cylindrical coordinates: ∫∫∫ (x² + y²) ρ s ds dφ dz, and x² + z²
    Izz = tplquad(lambda s, phi, z: rho * s**3, -h / 2, h / 2, 0, 2 * np.pi, 0, r)[0]
    Ixx = tplquad(lambda s, phi, z: rho * s * ((s * np.sin(phi)) ** 2 + z * z), -h / 2, h / 2,
                  0, 2 * np.pi, 0, r)[0]
    assert np.allclose(inertia.cylinder_moments(m, r, h, "z"), [Ixx, Ixx, Izz], rtol=1e-10)
    assert np.allclose(inertia.cylinder_moments(m, r, h, "x"), [Izz, Ixx, Ixx], rtol=1e-10)
    rho_s = m / (4 / 3 * np.pi * r**3)   # sphere: ∫ (x² + y²) dm in spherical coordinates
    Is = tplquad(lambda s, th, ph: rho_s * s**4 * np.sin(th) ** 3, 0, 2 * np.pi, 0, np.pi, 0, r)[0]
    assert np.allclose(inertia.sphere_moments(m, r), Is, rtol=1e-10)


def test_world_tensor_and_its_inverse():
    moments = inertia.box_moments(1.0, (0.3, 0.2, 0.1))
    R = quat.to_matrix(_unit(4))
    I_w = inertia.world_tensor(R, moments)
    assert np.allclose(I_w, R @ np.diag(moments) @ np.transpose(R, (0, 2, 1)), rtol=1e-14, atol=0)
    assert np.allclose(inertia.world_inverse(R, moments) @ I_w, np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.eigvalsh(I_w), np.sort(moments), rtol=1e-12)    # same moments


@pytest.mark.parametrize("bad,match", [((1.0, 2.0), "shape"), ((1.0, -1.0, 1.0), "> 0"),
                                       ((1.0, 1.0, 3.0), "triangle"), ((1.0, np.nan, 1.0), "finite")])
def test_bad_moments_are_refused(bad, match):
    with pytest.raises(ValueError, match=match):
        inertia.check_moments("inertia", bad)


def test_bad_shape_arguments():
    with pytest.raises(ValueError, match="sides"):
        inertia.box_moments(1.0, (0.1, 0.0, 0.2))
    with pytest.raises(ValueError, match="mass"):
        inertia.sphere_moments(-1.0, 0.1)
    with pytest.raises(ValueError, match="axis"):
        inertia.cylinder_moments(1.0, 0.1, 0.2, axis="w")


# --- torque-free spin --------------------------------------------------------------------

MOMENTS = np.array([1.0, 2.0, 3.0])
OMEGA0 = np.array([0.05, 1.0, 0.02])


@pytest.fixture(scope="module")
def runs():
    T = exact.period(MOMENTS, OMEGA0)
    dt = T / 400
    return T, dt, {m: rigid.free_body(MOMENTS, OMEGA0, dt, 800, m) for m in free.METHODS}


def _invariants(omega):
    L = omega * MOMENTS
    return np.linalg.norm(L, axis=1), 0.5 * np.sum(L * omega, axis=1)


def test_free_body_shapes_and_start(runs):
    _, dt, all_runs = runs
    for t, omega, q in all_runs.values():
        assert t.shape == (801,) and omega.shape == (801, 3) and q.shape == (801, 4)
        assert np.allclose(omega[0], OMEGA0) and np.allclose(q[0], quat.IDENTITY)
        assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=4 * EPS)
        assert t[-1] == pytest.approx(800 * dt)


@pytest.mark.roundoff
def test_invariants_per_method(runs):
    """What each method keeps, gains or loses (module docstring of free), with round-off
    bounds of 16 eps per step where a quantity is kept exactly."""
    _, _, all_runs = runs
    bound = 16 * EPS * 800
    grow = {}
    for method, (_, omega, q) in all_runs.items():
        L, E = _invariants(omega)
        grow[method] = (np.diff(L), np.diff(E))
        world = quat.rotate(q, omega * MOMENTS)
        if method in ("implicit_midpoint", "splitting", "baraff_euler"):
            assert np.abs(L / L[0] - 1).max() < bound, method
            assert np.abs(world - world[0]).max() < bound * L[0], method     # L_world fixed
    L, E = _invariants(all_runs["implicit_midpoint"][1])
    assert np.abs(E / E[0] - 1).max() < bound
    assert np.all(grow["forward_euler"][0] > 0) and np.all(grow["forward_euler"][1] > 0)
    assert np.all(grow["backward_euler"][0] < 0) and np.all(grow["backward_euler"][1] < 0)
    assert np.all(grow["baraff_euler"][1] > 0)                               # E gains every step
    _, E = _invariants(all_runs["splitting"][1])
    dE = E / E[0] - 1
    assert np.abs(dE).max() < 1e-3 and abs(dE[-1]) < np.abs(dE).max()      # bounded, no drift


def test_forward_euler_growth_is_the_formula():
    """|L_{n+1}|² = |L_n|² + Δt²|L_n × Ω_n|² and E grows by ½Δt²(L×Ω)ᵀI⁻¹(L×Ω), exactly."""
    dt = 0.03
    _, omega, _ = rigid.free_body(MOMENTS, OMEGA0, dt, 5, "forward_euler")
    L = omega * MOMENTS
    g = np.cross(L[:-1], omega[:-1])
    assert np.allclose(np.sum(L[1:] ** 2, 1) - np.sum(L[:-1] ** 2, 1), dt**2 * np.sum(g * g, 1), rtol=1e-9)
    E = 0.5 * np.sum(L * omega, 1)
    assert np.allclose(np.diff(E), 0.5 * dt**2 * np.sum(g * g / MOMENTS, 1), rtol=1e-7)


@pytest.mark.parametrize("method", free.METHODS)
def test_scalar_path_matches_the_vectorized_step(method):
    q, L = _unit(5), RNG.normal(size=(5, 3))
    moments = np.array([[1.0, 2.0, 2.5]] * 5)
    qb, Lb = free.rotate(q, L, moments, 0.05, method)
    for k in range(5):
        qs, Ls = _spin.step(tuple(q[k]), tuple(L[k]), tuple(moments[k]), 0.05, method,
                            free.NEWTON_TOL_ULPS, free.NEWTON_MAX_ITER)
        assert np.allclose(qs, qb[k], atol=64 * EPS) and np.allclose(Ls, Lb[k], atol=64 * EPS * 3)


def _dop853(moments, w0, t):
    sol = solve_ivp(lambda t, w, mom=moments: np.cross(mom * w, w) / mom, (0, t[-1]), w0,
                    method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
    return sol.y.T


@pytest.mark.parametrize("circles", ["smallest", "largest"])
def test_exact_solution_against_dop853(circles):
    """Both cases (|L|² below and above 2EI₂), moments in every order (right- and
    left-handed relabellings): the elliptic formulas against DOP853 at rtol 1e-12; each
    amplitude is the largest |Ω_i| of the run, the dn component never changes sign and
    its smallest value is A √(1 − m)."""
    rng = np.random.default_rng(1402 if circles == "smallest" else 1403)
    done = 0
    while done < 5:
        moments, w0 = rng.uniform(1.0, 2.0, 3), rng.normal(size=3)
        p = exact.parameters(moments, w0)
        if p["circles"] != circles:
            continue
        done += 1
        t = np.linspace(0, 1.7 * p["period"], 400)
        ref = _dop853(moments, w0, t)
        assert np.abs(exact.omega(moments, w0, t) - ref).max() < 1e-8 * np.abs(w0).max()
        dn = p["functions"].index("dn")
        assert p["functions"][p["order"][0 if circles == "smallest" else 2]] == "dn"
        assert np.all(np.sign(ref[:, dn]) == np.sign(p["amplitudes"][dn]))
        # 400 samples over 1.7 periods land within (2π/400)² of each extreme (relative)
        assert np.abs(ref).max(axis=0) == pytest.approx(np.abs(p["amplitudes"]), rel=1e-3)
        least = abs(p["amplitudes"][dn]) * np.sqrt(1 - p["m"])
        assert np.abs(ref[:, dn]).min() == pytest.approx(least, rel=1e-3)
        assert (p["D"] < 0) == (circles == "smallest")


def test_the_notebooks_flip_is_the_smallest_axis_case():
    """The box nudged about x: |L|² − 2EI₂ = I₁Ω₁²(I₁ − I₂) < 0, so Ω = (A₁ dn, A₂ sn, A₃ cn)
    with the amplitudes of the notebook's formulas, τ₀ = K(m), and DOP853 agrees."""
    moments, w0 = inertia.box_moments(0.3, (0.2, 0.1, 0.05)), np.array([0.1, 10.0, 0.0])
    p = exact.parameters(moments, w0)
    I1, I2, I3 = moments
    assert p["D"] == pytest.approx(I1 * 0.1**2 * (I1 - I2), rel=1e-12) and p["D"] < 0
    assert p["functions"] == ("dn", "sn", "cn") and p["circles"] == "smallest"
    L2, E2 = np.sum((moments * w0) ** 2), np.sum(moments * w0**2)
    A = np.sqrt([(E2 * I3 - L2) / (I1 * (I3 - I1)), (L2 - E2 * I1) / (I2 * (I2 - I1)),
                 (L2 - E2 * I1) / (I3 * (I3 - I1))])
    assert np.allclose(p["amplitudes"], A, rtol=1e-9)
    assert p["amplitudes"][1] == pytest.approx(10.0, rel=1e-12)                 # Ω_y starts at its peak
    assert p["amplitudes"][0] * np.sqrt(1 - p["m"]) == pytest.approx(0.1, rel=1e-9)  # and Ω_x at its least
    assert p["tau0"] == pytest.approx(ellipk(p["m"]), rel=1e-12) and p["rate"] > 0
    t = np.linspace(0, 8.0, 801)
    assert np.abs(exact.omega(moments, w0, t) - _dop853(moments, w0, t)).max() < 1e-8
    # the formulas printed for the other case give m > 1 here: K(m) has no real value
    m_other = (I2 - I1) * (E2 * I3 - L2) / ((I3 - I2) * (L2 - E2 * I1))
    assert m_other > 1


def test_spin_about_a_principal_axis():
    """m = 0: Ω stays put; the period is that of small wobbles about the axis."""
    for w0 in ([2.0, 0.0, 0.0], [0.0, 0.0, -3.0]):
        t = np.linspace(0.0, 5.0, 6)
        assert np.allclose(exact.omega(MOMENTS, w0, t), np.array(w0)[None], atol=1e-15)
        assert exact.parameters(MOMENTS, w0)["m"] == 0.0


def test_exact_refuses_the_separatrix_and_equal_moments():
    with pytest.raises(ValueError, match="distinct"):
        exact.period([1.0, 1.0, 1.5], [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="separatrix"):
        exact.period([1.0, 2.0, 3.0], [0.0, 1.0, 0.0])


def test_flip_period_within_one_percent_at_a_small_step():
    """The issue's target: 100 steps per period get the period within 1 %; the error of
    the second-order methods falls by 4 when the step halves (2 ± 0.15 in the slope)."""
    T = exact.period(MOMENTS, OMEGA0)
    errors = {}
    for n in (100, 200):
        t, omega, _ = rigid.free_body(MOMENTS, OMEGA0, T / n, int(2.2 * n), "implicit_midpoint")
        errors[n] = exact.measured_period(t, omega, 1) / T - 1
    assert abs(errors[100]) < 0.01
    assert np.log2(errors[100] / errors[200]) == pytest.approx(2.0, abs=0.15)


def test_measured_period_needs_two_crossings():
    t = np.linspace(0, 1, 11)
    with pytest.raises(ValueError, match="sign"):
        exact.measured_period(t, np.ones((11, 3)), 1)
    assert np.allclose(exact.crossings(t, np.cos(2 * np.pi * t)), [0.25, 0.75], atol=0.01)


@pytest.mark.parametrize("kwargs,error,match", [
    ({"inertia": [1.0, 2.0]}, ValueError, "inertia"),
    ({"inertia": [1.0, 0.0, 1.0]}, ValueError, "> 0"),
    ({"omega0": [1.0, 2.0]}, ValueError, "omega0"),
    ({"omega0": [1.0, np.inf, 0.0]}, ValueError, "finite"),
    ({"dt": 0.0}, ValueError, "dt"),
    ({"dt": -0.1}, ValueError, "dt"),
    ({"steps": 0}, ValueError, "steps"),
    ({"steps": 2.5}, TypeError, "steps"),
    ({"method": "verlet"}, ValueError, "implicit_midpoint"),
    ({"method": 3}, TypeError, "method"),
])
def test_free_body_validates_its_input(kwargs, error, match):
    args = {"inertia": MOMENTS, "omega0": OMEGA0, "dt": 0.01, "steps": 3, "method": "rk4", **kwargs}
    with pytest.raises(error, match=match):
        rigid.free_body(**args)


def test_a_run_that_blows_up_says_so(monkeypatch):
    with pytest.raises(BlowUpError, match="forward_euler blew up at step"):
        rigid.free_body(MOMENTS, [3.0, 30.0, 5.0], 1.0, 200, "forward_euler")
    monkeypatch.setattr(free, "NEWTON_MAX_ITER", 1)      # Newton's method cut short
    with pytest.raises(BlowUpError, match="Newton"):
        rigid.free_body(MOMENTS, [3.0, 30.0, 5.0], 0.1, 5, "implicit_midpoint")
    with pytest.raises(BlowUpError, match="Newton"):
        free.rotate(quat.IDENTITY, np.array([3.0, 30.0, 5.0]), MOMENTS, 0.1, "backward_euler")
