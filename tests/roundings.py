"""The second rounding of ``make test``: NumPy's and OpenBLAS's kernels one level down.

NumPy picks, at import, the fastest SIMD kernel ("dispatch target") that the CPU supports
for each loop: on x86-64 with NumPy 2.4 the groups are ``X86_V2`` (the baseline, SSE4.2),
``X86_V3`` (AVX2 and FMA3), ``X86_V4`` (AVX-512), ``AVX512_ICL`` and ``AVX512_SPR``. Kernels
of different widths add in a different order and contract ``a*b + c`` into one FMA or
not, so sums, norms, ``exp``/``sin`` and BLAS products can differ in their last bits from
one machine to the next. A chaotic run (a flock, a cloth in contact) amplifies those bits.

``make test`` runs the numerically sensitive tests (``@pytest.mark.roundoff``) and strict
nbval of the solutions a second time with the dispatch level one below the machine's own,
and OpenBLAS's kernels one generation down, so every machine tests two roundings:

- an X86_V4 (AVX-512) machine drops to X86_V3 (OpenBLAS ``Haswell``);
- an X86_V3 (AVX2) machine drops to the X86_V2 baseline (OpenBLAS ``Nehalem``);
- an X86_V2 machine has nothing below in NumPy; OpenBLAS drops to ``Core2``;
- aarch64: NumPy 2.4's float64 loops are all built for the ``ASIMD`` baseline (its dispatch
  targets above it, ``ASIMDHP`` ``ASIMDDP`` ``ASIMDFHM`` ``SVE``, serve float16 and sorting
  only), so the second pass disables those found and runs OpenBLAS's generic ``ARMV8``
  kernels, whose blocking and summation order differ from the tuned ones.

Run ``python tests/roundings.py`` to see the plan on this machine, or
``python tests/roundings.py run CMD ...`` to run CMD under the second rounding (the
Makefile does). Only the standard library and NumPy are imported.
"""

from __future__ import annotations

import ctypes
import glob
import os
import platform
import subprocess
import sys

#: x86-64: (group the machine has, the level below, NumPy groups to disable to get
#: there, OpenBLAS core for the pass)
X86_LEVELS = [
    ("X86_V4", "X86_V3", "X86_V4 AVX512_ICL AVX512_SPR", "Haswell"),
    ("X86_V3", "X86_V2", "X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "Nehalem"),
]
#: aarch64: NumPy 2.4's dispatch targets above the ASIMD baseline (numpy/_core/meson.build)
ARM_DISPATCH = ["ASIMDHP", "ASIMDDP", "ASIMDFHM", "SVE"]


def cpu_features() -> dict[str, bool]:
    """NumPy's runtime CPU features: name -> found and enabled."""
    from numpy._core._multiarray_umath import __cpu_features__

    return dict(__cpu_features__)


def machine() -> str:
    return platform.machine().lower()


def plan(features: dict[str, bool] | None = None, arch: str | None = None) -> dict:
    """The second rounding for this machine.

    Returns
    -------
    dict
        ``native``: the machine's highest NumPy group; ``lower``: the pass's level;
        ``env``: the variables to set; ``disabled``: NumPy groups turned off (may be empty);
        ``note``: one line for the log.
    """
    features = cpu_features() if features is None else features
    arch = machine() if arch is None else arch
    if arch in ("x86_64", "amd64"):
        for group, below, disable, core in X86_LEVELS:
            if features.get(group):
                return {"native": group, "lower": below, "disabled": disable.split(),
                        "env": {"NPY_DISABLE_CPU_FEATURES": disable,
                                "OPENBLAS_CORETYPE": core},
                        "note": f"NumPy {group} -> {below}, OpenBLAS -> {core}"}
        return {"native": "X86_V2", "lower": "X86_V2", "disabled": [],
                "env": {"OPENBLAS_CORETYPE": "Core2"},
                "note": "NumPy X86_V2 has no level below; OpenBLAS -> Core2 only"}
    if arch in ("aarch64", "arm64"):
        found = [name for name in ARM_DISPATCH if features.get(name)]
        env = {"OPENBLAS_CORETYPE": "ARMV8"}
        if found:
            env["NPY_DISABLE_CPU_FEATURES"] = " ".join(found)
        return {"native": found[-1] if found else "ASIMD", "lower": "ASIMD",
                "disabled": found, "env": env,
                "note": f"NumPy float64 loops stay on ASIMD (disabled: {' '.join(found) or 'none'}),"
                        " OpenBLAS -> ARMV8 (generic kernels)"}
    return {"native": "?", "lower": "?", "disabled": [], "env": {},
            "note": f"no second rounding known for {arch}: the pass repeats the first"}


def openblas_core() -> str | None:
    """The OpenBLAS core NumPy's bundled library runs (``OPENBLAS_CORETYPE`` honoured)."""
    import numpy as np

    libs = glob.glob(os.path.join(os.path.dirname(np.__file__), os.pardir, "numpy.libs",
                                  "libscipy_openblas*"))
    for path in libs:
        lib = ctypes.CDLL(path)
        for name in ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename",
                     "openblas_get_corename"):
            func = getattr(lib, name, None)
            if func is not None:
                func.restype = ctypes.c_char_p
                return func().decode()
    return None


def describe() -> str:
    """One line: the rounding this process gets (its NumPy groups, a float64 loop's
    kernel, OpenBLAS's core)."""
    from numpy.lib.introspect import opt_func_info

    exp = opt_func_info(func_name="^exp$", signature="float64")["exp"]
    current = next(iter(exp.values()))["current"]
    found = [k for k, v in cpu_features().items() if v and (k.startswith("X86_V") or
                                                           k in ARM_DISPATCH)]
    return (f"{machine()}: NumPy groups {' '.join(found) or 'baseline'}; float64 exp runs "
            f"{current}; OpenBLAS {openblas_core() or '?'}")


def main(argv: list[str]) -> int:
    p = plan()
    if argv[:1] == ["run"]:
        env = {**os.environ, **p["env"]}
        shown = subprocess.run([sys.executable, __file__, "--describe"], env=env,
                               capture_output=True, text=True).stdout.strip()
        print(f"second rounding ({p['note']}): {shown}", flush=True)
        os.execvpe(argv[1], argv[1:], env)
    if argv[:1] == ["--describe"]:
        print(describe())
        return 0
    if argv[:1] == ["--env"]:
        for key, value in p["env"].items():
            print(f"{key}={value}")
        return 0
    print(f"first rounding:  {describe()}")
    print(f"second rounding: {p['note']}  ({' '.join(f'{k}={v!r}' for k, v in p['env'].items())})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
