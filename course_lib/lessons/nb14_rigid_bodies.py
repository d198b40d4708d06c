"""Notebook 14 (rigid bodies): the scenes and studies behind the notebook.

Holds the spinning box of the flip (:data:`SPIN`, :func:`spin_moments`, :func:`flip`), the
invariant drift of every method (:func:`drift_table`) and the period study
(:func:`period_errors`); contact scenes: a sphere sliding into rolling
(:func:`rolling_sphere`, and written out step by step around any friction impulse,
:func:`slide_to_roll`, which the check of Exercise 5 runs) and boxes dropped on the ground
(:func:`bouncing_box`, :func:`settle_ensemble`); magnets: spherical NdFeB magnets that
snap together (:func:`magnet_scene`, :func:`alignment`) and rock in contact
(:func:`rocking_period`, :func:`single_ball_rocking`); and :func:`showcase_animation`, the
clip of the course project. Built on :mod:`course_lib.rigid`; the drawings are in
:mod:`course_lib.lessons.nb14_drawings`. The core never imports this module.
"""

from __future__ import annotations

import numpy as np

from .. import rigid
from ..rigid import contact, exact, inertia, magnets
from ..rigid import quaternion as quat

G = 9.81
#: A box of 0.3 kg, 20 × 10 × 5 cm, spun at 10 rad/s about its intermediate (y) axis,
#: nudged by 0.1 rad/s about x: it flips over every half period.
SPIN = {"mass": 0.3, "sides": (0.2, 0.1, 0.05), "omega0": (0.1, 10.0, 0.0)}
#: The drift study: step and duration (s).
DRIFT_DT, DRIFT_T = 0.01, 8.0
#: The sphere that slides into rolling: 1 kg, radius 0.1 m, 2 m/s, μ = 0.3, step 1 ms.
ROLL = {"mass": 1.0, "radius": 0.1, "v0": 2.0, "mu": 0.3, "dt": 1e-3}
#: The dropped box: 1 kg, 30 × 20 × 10 cm, from 0.5 m, e = 0.5, μ = 0.5, 240 steps/s.
DROP = {"mass": 1.0, "sides": (0.3, 0.2, 0.1), "height": 0.5, "restitution": 0.5,
        "friction": 0.5, "dt": 1 / 240}
#: NdFeB balls of 5 mm diameter (7500 kg/m³, remanence 1.3 T), a drag rate (1/s) standing
#: in for air, eddy currents and rolling friction, and the step (s).
MAGNET = {"radius": 0.0025, "density": 7500.0, "remanence": 1.3, "drag": 100.0, "dt": 5e-5,
          "restitution": 0.3, "friction": 0.3}


def spin_moments() -> np.ndarray:
    """Principal moments (kg m²) of the spinning box."""
    return inertia.box_moments(SPIN["mass"], SPIN["sides"])


def flip(method: str = "implicit_midpoint", dt: float = DRIFT_DT, t_end: float = DRIFT_T):
    """The spinning box's torque-free run ``(t, omega, q)`` by ``method``."""
    return rigid.free_body(spin_moments(), SPIN["omega0"], dt, round(t_end / dt), method)


def invariants(omega, moments=None) -> tuple[np.ndarray, np.ndarray]:
    """``|L|`` (kg m²/s) and kinetic energy (J) along a run's body angular velocities."""
    moments = spin_moments() if moments is None else moments
    L = omega * moments
    return np.linalg.norm(L, axis=1), 0.5 * np.sum(L * omega, axis=1)


def drift_table(dt: float = DRIFT_DT, t_end: float = DRIFT_T) -> dict:
    """For every method: the run and the relative drifts of ``|L|`` and ``E`` at the end
    (``"L_end"``, ``"E_end"``) and at worst (``"L_max"``, ``"E_max"``)."""
    rows = {}
    for method in rigid.METHODS:
        t, omega, q = flip(method, dt, t_end)
        L, E = invariants(omega)
        dL, dE = L / L[0] - 1.0, E / E[0] - 1.0
        rows[method] = {"t": t, "omega": omega, "q": q, "dL": dL, "dE": dE, "L_end": dL[-1],
                        "E_end": dE[-1], "L_max": np.abs(dL).max(), "E_max": np.abs(dE).max()}
    return rows


