"""Every number quoted in solutions/11_cloth.ipynb, and its exercise checks."""

import numpy as np
import pytest

from course_lib import cloth as C
from course_lib import springs
from course_lib.check import RESULTS
from course_lib.check import nb11 as check
from course_lib.lessons import nb11_cloth as nb11


@pytest.fixture(scope="module")
def hang():
    return nb11.hanging()


def test_spring_counts():
    for n, counts in [(6, (60, 50, 48)), (12, (264, 242, 240))]:
        _, net = springs.cloth_grid(n, n, 0.1, 100.0, 10.0, 2.0)
        got = tuple(net.select(k).n_springs for k in ("struct", "shear", "bend"))
        assert got == counts == (2 * n * (n - 1), 2 * (n - 1) ** 2, 2 * n * (n - 2))
    assert sum((264, 242, 240)) == 746


def test_the_cloth(hang):
    assert hang.n == 144 and f"{hang.mass[0] * 1e3:.3f}" == "0.694"
    assert hang.network.n_springs == 746 and hang.network.select("struct").rest[0] == pytest.approx(0.05)
    assert hang.pinned.tolist() == [0, 11]


def test_explicit_limit_predicted_and_measured(hang):
    omega, limit = nb11.frequency_and_limit(hang)
    assert f"{omega:.1f}" == "1366.4" and f"{limit * 1e3:.4f}" == "1.4637"
    measured = C.explicit_dt_max(hang)
    assert f"{measured * 1e3:.4f}" == "1.4633" and f"{measured / limit:.5f}" == "0.99976"
    assert 1 - measured / limit < 0.0003                                  # "to 0.03 %"
    assert int(np.ceil(1 / (30 * limit))) == 23
    assert 1 / (30 * 23) < limit < 1 / (30 * 22)


def test_explicit_runs(hang):
    ok = C.simulate(hang, "symplectic_euler", frames=60, substeps=24)
    bad = C.simulate(hang, "symplectic_euler", frames=60, substeps=20)
    assert ok.stable and f"{ok.dt * 1e3:.3f}" == "1.389"
    assert bad.message == "unstable at frame 2, t = 0.0667 s (|y| > 100)" and f"{bad.dt * 1e3:.3f}" == "1.667"
    omega2, limit2 = nb11.frequency_and_limit(hang, ok.x[60])
    assert f"{omega2:.1f}" == "1354.7" and f"{limit2 * 1e3:.4f}" == "1.4764"
    _, limit = nb11.frequency_and_limit(hang)
    assert limit2 / limit - 1 == pytest.approx(0.009, abs=0.0005)           # "0.9 % larger"
    # still swinging after 2 s: the undamped explicit cloth keeps its kinetic energy
    assert C.energies(hang, ok.x[60], ok.v[60])["kinetic"] > 0.1


def test_jacobian_check(hang):
    err, scale, asym_x, asym_v = nb11.jacobian_check(hang)
    assert f"{err:.1e}" == "1.6e-06" and f"{scale:.1f}" == "849.0"
    assert f"{err / scale:.1e}" == "1.8e-09" and asym_x == 0.0 and asym_v == 0.0
    assert hang.x0.size == 432


def test_large_implicit_steps(hang):
    _, limit = nb11.frequency_and_limit(hang)
    assert f"{(1 / 30) / limit:.1f}" == "22.8"
    run = C.simulate(hang, "baraff_witkin", frames=60)
    assert run.stable and run.iterations[:3].tolist() == [1, 46, 56]
    assert f"{run.iterations.mean():.1f}" == "99.6" and run.iterations.max() == 148
    bad = C.simulate(hang, "symplectic_euler", frames=60, substeps=1)
    assert bad.message == "unstable at frame 3, t = 0.1 s (|y| > 100)"
    # "all but stopped swinging after about a second": kinetic energy 5 % of the released
    kinetic = C.energies(hang, run.x, run.v)["kinetic"] / 0.27
    assert kinetic[30] == pytest.approx(0.05, abs=0.005) and kinetic[45] < 0.005


def test_work_per_frame():
    rows = nb11.work_per_frame([300.0, 3000.0, 30000.0], frames=10)
    assert [r["substeps"] for r in rows] == [24, 76, 240]
    assert [f"{r['iterations']:.1f}" for r in rows] == ["31.1", "51.7", "98.0"]
    growth = np.log(rows[-1]["iterations"] / rows[0]["iterations"]) / np.log(100.0)
    assert growth == pytest.approx(0.25, abs=0.01)                          # "about k^(1/4)"
    assert rows[0]["iterations"] > rows[0]["substeps"] and rows[1]["iterations"] < rows[1]["substeps"]
    assert rows[2]["iterations"] < 0.5 * rows[2]["substeps"]                  # "less than half"


