"""Case data of notebook 06's checks of ``nbody_force`` and ``bounce``.

:func:`located_mistakes` holds what the usual slips make of a located bounce step;
:func:`nbody_cases` holds the bodies the N-body check tries (2D and 3D, no softening, two
bodies at one point) and :func:`nbody_mistakes` the forces its usual slips give;
:func:`ground_states` holds the particles the contact-response check tries (above and below
the ground, moving in and out, straight down, 2D and 3D) and :func:`bounce_mistakes` what
the usual slips make of them, keyed by hint. Imports NumPy and the core's state helpers.
"""

from __future__ import annotations

import numpy as np

from ..systems import stack_state
from .tolerance import escalate


def ground_states():
    rng = np.random.default_rng(606)
    x = rng.normal(size=(12, 2))
    v = 2.0 * rng.normal(size=(12, 2))
    x[:3, 1] = np.abs(x[:3, 1]) + 0.1           # above the ground
    x[3:, 1] = -np.abs(x[3:, 1]) * 0.1 - 0.01    # below it
    v[3:6, 1] = np.abs(v[3:6, 1]) + 0.1          # below but already moving up
    v[6:9, 1] = -np.abs(v[6:9, 1]) - 0.1         # below and moving down
    v[6:9, 0] = 0.05 * np.sign(v[6:9, 0])        # slow sideways: friction stops them
    v[9:, 1] = -np.abs(v[9:, 1]) - 0.1           # below, down, fast sideways
    v[11, 0] = 0.0                               # straight down: no sideways speed
    yield "12 particles in 2D, e = 0.6, μ = 0.4", stack_state(x, v), 0.6, 0.4
    x3, v3 = rng.normal(size=(8, 3)), rng.normal(size=(8, 3))
    x3[:, 1] = -0.01 - 0.1 * np.abs(x3[:, 1])
    v3[:, 1] = -np.abs(v3[:, 1])
    v3[0, [0, 2]] = 0.0                          # straight down
    yield "8 particles in 3D, all hitting, e = 0.3, μ = 0.2", stack_state(x3, v3), 0.3, 0.2
    yield "same, e = 1 and μ = 0 (a perfect bounce)", stack_state(x3, v3), 1.0, 0.0
    # many particles: whole-array code runs a dozen lines, a loop over them hundreds
    xs, vs = rng.normal(size=(300, 3)), 2.0 * rng.normal(size=(300, 3))
    yield "a spray of 300 particles in 3D, e = 0.5, μ = 0.3", stack_state(xs, vs), 0.5, 0.3


def bounce_mistakes(y, e, mu, expected) -> dict:
    x, v = y[0], y[1]
    normal = np.eye(x.shape[-1])[1]
    below = x[:, 1] < 0
    vn = v[:, 1]
    vt = v * (1 - normal)
    speed_t = np.linalg.norm(vt, axis=1, keepdims=True)
    approaching = below & (vn < 0)

    def respond(scale, hit, normal_v):
        out = v.copy()
        out[hit] = (scale * vt + normal_v[:, None] * normal)[hit]
        return np.stack((np.where(below[:, None], x * (1 - normal), x), out))

    safe = np.where(speed_t > 0, speed_t, 1.0)       # no sideways speed: nothing to scale
    with np.errstate(divide="ignore", invalid="ignore"):
        drop = mu * (1 + e) * np.abs(vn)[:, None] / safe
        clamp = np.maximum(0.0, 1 - drop)
        return {
            "friction can stop the sliding but never reverse it: clamp the tangential "
            "scale at 0": respond(1 - drop, approaching, -e * vn),
            "only a particle moving INTO the ground bounces; one already moving up "
            "keeps its velocity": respond(clamp, below, -e * vn),
            "move penetrating particles back to the surface (y = 0)": np.stack((x, expected[1])),
            "friction takes μ times the change of the normal speed, (1 + e)|v_n|, not μ|v_n|":
                respond(np.maximum(0.0, 1 - mu * np.abs(vn)[:, None] / safe), approaching,
                        -e * vn),
            "restitution scales the normal velocity only; friction handles the tangential "
            "part": respond(e * clamp, approaching, -e * vn),
            "Coulomb friction removes speed, μ (1 + e) |v_n|, from the tangential velocity; "
            "scaling it by (1 - μ) is a different law":
                respond(np.full_like(drop, 1 - mu), approaching, -e * vn),
            "sign: after the bounce the normal velocity points up, v_n' = -e v_n":
                respond(clamp, approaching, e * vn),
            escalate("your bounce has no friction: the tangential velocity should lose speed "
                     "at the impact", "Coulomb friction takes μ (1 + e) |v_n| from its length"):
                respond(np.ones_like(drop), approaching, -e * vn),
            escalate("friction acts on the tangential velocity as one vector: shorten it, "
                     "keeping its direction, not each component on its own",
                     "in 3D the tangential velocity has two components; scale both by the "
                     "same factor"): respond_per_component(x, v, below, approaching, e, mu, normal),
        }


