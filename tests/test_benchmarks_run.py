"""The benchmarks still run, at tiny sizes (their speed is judged by `make bench`, not here).

Each ``benchmarks/bench_*.py`` module runs with ``quick=True`` and must return table rows;
the runner's table and machine line must render. No timing is asserted.
"""

import importlib
import pkgutil

import pytest
from notebook_helpers import ROOT

MODULES = [m.name for m in pkgutil.iter_modules([str(ROOT / "benchmarks")]) if m.name.startswith("bench_")]


def test_every_row_of_the_issue_has_a_benchmark_module():
    assert {"bench_core", "bench_integrate", "bench_implicit", "bench_widgets",
            "bench_notebooks"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_benchmark_module_runs(name, monkeypatch):
    from benchmarks.timing import Row

    main = importlib.import_module("benchmarks.__main__")
    module = importlib.import_module(f"benchmarks.{name}")
    # Modules in the older form (``run()`` with ``median_time``): one timing run each.
    monkeypatch.setattr(module, "median_time", lambda func, repeat=1, number=1: (func(), 1e-3)[1],
                        raising=False)
    rows = main.run_module(name, quick=True)
    assert rows and all(isinstance(r, Row) and r.case and r.target for r in rows)
    assert all(r.course_lib is None or r.course_lib > 0 for r in rows)


def test_table_and_machine_render(tmp_path):
    main = importlib.import_module("benchmarks.__main__")
    from benchmarks.timing import Row

    text = main.table([Row("a case", 1.5e-3, "≤ 3× numba", True, 0.2, 5e-4, "3.0× numba"),
                       Row("another", None, "p ≤ 1.3", False, note="p = 1.4")])
    assert "| a case | 1.5 ms | 200 ms | 500 µs | 3.0× numba | ≤ 3× numba | pass |" in text
    assert "**FAIL**" in text
    assert "cores" in main.machine() and "NumPy" in main.machine()


def test_equality_check_refuses_to_time_different_answers():
    import numpy as np

    from benchmarks.timing import check_equal

    check_equal({"a": np.ones(3), "b": np.ones(3) * (1 + 1e-12)}, "a")
    with pytest.raises(AssertionError, match="not timed"):
        check_equal({"a": np.ones(3), "b": np.ones(3) * (1 + 1e-9)}, "a")
