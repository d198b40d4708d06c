"""Every number quoted in solutions/08_hair_chains.ipynb, its widget, and its exercise checks."""

import numpy as np
import pytest

from course_lib import hair as H
from course_lib import springs as S
from course_lib.check import RESULTS
from course_lib.check import nb08 as check

M, K = H.MASS, H.STRAND["k_edge"]


def test_strand_setup_and_swing():
    x0, net = S.hair_chain(**H.STRAND)
    assert net.n_springs == 15 and net.rest[0] == pytest.approx(0.02)
    swing = H.simulate(x0, net, frames=40, substeps=160)
    assert swing.dt == pytest.approx(1 / 4800) and swing.stable
    assert swing.frames.shape == (41, 16, 3)
    assert np.all(swing.x[:, 0] == x0[0])                      # the root stays pinned
    assert H.max_strain(swing, net) == pytest.approx(0.0229, abs=5e-5)


@pytest.mark.parametrize(("k_bend", "zigzag", "sag_cm"), [
    (0.0, 0.0, 28.01), (2000.0, 0.0, 24.85), (0.0, 0.3, 29.24), (2000.0, 0.3, 3.31)])
def test_held_strand_sag(k_bend, zigzag, sag_cm):
    assert H.tip_sag(k_bend, zigzag) * 100 == pytest.approx(sag_cm, abs=0.005)


def test_static_shape_is_an_equilibrium():
    x0, net = H.held_strand(2000.0, 0.3)
    x = H.static_shape(x0, net)
    F = net.forces(x) + M * np.array([0.0, -9.81, 0.0])
    assert np.abs(F[2:]).max() < 1e-4 * M * 9.81 * 16


def test_spring_families():
    _, net3 = S.hair_chain(**H.STRAND, k_bend=2000.0, k_twist=500.0)
    counts = {k: net3.select(k).n_springs for k in ("edge", "bend", "twist")}
    assert counts == {"edge": 15, "bend": 14, "twist": 13}


def test_chain_step_limit():
    sqrt_mk = np.sqrt(M / K)
    assert sqrt_mk * 1e3 == pytest.approx(0.2236, abs=5e-5)
    x0, net = S.hair_chain(**H.STRAND)
    w = S.max_frequency(net, x0, M, pinned=[0])
    assert w == pytest.approx(S.chain_max_frequency(15, K, M), rel=1e-12)
    assert w == pytest.approx(8898.38, abs=0.005)
    assert 2e3 / w == pytest.approx(0.22476, abs=5e-6)
    measured = H.chain_dt_max(net, x0)
    assert measured * w / 2 == pytest.approx(0.99996, abs=5e-6)       # "to 0.004%"
    assert measured == pytest.approx(2 / w, rel=1e-2)
    assert measured / sqrt_mk == pytest.approx(1.0051, abs=5e-5)       # "0.5% above sqrt(m/k)"
    # substeps per frame at 30 fps
    assert int(np.ceil((1 / 30) / measured)) == 149


def test_bending_springs_lower_the_limit():
    xb, netb = S.hair_chain(**H.STRAND, k_bend=2000.0)
    w = S.max_frequency(netb, xb, M, pinned=[0])
    assert (2 / w) / np.sqrt(M / K) == pytest.approx(0.81, abs=5e-4)
    assert int(np.ceil((1 / 30) / (2 / w))) == 185
    xz, netz = S.hair_chain(**H.STRAND, k_bend=2000.0, zigzag=0.3)
    assert 2e3 / S.max_frequency(netz, xz, M, pinned=[0]) == pytest.approx(0.18347, abs=5e-6)
    # the held strand (two particles pinned) of the widget: limit 0.184 ms
    assert H.run_held_strand(dt=1e-4, t_end=0.01).dt_limit * 1e3 == pytest.approx(0.184, abs=5e-4)


def test_strain_against_substeps():
    budgets = [10, 20, 40, 80, 160]
    strains = np.array(H.max_strain_vs_substeps(budgets))
    assert H.stiffest_edge(10) == pytest.approx(4.5) and H.stiffest_edge(160) == pytest.approx(1152.0)
    assert strains[0] == pytest.approx(0.6234, abs=5e-5)
    assert strains[-1] == pytest.approx(0.00303, abs=5e-6)
    ratios = strains[:-1] / strains[1:]
    assert np.all(np.diff(strains) < 0)
    assert ratios.min() == pytest.approx(3.39, abs=0.005) and ratios.max() == pytest.approx(4.23, abs=0.005)


