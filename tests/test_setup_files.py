"""The two-command setup: pins agree everywhere, CI calls the README's test command."""

import re
import subprocess
import sys

import pytest
from notebook_helpers import ROOT


def pins_from_requirements_in() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "requirements.in").read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, version = line.split("==")
            pins[name.lower()] = version
    return pins


def pins_from_environment_yml() -> dict[str, str]:
    # A static read (no conda here): "  - name=version" lines of the dependencies list.
    pins = {}
    for m in re.finditer(r"^\s+-\s+([A-Za-z0-9_.-]+)=([^=\s]+)\s*$",
                         (ROOT / "environment.yml").read_text(), re.M):
        pins[m.group(1).lower()] = m.group(2)
    return pins


def test_environment_yml_matches_pip_pins():
    env = pins_from_environment_yml()
    python = env.pop("python")
    assert python == "3.11"
    assert env == pins_from_requirements_in()


def test_lock_contains_every_pin():
    lock = {}
    for line in (ROOT / "requirements.txt").read_text().splitlines():
        if "==" in line and not line.startswith("#"):
            name, version = line.strip().split("==")
            lock[name.lower().replace("_", "-")] = version
    for name, version in pins_from_requirements_in().items():
        assert lock.get(name) == version, f"{name}: requirements.txt has {lock.get(name)}"
    assert all("==" in line for line in (ROOT / "requirements.txt").read_text().splitlines()
               if line.strip() and not line.startswith("#")), "every lock line must be pinned"


def test_ci_runs_exactly_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text()
    commands = [ln.strip() for ln in ci.splitlines()
                if ln.strip() and not ln.strip().startswith(("#", "set ", "cd "))]
    assert commands == ["make test"]
    readme = (ROOT / "README.md").read_text()
    assert "make test" in readme and "make lab" in readme


@pytest.mark.parametrize("target", ["lab", "test", "student", "grade", "execute", "fuzz",
                                    "test-unit", "test-nbval", "test-rounding", "test-browser"])
def test_makefile_targets_exist(target):
    assert re.search(rf"^{target}:", (ROOT / "Makefile").read_text(), re.M)


def test_lab_never_disables_the_token_and_binds_localhost():
    makefile = (ROOT / "Makefile").read_text()
    assert "--ServerApp.ip=127.0.0.1" in makefile
    assert not re.search(r"token=(''|\"\"|\s)", makefile)


def test_make_test_runs_every_stage_and_says_where_time_went():
    makefile = (ROOT / "Makefile").read_text()
    stages = re.search(r"^TEST_STAGES := (.*)$", makefile, re.M).group(1).split()
    assert stages == ["lint", "test-unit", "test-nbval", "test-rounding", "test-browser"]
    test_rule = makefile.split("\ntest:\n", 1)[1].split("\n\n", 1)[0]
    assert "$(STAGE) run setup" in test_rule and "$(STAGE) summary" in test_rule
    assert "HYPOTHESIS_PROFILE=ci" in makefile and "HYPOTHESIS_PROFILE=fuzz" in makefile


def test_importing_nbformat_builds_no_parser():
    """Every pytest worker, grader and Jupyter server imports nbformat, whose validator
    imports jsonschema's format checkers: none of them may build a grammar at import
    (rfc3987-syntax's lark parser cost 2 s of CPU per process; requirements.in says why
    jsonschema is pinned)."""
    probe = ("import sys, nbformat, nbformat.v4; nbformat.validate(nbformat.v4.new_notebook()); "
             "print(sorted(m for m in ('lark', 'rfc3987_syntax') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120).stdout.strip()
    assert out == "[]"
