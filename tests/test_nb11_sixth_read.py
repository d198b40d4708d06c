"""Notebook 11, sixth read: the Ex 1 prompt says which Jacobian the check wants (the exact
one, the geometric term kept with its sign on compressed springs), and Section 6 gives the
drop height the scene has (0.15 m above the sphere's top, not "from 0.4 m")."""

import re

import numpy as np
import pytest
from notebook_helpers import markdown

import course_lib as cl
from course_lib.check import evaluate
from course_lib.check import nb11 as check
from course_lib.lessons import nb11_cloth as lesson

NAME = "11_cloth.ipynb"


def flat(text: str) -> str:
    return re.sub(r"\s+", " ", text)


@pytest.mark.parametrize("folder", ["solutions", "notebooks"])
def test_ex1_prompt_asks_for_the_exact_jacobian_on_compressed_springs(folder):
    text = flat(markdown(NAME, folder))
    prompt = text[text.index("### Exercise 1"):text.index("### Exercise 2")]
    assert "Keep the geometric term with its sign for compressed springs too" in prompt
    assert "`cl.springs.jacobian_x` builds" in prompt
    assert "option of the solver, not part of the Jacobian" in prompt
    assert "Choi & Ko 2002" in prompt
    # and the section it contrasts with still says the solver drops it by default
    assert "which `cl.baraff_witkin.BaraffWitkin` does by default" in text


def clamped(xi, xj, k, rest):
    """What a student following cell 10 might write: Choi-Ko's clamp of the sideways term."""
    d = xi - xj
    length = np.linalg.norm(d)
    u = d / length
    uu = np.outer(u, u)
    return -k * (uu + max(0.0, 1 - rest / length) * (np.eye(3) - uu))


def test_the_prompt_is_what_the_check_enforces():
    """The clamp fails the compressed case: the prompt must say so up front."""
    verdict = evaluate(check.spring_jacobian, clamped)
    assert verdict["status"] == "incorrect"
    assert all("compressed" in c for c in verdict["failed_cases"]), verdict["failed_cases"]
    # and jacobian_x is the exact block on a compressed spring (the geometric term negative)
    net = cl.springs.SpringNetwork([0], [1], [3.0], [120.0], [0.0], 2)
    x = np.array([[0.4, -0.3, 1.1], [0.0, 0.0, 0.0]])
    block = cl.springs.jacobian_x(net, x).toarray()[:3, :3]
    assert np.allclose(block, check_exact(x[0], x[1], 120.0, 3.0), rtol=1e-12, atol=1e-12)
    assert not np.allclose(block, clamped(x[0], x[1], 120.0, 3.0))


def check_exact(xi, xj, k, rest):
    d = xi - xj
    length = np.linalg.norm(d)
    u = d / length
    uu = np.outer(u, u)
    return -k * (uu + (1 - rest / length) * (np.eye(3) - uu))


@pytest.mark.parametrize("folder", ["solutions", "notebooks"])
def test_drop_height_is_quoted_from_the_sphere_top(folder):
    text = flat(markdown(NAME, folder))
    assert "dropped from 0.4 m" not in text
    assert "dropped flat from 0.15 m above the top of a sphere of radius 0.25 m" in text
    assert "(at $y = 0.4$ m, the sphere's centre at 0 and the ground at $-0.25$ m)" in text


def test_drop_height_numbers_match_the_scene():
    c = cl.cloth.sheet(n=20, size=0.9, total_mass=0.15, k_struct=300.0, c=0.01,
                       height=lesson.DRAPE_HEIGHT, pinned="none")
    assert np.all(c.x0[:, 1] == 0.4)                                       # y = 0.4 m, flat
    assert lesson.SPHERE_RADIUS == 0.25
    assert lesson.DRAPE_HEIGHT - lesson.SPHERE_RADIUS == pytest.approx(0.15, abs=1e-15)
    assert lesson.DRAPE_HEIGHT + lesson.SPHERE_RADIUS == pytest.approx(0.65, abs=1e-15)
    # the sphere is centred at the origin and the ground is y = -R (the scene's contacts)
    import inspect
    source = inspect.getsource(lesson.drape)
    assert "collisions.sphere((0.0, 0.0, 0.0)" in source
    assert "collisions.plane((0.0, 1.0, 0.0), -SPHERE_RADIUS" in source
