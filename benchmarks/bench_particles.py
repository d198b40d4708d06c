"""Particle systems (notebook 09): one frame with 10,000 live particles (target 5 ms).

A frame is the fountain's emit (Reeves count, disc shape, cone of directions), one
symplectic Euler step under gravity, the ground bounce and the compaction of the expired,
measured at the steady state where emission balances expiry.
"""

from __future__ import annotations

import numpy as np

from benchmarks.__main__ import Result, median_time
from course_lib.lessons import nb09_particle_systems as nb09
from course_lib.particles import ParticleSystem

TARGET = 0.005  # s per frame, issue 9
N_LIVE, DT, LIFETIME = 10_000, 1.0 / 60.0, 2.0


def run() -> list[Result]:
    emitter = nb09.fountain(count=N_LIVE / (LIFETIME / DT - 0.5), lifetime=LIFETIME)
    rng = np.random.default_rng(2026)
    ps = ParticleSystem(3, 2 * N_LIVE)
    update = nb09.gravity_bounce()
    clock = [0.0]

    def frame() -> None:
        emitter.emit(ps, clock[0], rng)
        update(ps, clock[0], DT)
        ps.expire()
        clock[0] += DT

    for _ in range(int(LIFETIME / DT) + 30):       # reach the steady state first
        frame()
    return [Result(f"particle frame: emit + step + bounce + compact, ~{len(ps)} live",
                   median_time(frame, repeat=60), TARGET)]
