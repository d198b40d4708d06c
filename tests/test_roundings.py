"""The second rounding of ``make test`` really changes NumPy's kernels, and its plan is right
for each kind of machine; the stage timer counts pytest's "no tests" as a pass."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys

import pytest
import roundings
from notebook_helpers import ROOT

PROBE = """
import json, numpy as np
from numpy._core._multiarray_umath import __cpu_features__
from numpy.lib.introspect import opt_func_info
import roundings
loops = {f"{name} {sig}": target["current"]
         for name, sigs in opt_func_info(signature="float64").items()
         for sig, target in sigs.items()}
print(json.dumps({"features": dict(__cpu_features__), "loops": loops,
                  "openblas": roundings.openblas_core()}))
"""


def probe(env: dict[str, str]) -> dict:
    """What a fresh interpreter with ``env`` added dispatches to."""
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                          env={**os.environ, **env, "PYTHONPATH": str(ROOT / "tests")},
                          check=True)
    return json.loads(done.stdout)


def test_the_second_rounding_runs_other_kernels_than_the_first():
    plan = roundings.plan()
    here, there = probe({}), probe(plan["env"])
    for group in plan["disabled"]:
        assert not there["features"].get(group), f"{group} still dispatched"
    if plan["disabled"] and any(here["features"].get(g) for g in plan["disabled"]):
        changed = {k: (v, there["loops"][k]) for k, v in here["loops"].items()
                   if there["loops"].get(k) != v}
        assert changed, "no float64 loop runs another kernel under the second rounding"
        ran = {target.split("(")[0] for target in there["loops"].values()}
        assert not ran & set(plan["disabled"]), ran
    if here["openblas"] is not None and "OPENBLAS_CORETYPE" in plan["env"]:
        assert there["openblas"].lower() == plan["env"]["OPENBLAS_CORETYPE"].lower()
    if not plan["disabled"] and here["openblas"] is None:
        pytest.skip(f"no second rounding on this machine: {plan['note']}")


@pytest.mark.parametrize(("arch", "found", "disabled", "lower", "core"), [
    ("x86_64", ["X86_V2", "X86_V3", "X86_V4", "AVX512_ICL"], "X86_V4 AVX512_ICL AVX512_SPR",
     "X86_V3", "Haswell"),
    ("x86_64", ["X86_V2", "X86_V3"], "X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "X86_V2", "Nehalem"),
    ("x86_64", ["X86_V2"], "", "X86_V2", "Core2"),
    ("aarch64", ["NEON", "ASIMD", "ASIMDHP", "ASIMDDP"], "ASIMDHP ASIMDDP", "ASIMD", "ARMV8"),
    ("aarch64", ["NEON", "ASIMD"], "", "ASIMD", "ARMV8"),
])
def test_plan_drops_one_level(arch, found, disabled, lower, core):
    plan = roundings.plan(dict.fromkeys(found, True), arch)
    assert plan["env"].get("NPY_DISABLE_CPU_FEATURES", "") == disabled
    assert plan["lower"] == lower and plan["env"]["OPENBLAS_CORETYPE"] == core
    assert plan["note"]


def test_an_unknown_machine_is_told_not_guessed():
    plan = roundings.plan({}, "riscv64")
    assert plan["env"] == {} and "riscv64" in plan["note"]


def test_the_make_rule_prints_both_roundings():
    out = subprocess.run([sys.executable, str(ROOT / "tests" / "roundings.py")],
                         capture_output=True, text=True, check=True).stdout
    assert out.startswith("first rounding:") and "second rounding:" in out


@pytest.fixture
def stage(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("stage", ROOT / "tools" / "stage.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "RECORD", tmp_path / "stages.tsv")
    return module


def test_stages_are_timed_and_pytest_exit_5_passes(stage):
    assert stage.run("empty", [sys.executable, "-c", "raise SystemExit(5)"]) == 0
    assert stage.run("broken", [sys.executable, "-c", "raise SystemExit(3)"]) == 3
    # busy for 0.3 s of CPU on any machine (a fixed sum took 0.04 s on a fast one: "0.0s")
    busy_loop = "import time\nwhile time.process_time() < 0.3: pass"
    assert stage.run("busy", [sys.executable, "-c", busy_loop]) == 0
    table = stage.summary()
    assert "empty" in table and "FAILED (exit 3)" in table and "sum" in table
    busy = next(line for line in table.splitlines() if "busy" in line).split()
    assert float(busy[2].rstrip("s")) >= 0.3   # the child's CPU time is counted


def test_stages_run_alongside_each_other_show_less_elapsed_than_their_sum(stage):
    """make test runs stages alongside others (the browser beside the unit tests): the summary's
    elapsed line is the time since reset, not the sum of the stages' walls."""
    import threading
    import time

    assert stage.main(["reset"]) == 0
    nap = [sys.executable, "-c", "import time; time.sleep(1.0)"]
    runs = [threading.Thread(target=stage.run, args=(f"nap{k}", nap)) for k in range(2)]
    for r in runs:
        r.start()
    for r in runs:
        r.join()
    time.sleep(0.05)
    lines = {line.split()[0]: line.split() for line in stage.summary().splitlines()[2:]}
    assert float(lines["sum"][1].rstrip("s")) >= 2.0
    assert 1.0 <= float(lines["elapsed"][1].rstrip("s")) < 1.9



def test_make_test_fails_naming_what_it_left_in_the_checkout(stage, tmp_path):
    """The summary compares git status with the one noted at reset: a file a run left
    (new, changed or deleted, and not ignored) is named; ignored ones and files that were
    there before are not; outside a git checkout the check is skipped."""
    repo = tmp_path / "repo"
    repo.mkdir()
    git = ["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run([*git, "init", "-q"], check=True)
    (repo / ".gitignore").write_text("build/\n")
    (repo / "kept.txt").write_text("one\n")
    (repo / "mine.txt").write_text("a developer's own untracked file\n")
    subprocess.run([*git, "add", ".gitignore", "kept.txt"], check=True)
    subprocess.run([*git, "commit", "-qm", "init"], check=True)
    before = stage.checkout_status(repo)
    assert before == ["?? mine.txt"]
    (repo / "build").mkdir()
    (repo / "build" / "log.txt").write_text("ignored\n")
    (repo / ".venv.lock").write_text("")
    (repo / "kept.txt").write_text("two\n")
    assert stage.left_behind(before, stage.checkout_status(repo)) == [" M kept.txt", "?? .venv.lock"]
    (repo / "kept.txt").unlink()
    assert " D kept.txt" in stage.left_behind(before, stage.checkout_status(repo))
    assert stage.checkout_status(tmp_path / "not-a-repo") is None
    assert stage.left_behind(None, ["?? x"]) == []
