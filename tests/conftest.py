"""Settings shared by every unit test: matplotlib off-screen (settings and figures reset
around each test), and Hypothesis profiles.

Hypothesis profiles, chosen with the environment variable ``HYPOTHESIS_PROFILE``:

- ``ci`` (what ``make test`` sets): derandomized, so a run is reproducible on any machine
  and CI cannot go red on an example it never saw before; no example database; no deadline
  (a loaded machine would otherwise fail slow examples); ``too_slow`` not a failure.
- ``fuzz`` (``make fuzz``): the random search, each test's ``max_examples`` times
  ``FUZZ_FACTOR`` (default 10), failures saved in ``.hypothesis/`` and replayed first.
- ``dev`` (the default, a plain ``pytest``): Hypothesis's random search with no deadline.

A failure found by ``make fuzz`` is fixed, then kept as an ``@example`` or a hand case.
"""

import os

import matplotlib
import pytest
from hypothesis import HealthCheck, settings

matplotlib.use("Agg")  # unit tests draw off-screen; notebook kernels keep the inline backend

settings.register_profile("ci", derandomize=True, database=None, deadline=None,
                          print_blob=True, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("fuzz", deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "dev")
settings.load_profile(PROFILE)
FUZZ_FACTOR = int(os.environ.get("FUZZ_FACTOR", "10"))


@pytest.fixture(autouse=True)
def _own_matplotlib_state():
    """Each test starts from the same matplotlib settings and leaves no figure open: test
    files share a process under pytest-xdist, and a style one lesson sets (dpi, sizes) or a
    figure another test left open must not change the next test's pictures or counts."""
    import matplotlib.pyplot as plt

    with matplotlib.rc_context():
        yield
    plt.close("all")


def pytest_report_header(config):
    return f"hypothesis profile: {PROFILE}"


def pytest_collection_modifyitems(config, items):
    """Under ``fuzz``, scale every property test's own ``max_examples`` (set with
    ``@settings`` at import, so a profile alone cannot raise it)."""
    if PROFILE != "fuzz":
        return
    for func in {getattr(getattr(item, "obj", None), "__func__", getattr(item, "obj", None))
                 for item in items}:
        own = getattr(func, "_hypothesis_internal_use_settings", None)
        if own is not None and not getattr(func, "_fuzz_scaled", False):
            func._hypothesis_internal_use_settings = settings(
                own, max_examples=own.max_examples * FUZZ_FACTOR)
            func._fuzz_scaled = True
