"""Run every test (unit and notebook) without touching the user's home directory.

Jupyter, IPython and matplotlib read and write config, runtime and cache files; we point
them at a fresh temporary folder before any kernel starts, so tests see no personal
settings and leave nothing behind. The nbval plugin of ``make test`` (``--nbval-rerun``,
``roundoff`` on nbval's cells) lives in ``tests/nbval_rerun.py`` and is loaded here, so
that it applies to ``solutions/`` and ``notebooks/`` too, as does ``tests/schedule.py`` (the
costliest files first, for pytest-xdist).
"""

import os
import sys
import tempfile
from pathlib import Path

_home = tempfile.mkdtemp(prefix="course-kit-test-")
for var, sub in {
    "JUPYTER_CONFIG_DIR": "jupyter-config",
    "JUPYTER_RUNTIME_DIR": "jupyter-runtime",
    "IPYTHONDIR": "ipython",
    "MPLCONFIGDIR": "matplotlib",
}.items():
    path = os.path.join(_home, sub)
    os.makedirs(path, exist_ok=True)
    os.environ[var] = path
os.environ["JUPYTER_PLATFORM_DIRS"] = "1"
os.environ.pop("MPLBACKEND", None)  # kernels must use the inline backend
import matplotlib  # noqa: E402

matplotlib.use("Agg")  # unit tests draw off-screen; notebook kernels keep the inline backend

sys.path.insert(0, str(Path(__file__).resolve().parent / "tests"))
from nbval_rerun import (  # noqa: E402, F401  (hooks of the nbval plugin)
    pytest_addoption,
    pytest_collection_modifyitems,
    pytest_configure,
    pytest_runtest_logreport,
    pytest_runtest_setup,
)

pytest_plugins = ["schedule"]
