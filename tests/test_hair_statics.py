"""Resting shapes are stable minima (course_lib.statics, hair.static_shape): the class of
strands that used to end on saddle points (zigzag and curled strands held sideways, helices
with a horizontal axis), in several orientations, checked by the Hessian and by a nudged,
damped dynamic run."""

import numpy as np
import pytest

from course_lib import hair as H
from course_lib import springs as S
from course_lib import statics, strands

G = np.array([0.0, -9.81, 0.0])
NUDGE = 1e-6          # m, per coordinate (seeded normal)
CLAMP = (0, 1)


def strand(shape: str, direction):
    """A held-out strand with bending springs as stiff as its edges, root clamped."""
    if shape == "helix":
        x0 = strands.helix(16, 0.3, radius=0.01, turn=np.pi / 3, axis=direction)
        return x0, strands.strand_network(x0, 2000.0, 2000.0, 500.0)
    extra = {"zigzag": {"zigzag": 0.3}, "curl": {"curl": 0.3}, "straight": {}}[shape]
    return S.hair_chain(**H.STRAND, k_bend=2000.0, direction=direction, **extra)


def nudged_run(x_eq, net, seconds=0.3, dt=1e-4, damping=2e-3):
    """Largest distance (m, Euclidean over all coordinates) from ``x_eq`` of a damped
    symplectic Euler run started 1 µm away, and the run's last state."""
    rng = np.random.default_rng(7)
    nudge = NUDGE * rng.standard_normal(x_eq.shape)
    nudge[list(CLAMP)] = 0.0
    x, message = H.symplectic_euler_run(x_eq + nudge, net, dt, round(seconds / dt),
                                        pinned=CLAMP, damping=damping)
    assert message == "ok"
    return float(np.linalg.norm(x - x_eq, axis=(1, 2)).max()), x[-1], float(np.linalg.norm(nudge))


CASES = [("zigzag", (1.0, 0.0, 0.0)), ("zigzag", (0.0, 0.0, 1.0)), ("zigzag", (1.0, 0.0, 1.0)),
         ("curl", (1.0, 0.0, 0.0)), ("curl", (0.0, 0.2, 1.0)), ("helix", (1.0, 0.0, 0.0)),
         ("helix", (1.0, 1.0, 0.0)), ("straight", (0.0, -1.0, 0.2))]


@pytest.fixture(scope="module")
def minima():
    out = {}
    for shape, direction in CASES:
        x0, net = strand(shape, direction)
        out[shape, direction] = (x0, net, statics.equilibrium(x0, net, H.MASS, CLAMP, G))
    return out


@pytest.mark.parametrize(("shape", "direction"), CASES)
def test_the_resting_shape_is_a_stable_minimum(minima, shape, direction):
    x0, net, eq = minima[shape, direction]
    assert np.array_equal(eq.x[list(CLAMP)], x0[list(CLAMP)])
    force = net.forces(eq.x) + H.MASS * G
    assert np.linalg.norm(force[2:]) < 1e-9 * H.MASS * 9.81 * 14
    lam = statics.curvature(net, eq.x, CLAMP)
    # positive definite on the free coordinates: the softest direction is a swing of the
    # hanging strand, about m g / L per particle (≈ 3e-3 N/m), far above round-off
    assert lam[0] > 1e-3 and lam[0] == pytest.approx(eq.lowest, rel=1e-6)
    assert H.static_shape(x0, net) == pytest.approx(eq.x, abs=1e-12)
    # a nudged, damped run stays near it: in the linear regime each mode keeps at most its
    # start amplitude, times symplectic Euler's band 1/(1 - ω dt/2) < 2.5 at ω_max dt ≈ 1.1
    far, _, size = nudged_run(eq.x, net)
    assert far < 2.5 * np.sqrt(eq.x.size) * size


@pytest.mark.parametrize(("shape", "direction"), [("zigzag", (1.0, 0.0, 0.0)),
                                                  ("curl", (1.0, 0.0, 0.0))])
def test_the_planar_equilibrium_is_a_saddle_that_a_nudge_leaves(minima, shape, direction):
    x0, net, eq = minima[shape, direction]
    planar = statics.equilibrium(x0, net, H.MASS, CLAMP, G, axes=(0, 1))
    assert np.all(planar.x[:, 2] == 0.0)                     # stayed in its plane
    assert planar.lowest > 0.0                               # a minimum among planar shapes ...
    lam = statics.curvature(net, planar.x, CLAMP)
    assert lam[0] < -1e-2                                    # ... and a saddle in 3D
    assert planar.energy > eq.energy
    # undamped, the nudge grows like exp(√(-λ/m) t), 40/s for the curl's -0.16 N/m
    far, _, _ = nudged_run(planar.x, net, seconds=1.0, damping=0.0)
    assert far > 1e-2                                        # it falls, by centimetres
    # the 3D search leaves the saddle along the negative curvature (the zigzag's planar
    # start never feels a force across its plane)
    assert eq.escapes >= 1 or shape == "curl"


def test_a_helix_with_a_horizontal_axis_converges():
    # used to raise "the line search found no lower energy" (a zero-energy turn about the
    # clamp's axis made Newton's step enormous)
    x0, net = strand("helix", (1.0, 0.0, 0.0))
    x = H.static_shape(x0, net)
    assert statics.curvature(net, x, CLAMP)[0] > 0.0


def test_planar_strand_keeps_its_plane_and_matches_the_2d_problem():
    x0, net = S.hair_chain(**H.STRAND, k_bend=2000.0, zigzag=0.3)
    planar = H.static_shape(x0, net, axes=(0, 1))
    assert np.all(planar[:, 2] == 0.0)
    lam2d = statics.curvature(net, planar, CLAMP, axes=(0, 1))
    assert lam2d[0] > 0.0


def test_no_minimum_is_said_clearly():
    # a particle tied to nothing falls for ever: the energy has no minimum
    net = S.SpringNetwork([0], [1], [0.1], [100.0], [0.0], 3)
    x0 = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.5, 0.0, 0.0]])
    with pytest.raises(RuntimeError, match="no stable minimum"):
        statics.equilibrium(x0, net, 1e-3, pinned=(0,), gravity=G, max_iter=50)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"x0": np.zeros((4, 3))}, "shape"), ({"mass": -1.0}, "mass"),
    ({"gravity": (0.0, -9.81)}, "gravity"), ({"axes": (3,)}, "axes"),
    ({"x0": np.full((16, 3), np.nan)}, "finite")])
def test_bad_input_is_named(kwargs, match):
    x0, net = S.hair_chain(**H.STRAND)
    args = {"x0": x0, "mass": H.MASS, "gravity": G, **kwargs}
    with pytest.raises(ValueError, match=match):
        statics.equilibrium(args["x0"], net, args["mass"], CLAMP, args["gravity"],
                            axes=kwargs.get("axes"))


def test_model_step_hard_case_goes_down_negative_curvature():
    lam = np.array([-2.0, 1.0, 3.0])
    grad = np.array([0.0, 1.0, 1.0])            # nothing along the negative direction
    p, escape = statics.model_step(lam, np.eye(3), grad, radius=2.0)
    assert escape and np.linalg.norm(p) == pytest.approx(2.0)
    assert abs(p[0]) > 1.0                       # most of the step goes down the saddle
    model = grad @ p + 0.5 * p @ (lam * p)
    assert model < 0.0
    # positive definite and a short Newton step: Newton's step itself
    p, escape = statics.model_step(np.array([1.0, 2.0]), np.eye(2), np.array([0.1, 0.2]), 1.0)
    assert not escape and p == pytest.approx([-0.1, -0.1])