def respond_per_component(x, v, below, hit, e, mu, normal):
    """The response with friction taken off each tangential component separately (a 2D
    habit): every component loses μ (1 + e) |v_n|, clamped at zero on its own."""
    vn = v[:, 1]
    loss = mu * (1 + e) * np.abs(vn)[:, None]
    vt = np.sign(v) * np.maximum(0.0, np.abs(v) - loss) * (1 - normal)
    out = v.copy()
    out[hit] = (vt + (-e * vn)[:, None] * normal)[hit]
    return np.stack((np.where(below[:, None], x * (1 - normal), x), out))


def nbody_cases():
    rng = np.random.default_rng(66)
    yield "5 bodies in 2D, G = 1, softening 0.1", rng.normal(size=(5, 2)), rng.uniform(0.5, 2, 5), 1.0, 0.1
    yield ("7 bodies in 3D, G = 6.674e-11, no softening", rng.normal(size=(7, 3)) * 1e3,
           rng.uniform(1e10, 1e12, 7), 6.674e-11, 0.0)
    x = rng.normal(size=(4, 2))
    x[3] = x[0]                                      # two bodies at the same point
    yield "4 bodies in 2D, two of them at one point, softening 0.5", x, np.ones(4), 2.0, 0.5
    # many bodies: whole-array code runs a dozen lines, a loop over them more than 60
    yield ("a cluster of 64 bodies in 3D, G = 1, softening 0.05", rng.normal(size=(64, 3)),
           rng.uniform(0.1, 1.0, 64), 1.0, 0.05)


def nbody_mistakes(x, m, G, eps, expected) -> dict:
    r = x[:, None, :] - x[None, :, :]
    d2 = np.sum(r * r, axis=-1)
    np.fill_diagonal(d2, np.inf)

    def pairs(den, weight=m[:, None] * m[None, :]):
        return -G * np.einsum("ij,ijk->ik", weight / den, r)

    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            escalate("every force points the wrong way: a sign error (gravity pulls body i "
                     "TOWARDS j, along x_j - x_i), or a sum of the pair matrix over the wrong "
                     "axis, which flips every force the same way",
                     "with r[i, j] = x_i - x_j the force on i sums over j, the second index "
                     "(axis=1), and carries a minus sign"): -expected,
            "that is the acceleration; the force is m_i times it": expected / m[:, None],
            "each pair's force is G m_i m_j ...: you left out m_j":
                pairs((d2 + eps**2) ** 1.5, m[:, None] * np.ones_like(d2)),
            "soften with the square: (|r|² + ε²)^{3/2}, not (|r|² + ε)^{3/2}":
                pairs((d2 + eps) ** 1.5),
            "soften inside: (|r|² + ε²)^{3/2}, not (|r| + ε)³": pairs((np.sqrt(d2) + eps) ** 3),
            "soften inside: (|r|² + ε²)^{3/2}, not |r|³ + ε³": pairs(d2**1.5 + eps**3),
            "r_ij/|r|³ is the inverse-square law; dividing r_ij by |r|² gives 1/r":
                pairs(d2 + eps**2),
            "you left out the softening ε": pairs(d2**1.5),
            "each body has its own mass: you gave every body the same one":
                pairs((d2 + eps**2) ** 1.5, np.full_like(d2, m.mean() ** 2)),
        }


