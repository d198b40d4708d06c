"""The benchmarks still run (their speed is judged by `make bench`, not here)."""

import importlib
import pkgutil

import pytest
from notebook_helpers import ROOT

MODULES = [m.name for m in pkgutil.iter_modules([str(ROOT / "benchmarks")]) if m.name.startswith("bench_")]


@pytest.mark.parametrize("name", MODULES)
def test_benchmark_module_runs(name, monkeypatch):
    main = importlib.import_module("benchmarks.__main__")
    # One timing run is enough to prove the code path works.
    monkeypatch.setattr(main, "median_time", lambda func, repeat=1, number=1: (func(), 1e-3)[1])
    module = importlib.import_module(f"benchmarks.{name}")
    monkeypatch.setattr(module, "median_time", main.median_time, raising=False)
    results = module.run()
    assert results and all(r.seconds > 0 and r.name for r in results)