def test_numerical_damping_numbers(hang):
    assert np.allclose(nb11.damping_ratios(k=100.0, m=1.0, h=0.1), 0.5, rtol=1e-12)
    per_step = 1 / (1 + 0.15**2)
    assert 1 - per_step == pytest.approx(0.02, abs=0.003)                   # "about 2 % per step"
    assert per_step**30 == pytest.approx(0.5, abs=0.02)                      # "half in a second"
    runs = {"se": C.simulate(hang, "symplectic_euler", frames=60, substeps=24),
            "bw30": C.simulate(hang, "baraff_witkin", frames=60, rtol=1e-3),
            "bw120": C.simulate(hang, "baraff_witkin", frames=60, substeps=4, rtol=1e-3)}
    total = {k: C.energies(hang, r.x, r.v)["total"] for k, r in runs.items()}
    released = -total["bw30"][-1]
    assert f"{released:.2f}" == "0.27"
    quoted = {"se": ("-0.003", "+0.011", "0.018"), "bw30": ("-0.949", "-1.000", "1.000"),
              "bw120": ("-0.514", "-0.775", "0.775")}
    for k, (one, two, worst) in quoted.items():
        e = (total[k] - total[k][0]) / released
        assert (f"{e[30]:+.3f}", f"{e[60]:+.3f}", f"{np.abs(e).max():.3f}") == (one, two, worst)
    assert np.abs((total["se"] - total["se"][0]) / released).max() < 0.02    # "within 2 %"


def test_drape_respects_the_sphere_and_the_ground():
    c, run = nb11.drape()
    assert run.stable and c.n == 400
    distance = np.linalg.norm(run.x[1:], axis=2)
    assert distance.min() >= 1.03 * nb11.SPHERE_RADIUS * (1 - 1e-12)
    assert run.x[1:, :, 1].min() >= -nb11.SPHERE_RADIUS - 1e-12
    assert f"{run.iterations.mean():.1f}" == "28.1"
    speed = np.linalg.norm(run.v[-1], axis=1)
    assert speed.max() < 0.05                                                 # come to rest


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb11.{name}"]["status"]


def _block(xi, xj, k, rest, geometric=True, sign=-1.0):
    d = xi - xj
    length = np.linalg.norm(d)
    uu = np.outer(d, d) / length**2
    side = (1 - rest / length) * (np.eye(3) - uu) if geometric else 0.0
    return sign * k * (uu + side)


def test_check_spring_jacobian(capsys):
    check.spring_jacobian(_block)
    assert _status("spring_jacobian") == "correct"
    capsys.readouterr()

    def l_over_ell(xi, xj, k, rest):
        d = xi - xj
        length = np.linalg.norm(d)
        uu = np.outer(d, d) / length**2
        return -k * (uu + rest / length * (np.eye(3) - uu))

    def unnormalised(xi, xj, k, rest):
        d = xi - xj
        length = np.linalg.norm(d)
        uu = np.outer(d, d) / length**2
        return -k * (np.outer(d, d) + (1 - rest / length) * (np.eye(3) - uu))

    for func, hint in [(lambda *a: _block(*a, sign=1.0), "sign"),
                       (lambda *a: _block(*a, geometric=False), "only the stiffness along"),
                       (l_over_ell, "not L/ℓ"), (unnormalised, "unit vector")]:
        check.spring_jacobian(func)
        assert _status("spring_jacobian") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(xi, xj, k, rest):
        raise NotImplementedError()

    check.spring_jacobian(pending)
    assert _status("spring_jacobian") == "pending"


def _limit(K, mass, layout=np.repeat, root=True, two=2.0):
    m3 = layout(mass, 3)
    lam = np.linalg.eigvalsh(K / np.sqrt(np.outer(m3, m3))).max()
    return two / (np.sqrt(lam) if root else lam)


def test_check_explicit_limit(capsys):
    check.explicit_limit(_limit)
    assert _status("explicit_limit") == "correct"
    capsys.readouterr()
    for func, hint in [(lambda K, m: 2 / np.sqrt(np.linalg.eigvalsh(K).max()), "include the masses"),
                       (lambda K, m: 2 / np.sqrt(np.linalg.eigvalsh(K).max() / m.mean()), "one mass"),
                       (lambda K, m: _limit(K, m, root=False), "square root"),
                       (lambda K, m: _limit(K, m, two=1.0), "not 1/ω_max"),
                       (lambda K, m: _limit(K, m, layout=np.tile), "np.repeat")]:
        check.explicit_limit(func)
        assert _status("explicit_limit") == "incorrect"
        assert hint in capsys.readouterr().out

    def pending(K, mass):
        raise NotImplementedError()

    check.explicit_limit(pending)
    assert _status("explicit_limit") == "pending"