def located_mistakes(h, v, dt, g, e) -> dict:
    """What the usual slips make of one step, keyed by hint (a nudge, then a stronger one)."""
    free_h, free_v = h + v * dt - 0.5 * g * dt**2, v - g * dt
    hit = free_h < 0.0
    disc = np.sqrt(v * v + 2 * g * h)
    s = np.where(hit, (v + disc) / g, dt)
    rest = dt - s

    def after(s, v_up, flight=True):
        r = dt - s
        if flight:
            return np.where(hit, v_up * r - 0.5 * g * r**2, free_h), np.where(hit, v_up - g * r, free_v)
        return np.where(hit, 0.0, free_h), np.where(hit, v_up, free_v)

    with np.errstate(divide="ignore", invalid="ignore"):
        s_lin = np.where(hit, np.minimum(h / np.abs(v), dt), dt)
        s_chord = np.where(hit, dt * h / (h - free_h), dt)     # interpolated start to end
        return {
            escalate("your impact time interpolates linearly between the start of the step and "
                     "the end of the free flight: the ball accelerates, so the path is a parabola "
                     "and the chord crosses the ground at the wrong time", "the impact is the "
                     "positive root s of h + v s - g s²/2 = 0, the step's own quadratic"):
                after(s_chord, -e * (v - g * s_chord)),
            escalate("you bounced at the end of the step, where the ball is already below the "
                     "ground: locate the impact inside the step",
                     "find the time s of the impact within the step, bounce there, and fly "
                     "the rest of the step"): (np.where(hit, 0.0, free_h),
                                               np.where(hit, -e * free_v, free_v)),
            escalate("the ball accelerates during the step: the time of impact is a root of "
                     "the step's own quadratic, not a straight line's", "solve h + v s - g s²/2 "
                     "= 0 for s and take the positive root"): after(s_lin, -e * (v - g * s_lin)),
            escalate("at the impact the ball has the velocity it has then, not the one the step "
                     "started with", "gravity has been speeding it up for s seconds"):
                after(s, -e * v),
            escalate("the ball stopped at the impact: it must fly the rest of the step",
                     "after the bounce it has dt - s left, under gravity"):
                after(s, -e * (v - g * s), flight=False),
            escalate("after the bounce gravity still acts for the rest of the step",
                     "the remaining flight is a parabola too"):
                (np.where(hit, -e * (v - g * s) * rest, free_h),
                 np.where(hit, -e * (v - g * s), free_v)),
            escalate("the rebound must point up: restitution reverses the velocity",
                     "the velocity after the impact is -e times the velocity at the impact"):
                after(s, e * (v - g * s)),
            escalate("a ball on the ground moving up has just bounced: it hits again only if it "
                     "comes down within the step", "decide from where the free flight ends, "
                     "not from where the step starts"):
                (np.where(h == 0.0, (-e * (v - g * 2 * v / g)) * (dt - 2 * v / g)
                          - 0.5 * g * (dt - 2 * v / g) ** 2, after(s, -e * (v - g * s))[0]),
                 np.where(h == 0.0, -e * (v - 2 * v) - g * (dt - 2 * v / g),
                          after(s, -e * (v - g * s))[1])),
            escalate("wrong root: of the two roots of h + v s - g s²/2 = 0 the impact is the "
                     "one inside the step, the positive one", "the other root is negative, "
                     "before the step began"): after(np.where(hit, (v - disc) / g, dt),
                                                     -e * (v - g * np.where(hit, (v - disc) / g, dt))),
        }
