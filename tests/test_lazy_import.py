"""``import course_lib`` loads the integrators and leaves the other core modules to their
first use (``cl.sph``): every sandboxed grading run and every kernel starts a fresh Python,
and the eager import of every model (SciPy's optimizers among them) cost about 0.3 s of CPU in each."""

import subprocess
import sys

import pytest

import course_lib as cl


def _loaded_after(code: str) -> set[str]:
    out = subprocess.run([sys.executable, "-c", code + "\nimport sys\nprint(' '.join(sys.modules))"],
                         capture_output=True, text=True, check=True).stdout
    return set(out.split())


def test_import_leaves_the_heavy_modules_for_later():
    loaded = _loaded_after("import course_lib")
    assert "course_lib.integrators" in loaded
    assert not {"scipy.optimize", "course_lib.sph", "course_lib.rigid", "course_lib.largestep",
                "course_lib.cloth", "course_lib.statics"} & loaded


def test_every_public_name_resolves_and_a_submodule_loads_on_first_use():
    loaded = _loaded_after("import course_lib as cl\nassert cl.sph.KERNELS\nfrom course_lib import rigid")
    assert {"course_lib.sph", "course_lib.rigid"} <= loaded
    for name in cl.__all__:
        assert getattr(cl, name) is not None, name
    assert set(cl.__all__) <= set(dir(cl))
    with pytest.raises(AttributeError, match="no_such_module"):
        cl.__getattr__("no_such_module")
