"""The student release (``make release``): everything a student needs, no solution text."""

import json
import shutil
import subprocess
import sys

import nbformat
import pytest
from notebook_helpers import ROOT

from course_lib.instructor.notebooks import make_student_notebook
from course_lib.instructor.release import MARKER, build_release, secret_lines


@pytest.fixture(scope="module")
def release(tmp_path_factory):
    return build_release(tmp_path_factory.mktemp("dist") / "student", ROOT)


def text_files(folder):
    for path in sorted(folder.rglob("*")):
        if path.is_file():
            try:
                yield path, path.read_text("utf-8")
            except UnicodeDecodeError:
                continue


def test_release_has_notebooks_library_setup_and_readme(release):
    names = sorted(p.name for p in (ROOT / "solutions").glob("*.ipynb"))
    assert sorted(p.name for p in (release / "notebooks").glob("*.ipynb")) == names
    for name in names:
        ours = nbformat.read(release / "notebooks" / name, as_version=4)
        fresh = make_student_notebook(nbformat.read(ROOT / "solutions" / name, as_version=4))
        assert [c.source for c in ours.cells] == [c.source for c in fresh.cells]
    for name in ("pyproject.toml", "requirements.txt", "environment.yml", "LICENSE", "Makefile",
                 "README.md", "course_lib/__init__.py", "course_lib/check/__init__.py"):
        assert (release / name).is_file(), name
    readme = (release / "README.md").read_text()
    assert "make lab" in readme and "uses the reference" in readme and "Handing in" in readme
    assert "notebooks/01_" in (release / "Makefile").read_text()
    for leftover in ("solutions", "tests", "benchmarks", "docs", ".ci"):
        assert not (release / leftover).exists(), leftover
    assert not list(release.rglob("*.pyc")) and not list((release / "course_lib").rglob("*.ipynb"))


def leaks(folder, secrets) -> list[str]:
    """Solution lines found in ``folder``'s text files (JSON-escaped in notebooks too)."""
    library = {}
    for path in (ROOT / "course_lib").rglob("*.py"):
        lines = path.read_text("utf-8").splitlines()
        library[path.relative_to(ROOT).as_posix()] = {ln.strip() for ln in lines}
    found = []
    for path, text in text_files(folder):
        rel = path.relative_to(folder).as_posix()
        lines = {ln.strip() for ln in text.splitlines()}
        if path.suffix == ".ipynb":  # every line of every cell and output, unescaped
            nb = json.loads(text)
            lines |= {ln.strip() for c in nb.get("cells", []) for part in [c.get("source", "")]
                      + [o.get("text", "") for o in c.get("outputs", [])]
                      for ln in ("".join(part) if isinstance(part, list) else part).splitlines()}
        for line in secrets.keys() & lines:
            # The library's own reference code may coincide with a solution line: that is the
            # library students use, not text copied from solutions/.
            if line not in library.get(rel, set()):
                found.append(f"{rel}: {line!r} (from {secrets[line]})")
        if "### BEGIN SOLUTION" in text and not rel.startswith("course_lib/"):
            found.append(f"{rel}: a solution marker")
    return found


def test_no_solution_text_anywhere_in_the_release(release, tmp_path):
    secrets = secret_lines(ROOT / "solutions")
    assert len(secrets) >= 30  # the scan has something to look for
    assert leaks(release, secrets) == []
    shutil.copytree(release, tmp_path / "leaky")  # the scan does fail on a leak
    shutil.copy(ROOT / "solutions" / "02_forward_euler.ipynb", tmp_path / "leaky" / "notebooks" / "x.ipynb")
    (tmp_path / "leaky" / "hint.txt").write_text("    return r0 * ((1 - k * dt) ** 2 + dt**2) ** (n / 2)\n")
    found = leaks(tmp_path / "leaky", secrets)
    assert any(f.startswith("hint.txt") for f in found) and any(f.startswith("notebooks/x") for f in found)


def test_release_refuses_to_overwrite_what_it_did_not_build(tmp_path):
    (tmp_path / "mine.txt").write_text("keep")
    with pytest.raises(ValueError, match="not an earlier release"):
        build_release(tmp_path, ROOT)
    with pytest.raises(ValueError, match="would contain the kit"):
        build_release(ROOT, ROOT)
    out = build_release(tmp_path / "rel", ROOT)
    assert (out / MARKER).exists()
    assert build_release(out, ROOT) == out  # an earlier release is replaced


def test_release_command_line(tmp_path):
    out = tmp_path / "student"
    done = subprocess.run([sys.executable, "-m", "course_lib.instructor", "release", str(out)],
                          cwd=ROOT, capture_output=True, text=True, check=True)
    assert str(out) in done.stdout and (out / "README.md").exists()
