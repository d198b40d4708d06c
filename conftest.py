"""Run every test (unit and notebook) without touching the user's home directory.

Jupyter, IPython and matplotlib read and write config, runtime and cache files; we point
them at a fresh temporary folder before any kernel starts, so tests see no personal
settings and leave nothing behind.
"""

import os
import tempfile

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