def period_errors(steps_per_period=(25, 50, 100, 200),
                  methods=("implicit_midpoint", "splitting", "rk4"), periods: float = 2.2) -> dict:
    """Relative error of the measured flip period against ``4K(m)/λ`` for each method and
    number of steps per period; ``method + "_order"`` holds the slope of the last two
    halvings, ``method + "_energy"`` the largest ``|E/E₀ − 1|`` of each run."""
    T = exact.period(spin_moments(), SPIN["omega0"])
    out = {"T": T, "steps": np.array(steps_per_period)}
    for method in methods:
        errors, energy = [], []
        for n in steps_per_period:
            t, omega, _ = flip(method, T / n, periods * T)
            errors.append(exact.measured_period(t, omega, 1) / T - 1.0)
            E = invariants(omega)[1]
            energy.append(float(np.abs(E / E[0] - 1.0).max()))
        errors = np.array(errors)
        out[method], out[method + "_energy"] = errors, np.array(energy)
        out[method + "_order"] = float(np.log2(abs(errors[-2] / errors[-1])))
    return out


def gravity(b):
    """Weight ``m g`` (down the y axis) and no torque, for :func:`course_lib.rigid.step`."""
    F = np.zeros_like(b.x)
    F[:, 1] = -G * b.mass
    return F, np.zeros_like(b.x)


def rolling_sphere(**changes) -> dict:
    """A sphere launched sliding (no spin) along the ground: its speed ``v`` and rim speed
    ``ωR`` against time, the step at which the slip stops, and the exact answer (sliding
    until ``t = 2v₀/(7μg)``, then rolling at ``5/7 v₀``)."""
    p = {**ROLL, **changes}
    R, v0, mu, dt = p["radius"], p["v0"], p["mu"], p["dt"]
    t_roll = 2.0 * v0 / (7.0 * mu * G)
    b = rigid.make("sphere", p["mass"], R, [[0.0, R, 0.0]], v=[v0, 0.0, 0.0])
    ground = contact.Ground(restitution=0.0, friction=mu)
    run = rigid.simulate(b, dt, int(np.ceil(2.0 * t_roll / dt)), gravity, ground)
    v = run.P[:, 0, 0] / p["mass"]
    rim = -(run.L[:, 0, 2] / b.moments[0, 2]) * R          # ω_z < 0 rolls towards +x
    rolling = np.flatnonzero(v - rim <= 1e-9 * v0)
    return {"t": run.t, "v": v, "rim": rim, "height": run.x[:, 0, 1] - R, "t_roll": t_roll,
            "v_roll": 5.0 / 7.0 * v0, "k_roll": int(rolling[0]), "dt": dt, "v0": v0, "mu": mu}


def slide_to_roll(friction=contact.friction_impulse, **changes) -> dict:
    """:func:`rolling_sphere` written out for one ball: each step gravity, the normal impulse
    that stops the approach (``e = 0``), then ``friction(mass, inv_inertia, r, normal, v,
    omega, j_n, mu) -> J_t`` (N s, (3,)) at the lowest point. Returns the centre speed
    ``v``, the rim speed ``ωR`` per step, and ``k_roll``, the first step without slip."""
    p = {**ROLL, **changes}
    m, R, v0, mu, dt = p["mass"], p["radius"], p["v0"], p["mu"], p["dt"]
    inv_I = np.eye(3) / (0.4 * m * R * R)
    r, n = np.array([0.0, -R, 0.0]), np.array([0.0, 1.0, 0.0])
    v, w = np.array([v0, 0.0, 0.0]), np.zeros(3)
    steps = int(np.ceil(4.0 * v0 / (7.0 * mu * G * dt)))
    speed, rim = np.empty(steps + 1), np.empty(steps + 1)
    speed[0], rim[0] = v0, 0.0
    with np.errstate(all="ignore"):                   # a wrong answer's NaN is judged, not warned
        for k in range(1, steps + 1):
            v[1] -= G * dt
            j_n = max(-m * float(v @ n), 0.0)
            v = v + j_n / m * n
            J = np.asarray(friction(m, inv_I.copy(), r.copy(), n.copy(), v.copy(), w.copy(), j_n, mu),
                           dtype=float)
            v, w = v + J / m, w + inv_I @ np.cross(r, J)
            speed[k], rim[k] = v[0], -w[2] * R
    rolling = np.flatnonzero(speed - rim <= 1e-9 * v0)
    return {"t": dt * np.arange(steps + 1), "v": speed, "rim": rim, "v0": v0, "mu": mu,
            "k_roll": int(rolling[0]) if len(rolling) else -1, "v_roll": 5.0 / 7.0 * v0,
            "t_roll": 2.0 * v0 / (7.0 * mu * G)}


