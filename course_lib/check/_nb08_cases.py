"""Case data of notebook 08's check of the hair loop (``nb08.hair_frames``).

:func:`loop_cases` holds the runs the check asks for (three curly strands that fall onto a
head, roots listed last first; a tapered strand with damping beside a head it never
reaches), each with the library's answer (:func:`course_lib.hair.simulate` with
:func:`course_lib.hair.head_collision`). :func:`hair_loop` is the same loop written out
with switches for the usual slips, and :func:`loop_mistakes` the frames those slips give,
keyed by hint (computed only for a wrong answer: each is a whole run). Imports NumPy and
the core's hair and spring modules.
"""

from __future__ import annotations

import numpy as np

from .. import hair, springs
from ..forces import G_EARTH
from .tolerance import escalate


def loop_cases():
    """(what, x0, network, mass, pinned, damping, (center, radius), frames, substeps, fps)."""
    center, radius = np.zeros(3), 0.1
    xs, net, roots = hair.hairstyle(n_strands=3, center=center, radius=radius, k_bend=200.0,
                                    k_twist=100.0)
    yield ("3 curly strands falling onto a head, roots listed last first, 8 frames of 180 "
           "substeps, damping 2e-3 kg/s", xs, net, np.full(len(xs), hair.MASS),
           [int(r) for r in roots[::-1]], 2e-3, (center, radius), 8, 180, 30.0)
    x0, strand = springs.hair_chain(**hair.STRAND, k_bend=300.0, zigzag=0.3)
    yield ("a tapered zigzag strand (0.2 g to 0.05 g), root clamped [1, 0], a head it never "
           "reaches, damping 5e-3 kg/s, 3 frames of 250 substeps at 24 fps", x0, strand,
           np.linspace(2e-4, 5e-5, 16), [1, 0], 5e-3, (np.array([0.0, -1.0, 0.0]), 0.2),
           3, 250, 24.0)


def reference(x0, net, mass, pinned, damping, head, frames, substeps, fps) -> np.ndarray:
    """The library's frames, shape ``(frames + 1, N, 3)``."""
    center, radius = head
    return hair.simulate(x0, net, frames=frames, substeps=substeps, fps=fps, mass=mass,
                         pinned=pinned, damping=damping,
                         post_step=hair.head_collision(center, radius, pinned=pinned)).frames


def hair_loop(x0, forces, mass, pinned, damping, head, frames, substeps, fps, *,
              order="velocity first", contact="slide", pins=None, masses=None,
              gravity=True, damped=True) -> np.ndarray:
    """Symplectic Euler with the head's projection, with switches for the usual slips:
    ``order="position first"`` (forward Euler), ``contact`` one of ``"slide"`` (right),
    ``"none"``, ``"keep velocity"``, ``"stop"``, ``"bounce"``, ``"before drift"``; ``pins``
    and ``masses`` replace the pinned list and the masses; no ``gravity``, no ``damping``."""
    center, radius = head
    x = np.array(x0, dtype=float)
    v = np.zeros_like(x)
    m = np.broadcast_to(np.asarray(mass if masses is None else masses, dtype=float),
                        (len(x),))[:, None]
    free = np.ones((len(x), 1))
    free[list(pinned if pins is None else pins)] = 0.0
    dt = 1.0 / (fps * substeps)
    g = G_EARTH if gravity else np.zeros(3)

    def collide(x, v):
        r = x - center
        dist = np.linalg.norm(r, axis=1, keepdims=True)
        inside = (dist[:, 0] < radius) & (free[:, 0] > 0)
        if contact == "none" or not inside.any():
            return
        n = r / np.where(dist > 0, dist, 1.0)
        x[inside] = (center + radius * n)[inside]
        vn = np.sum(v * n, axis=1, keepdims=True)
        into = inside & (vn[:, 0] < 0)
        if contact in ("slide", "before drift"):
            v[into] -= (vn * n)[into]
        elif contact == "stop":
            v[into] = 0.0
        elif contact == "bounce":
            v[into] -= (2.0 * vn * n)[into]

    out = [x.copy()]
    with np.errstate(all="ignore"):
        for step in range(1, frames * substeps + 1):
            f = forces(x) + m * g - (damping * v if damped else 0.0)
            if order == "position first":
                x += dt * v
                v += dt * free * f / m
            else:
                v += dt * free * f / m
                if contact == "before drift":
                    collide(x, v)
                x += dt * v
            if contact != "before drift":
                collide(x, v)
            if step % substeps == 0:
                out.append(x.copy())
    return np.array(out)


def loop_mistakes(x0, net, mass, pinned, damping, head, frames, substeps, fps) -> dict:
    """The frames each usual slip gives, keyed by hint (a nudge, then a stronger one)."""
    args = (x0, net.forces, mass, pinned, damping, head, frames, substeps, fps)
    out = {
        escalate("this is forward Euler: symplectic Euler moves the particles with the NEW "
                 "velocity", "update v from the forces first, then x with that v"):
            hair_loop(*args, order="position first"),
        escalate("your particles end up inside the head: after each substep, push any "
                 "particle inside it back to the surface", "a particle inside the sphere goes "
                 "to the surface point along the line from the centre"):
            hair_loop(*args, contact="none"),
        escalate("a particle pushed back to the surface keeps the velocity that carried it "
                 "into the head", "remove the inward (normal) part of its velocity"):
            hair_loop(*args, contact="keep velocity"),
        escalate("your particles stop dead on the head: remove only the inward part of the "
                 "velocity, so that hair can slide along the scalp",
                 "subtract (v·n) n when v·n < 0, with n the outward normal"):
            hair_loop(*args, contact="stop"),
        escalate("your hair bounces off the head: the exercise asks for no bounce",
                 "remove the inward normal velocity, do not reverse it"):
            hair_loop(*args, contact="bounce"),
        escalate("the collision belongs after the drift: test the positions the step has "
                 "just moved", "kick, drift, then project"):
            hair_loop(*args, contact="before drift"),
        escalate("you left out the damping -c v", "add it to the force before the kick"):
            hair_loop(*args, damped=False),
        escalate("you left out gravity", "each particle weighs m g, g = (0, -9.81, 0) m/s²"):
            hair_loop(*args, gravity=False),
        escalate("only the first particle in pinned is held: every particle listed stays put",
                 "zero the velocity change of every pinned particle"):
            hair_loop(*args, pins=[pinned[0]]),
        escalate("only particle 0 is held: pinned lists every particle that stays put, and "
                 "here particle 0 is not the only one", "zero the velocity change of every "
                 "particle in pinned"): hair_loop(*args, pins=[0]),
        escalate("each particle has its own mass (this strand is tapered): divide each "
                 "force by its own particle's mass", "mass has shape (N,): use mass[:, None]"):
            hair_loop(*args, masses=float(np.mean(mass))),
    }
    return out