def test_damping_calms_the_strand():
    eq = None
    spans = {}
    for c in (0.0, 2e-3):
        run = H.run_held_strand(k_bend=2000.0, damping=c, dt=1e-4, t_end=0.5)
        assert run.stable
        late = run.tip_y[run.params["t"] > 0.4]
        spans[c] = (late.min(), late.max())
        eq = run.equilibrium[-1, 1]
    assert eq * 100 == pytest.approx(-2.71, abs=0.005)
    assert spans[0.0][0] * 100 == pytest.approx(-6.11, abs=0.005)
    assert abs(spans[2e-3][0] - eq) < 1e-3 and abs(spans[2e-3][1] - eq) < 1e-3     # settled


def test_widget_blowup_state():
    run = H.run_held_strand(k_bend=2000.0, damping=2e-3, dt=1.9e-4, t_end=0.5)
    assert not run.stable and "step 32" in run.message


def test_held_strand_explorer_view():
    view = H.held_strand_explorer(k_bend=2000.0, damping=2e-3, dt=1e-4)
    assert view.result.stable
    view.controls["dt"].value = 3e-4                      # past the 0.184 ms limit
    assert not view.result.stable
    view.controls["k_bend"].value = 10.0                  # soft bending springs: droops
    view.controls["dt"].value = 1e-4
    r = view.result
    assert r.stable and r.params["k_bend"] == pytest.approx(10.0, rel=1e-2)
    assert r.equilibrium[-1, 1] < -0.25


def test_hairstyle_one_network_and_head_collision():
    center, R = np.zeros(3), 0.1
    xs, net, roots = H.hairstyle(n_strands=7, center=center, radius=R, k_bend=200.0)
    assert xs.shape == (112, 3) and net.n_springs == 203 and roots.tolist() == list(range(0, 112, 16))
    assert np.allclose(np.linalg.norm(xs[roots] - center, axis=1), R)
    assert np.allclose(net.strain(xs), 0.0) and np.allclose(net.forces(xs), 0.0, atol=1e-9)
    w = S.max_frequency(net, xs, M, pinned=roots)
    assert 2e3 / w == pytest.approx(0.2244, abs=5e-5)
    style = H.simulate(xs, net, frames=45, substeps=180, pinned=roots, damping=2e-3,
                       post_step=H.head_collision(center, R, pinned=roots))
    assert style.stable
    assert np.linalg.norm(style.x - center, axis=-1).min() >= R * (1 - 1e-12)
    assert H.max_strain(style, net) == pytest.approx(0.0026, abs=5e-5)
    assert np.all(style.x[:, roots] == xs[roots])


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb08.{name}"]["status"]


def test_check_chain_spring_indices(capsys):
    def right(n):
        e, b = np.arange(n - 1), np.arange(n - 2)
        return np.r_[e, b], np.r_[e + 1, b + 2]

    check.chain_spring_indices(right)
    assert _status("chain_spring_indices") == "correct"
    capsys.readouterr()

    def one_too_many(n):
        e, b = np.arange(n - 1), np.arange(n - 1)
        return np.r_[e, b], np.r_[e + 1, b + 2]

    check.chain_spring_indices(one_too_many)
    assert _status("chain_spring_indices") == "incorrect"
    assert "off by one" in capsys.readouterr().out

    def pending(n):
        raise NotImplementedError()

    check.chain_spring_indices(pending)
    assert _status("chain_spring_indices") == "pending"


def test_check_max_strain_for_substeps(capsys):
    check.max_strain_for_substeps(lambda counts: H.max_strain_vs_substeps(counts))
    assert _status("max_strain_for_substeps") == "correct"
    capsys.readouterr()

    def frames_only(counts):
        out = []
        for s in counts:
            x0, net = S.hair_chain(**{**H.STRAND, "k_edge": H.stiffest_edge(s)})
            out.append(np.max(np.abs(net.strain(H.simulate(x0, net, frames=12, substeps=s).frames))))
        return out

    check.max_strain_for_substeps(frames_only)
    assert _status("max_strain_for_substeps") == "incorrect"
    assert "at the frames only" in capsys.readouterr().out

    def pending(counts):
        raise NotImplementedError()

    check.max_strain_for_substeps(pending)
    assert _status("max_strain_for_substeps") == "pending"


def test_hanging_strand_stretch():
    strain_formula = 15 * M * 9.81 / (K * 0.02)
    assert strain_formula * 100 == pytest.approx(0.04, abs=0.005)
    x0, net = S.hair_chain(**H.STRAND, direction=(0.0, -1.0, 0.0))
    x = H.static_shape(x0, net, pinned=(0,))
    assert np.max(np.abs(net.strain(x))) == pytest.approx(strain_formula, rel=1e-3)