def drop_box(seed: int, t_end: float = 2.5, every: int = 4, **changes):
    """A box dropped from rest from ``DROP["height"]`` (its centre) at a random orientation
    and spin (seeded), onto the ground ``y = 0``. Returns the :class:`~course_lib.rigid.Run`."""
    p = {**DROP, **changes}
    rng = np.random.default_rng(seed)
    b = rigid.make("box", p["mass"], p["sides"], [[0.0, p["height"], 0.0]],
                   q=quat.normalize(rng.normal(size=4)), v=[0.3, 0.0, 0.0],
                   omega=2.0 * rng.normal(size=3))
    ground = contact.Ground(restitution=p["restitution"], friction=p["friction"])
    return rigid.simulate(b, p["dt"], round(t_end / p["dt"]), gravity, ground, every=every)


def bouncing_box(seed: int = 2026, **kwargs):
    """The notebook's dropped box (:func:`drop_box` with its seed)."""
    return drop_box(seed, **kwargs)


def energies(run, b=None) -> dict:
    """Kinetic, potential (``m g y``) and total energy (J) of a one-box run, per frame."""
    b = run.bodies if b is None else b
    L_body = quat.rotate(quat.conjugate(run.q[:, 0]), run.L[:, 0])
    kinetic = 0.5 * np.sum(run.P[:, 0] ** 2, axis=1) / b.mass[0] + rigid.free.energy(L_body, b.moments[0])
    potential = b.mass[0] * G * run.x[:, 0, 1]
    return {"kinetic": kinetic, "potential": potential, "total": kinetic + potential}


def at_rest_on_a_face(run, sides=DROP["sides"]) -> tuple[bool, float, float]:
    """Whether a box run ends at rest lying on a face: the kinetic energy left (J), and the
    gap between its centre's height and half the side that stands upright (m)."""
    R = quat.to_matrix(run.q[-1, 0])
    upright = int(np.argmax(np.abs(R[1])))                # body axis closest to vertical
    gap = float(run.x[-1, 0, 1] - 0.5 * sides[upright])
    kinetic = float(energies(run)["kinetic"][-1])
    return kinetic < 1e-6 and abs(gap) < contact.ALLOWED * min(sides), kinetic, gap


def settle_ensemble(seeds=range(16), t_end: float = 2.5) -> list[tuple[bool, float, float]]:
    """:func:`at_rest_on_a_face` for boxes dropped with each seed."""
    return [at_rest_on_a_face(drop_box(s, t_end=t_end, every=round(t_end / DROP["dt"])))
            for s in seeds]


def magnet_bodies(x, seed: int) -> rigid.Bodies:
    """Spherical magnets (:data:`MAGNET`) at ``x`` (N, 3), at rest, turned at random (seeded)."""
    R, p = MAGNET["radius"], MAGNET
    mass = p["density"] * 4.0 / 3.0 * np.pi * R**3
    moment = magnets.sphere_moment(R, p["remanence"])
    q = quat.normalize(np.random.default_rng(seed).normal(size=(len(x), 4)))
    return rigid.make("sphere", mass, R, x, q=q, dipole=[0.0, 0.0, moment])


def magnet_forces(b):
    """Dipole forces and torques between the magnets, with a linear drag on their motion
    and spin (rate :data:`MAGNET` ``["drag"]``, 1/s)."""
    F, tau, _ = magnets.interactions(b.x, b.magnetic_moment)
    rate = MAGNET["drag"]
    return F - rate * b.P, tau - rate * b.L


def magnet_scene(n: int = 2, seed: int = 14, t_end: float = 0.06, every: int = 20, spread=0.015):
    """``n`` magnets released at rest: two on the x axis ``spread`` (m) apart, or more on a
    jittered circle of diameter ``spread``; they turn, attract and snap together."""
    if n == 2:
        x = np.array([[-0.5 * spread, 0.0, 0.0], [0.5 * spread, 0.0, 0.0]])
    else:
        rng = np.random.default_rng(seed + 1)
        a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False) + rng.uniform(-0.2, 0.2, n)
        x = 0.5 * spread * np.stack((np.cos(a), np.sin(a), rng.uniform(-0.05, 0.05, n)), axis=1)
    b = magnet_bodies(x, seed)
    pairs = contact.SpherePairs(restitution=MAGNET["restitution"], friction=MAGNET["friction"])
    dt = MAGNET["dt"]
    return rigid.simulate(b, dt, round(t_end / dt), magnet_forces, pairs, every=every)


def alignment(run) -> dict:
    """For a two-magnet run, per frame: the centre distance over the contact distance, the
    angle (degrees) of each dipole to the line of centres, and ``m₁·m₂ / |m|²``."""
    b = run.bodies
    m = quat.rotate(run.q, b.dipole[None])
    d = run.x[:, 1] - run.x[:, 0]
    dist = np.linalg.norm(d, axis=1)
    line = d / dist[:, None]
    size = np.linalg.norm(b.dipole[0])
    angles = np.degrees(np.arccos(np.clip(np.abs(np.sum(m * line[:, None], axis=2)) / size, 0, 1)))
    return {"distance": dist / (2.0 * MAGNET["radius"]), "angles": angles,
            "parallel": np.sum(m[:, 0] * m[:, 1], axis=1) / size**2}


def rocking_period(run, after: float = 0.002) -> float:
    """Period (s) at which two touching magnets rock about head to tail, from ``after`` (s)
    past their first contact: the part of the first dipole's direction across the line of
    centres, along the direction it swings most (its principal axis), changes sign twice per
    period (median spacing of the sign changes)."""
    align = alignment(run)
    start = int(np.argmax(align["distance"] < 1.001)) + int(np.ceil(after / (run.t[1] - run.t[0])))
    m = quat.rotate(run.q[start:, 0], run.bodies.dipole[0])
    d = run.x[start:, 1] - run.x[start:, 0]
    line = d / np.linalg.norm(d, axis=1)[:, None]
    across = m - np.sum(m * line, axis=1)[:, None] * line
    across -= across.mean(axis=0)
    swing = np.linalg.eigh(across.T @ across)[1][:, -1]
    times = exact.crossings(run.t[start:], across @ swing)
    if len(times) < 3:
        raise ValueError("the run has too few swings after contact: run it longer or sample it more finely")
    return 2.0 * float(np.median(np.diff(times)))


def single_ball_rocking() -> float:
    """Period (s) of one ball turning in the field of a fixed neighbour touching it, head to
    tail: stiffness ``m B`` with ``B = μ₀ m / (2π (2R)³)``, inertia ``2/5 M R²``."""
    R, p = MAGNET["radius"], MAGNET
    m = magnets.sphere_moment(R, p["remanence"])
    B = magnets.MU0 * m / (2.0 * np.pi * (2.0 * R) ** 3)
    inertia_ball = 0.4 * p["density"] * 4.0 / 3.0 * np.pi * R**3 * R**2
    return 2.0 * np.pi * float(np.sqrt(inertia_ball / (m * B)))


def showcase_animation(t_end: float = 0.1, every: int = 10):
    """The clip of this notebook: six magnets snapping into a cluster, in slow motion
    (``t_end`` = 0.1 s of physics over 6.7 s, a frame every ``every`` steps of 50 µs:
    201 frames at 30 fps, 16:9). A smaller ``t_end`` makes a short test clip."""
    from .nb14_drawings import animate_magnets

    run = magnet_scene(n=6, seed=3, t_end=t_end, every=every, spread=0.024)
    return animate_magnets(run, MAGNET["radius"], figsize=(8.0, 4.5), fps=30.0,
                           title="six NdFeB magnets snapping together, 1/67 real speed")
