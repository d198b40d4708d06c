"""The private runtime of a grading run, which every sandboxed worker imports from.

:class:`Runtime` is prepared once per grading run (per Dask worker on a cluster), in a
private temporary folder outside the kit: a copy of the installed ``course_lib`` (the only
one a worker can import), its bytecode, a warmed matplotlib cache, the scrubbed environment
and the Landlock rules, and the fork server (:mod:`.forkserver`) that starts the workers
(or, where there is none, a new ``python -I -S`` per worker). :mod:`.sandbox` runs the
submissions in it. Imports: the standard library.
"""

from __future__ import annotations

import atexit
import compileall
import os
import shutil
import site
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

import course_lib

from . import forkserver, landlock


class Runtime:
    """The private, per-run folder every worker imports course_lib from."""

    def __init__(self, root: Path | None = None):
        self.root = Path(root or tempfile.mkdtemp(prefix="course-grade-"))
        self.lib = self.root / "lib"
        self.work = self.root / "work"
        self.mpl = self.root / "matplotlib"
        for d in (self.lib, self.work, self.mpl):
            d.mkdir(parents=True, exist_ok=True)
        os.chmod(self.root, 0o700)
        source = Path(course_lib.__file__).parent
        shutil.copytree(source, self.lib / "course_lib", dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns(".ipynb_checkpoints", "*.ipynb"))
        compileall.compile_dir(self.lib, quiet=1, workers=1)  # workers cannot write bytecode
        self.worker = self.lib / "course_lib" / "instructor" / "worker.py"
        paths = sysconfig.get_paths()
        self.site = [p for p in dict.fromkeys([paths["purelib"], paths["platlib"], *site.getsitepackages()])
                     if os.path.isdir(p)]
        self.sys_path = [str(self.lib), *self.site]
        self.read = [str(self.lib), str(self.mpl), paths["stdlib"], paths["platstdlib"], *self.site,
                     sys.base_prefix, "/usr/lib", "/usr/lib64", "/usr/share", "/lib", "/lib64",
                     "/etc", "/dev/null", "/dev/urandom", "/dev/zero"]
        self.landlock = landlock.abi_version()
        #: The fork server (:mod:`.forkserver`) that starts the workers, or None: each is
        #: then started with ``python -I -S`` (not Linux, or the server failed).
        self.forks: forkserver.ForkServer | None = None
        if forkserver.SUPPORTED:
            self.forks = forkserver.ForkServer(self.lib / "course_lib" / "instructor" / "forkserver.py",
                                               self.sys_path, self.env(self.root), self.root / "forks.log")
            # A Dask worker's runtime is never cleaned up (Dask deletes its folder): the
            # server is still ended and waited for at exit, so that its CPU time (and its
            # workers') counts in this process's children, as a worker's did before.
            atexit.register(self.close_forks)
        else:
            self._warm()

    def _warm(self) -> None:
        code = ("import sys; sys.path.extend(sys.argv[1:]); import matplotlib; "
                "matplotlib.use('Agg'); import matplotlib.pyplot")
        subprocess.run([sys.executable, "-I", "-S", "-c", code, *self.sys_path],
                       env=self.env(self.root), capture_output=True, timeout=300, check=False)

    def start(self, workdir: Path, module: str, channel_fd: int, log) -> tuple:
        """Start a worker in ``workdir`` (forked by the server, or a new ``python -I -S``);
        ``(process, its stdin)``: the process has ``pid`` (its group too) and ``wait()``."""
        if self.forks is not None:
            read, write = os.pipe()
            try:
                proc = self.forks.spawn(str(workdir), self.env(workdir), module, read, channel_fd,
                                        log.fileno())
                return proc, os.fdopen(write, "wb")
            except OSError as exc:                   # the server is gone: start them as before
                os.close(write)
                log.write(f"(fork server: {exc}; workers start with python -I -S)\n".encode())
                self.close_forks()
            finally:
                os.close(read)
        proc = subprocess.Popen([sys.executable, "-I", "-S", str(self.worker), str(channel_fd)],
                                stdin=subprocess.PIPE, stdout=log, stderr=log, cwd=workdir,
                                env=self.env(workdir), pass_fds=(channel_fd,), start_new_session=True)
        return proc, proc.stdin

    def env(self, home: Path) -> dict[str, str]:
        return {"PATH": "/usr/bin:/bin", "HOME": str(home), "TMPDIR": str(home),
                "LANG": "C.UTF-8", "MPLBACKEND": "Agg", "MPLCONFIGDIR": str(self.mpl),
                "PYTHONHASHSEED": "0", "PYTHONIOENCODING": "utf-8", "PYTHONDONTWRITEBYTECODE": "1",
                "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

    def ready(self, timeout: float = 120.0) -> None:
        """Wait until the fork server has imported the libraries (it starts in the
        background; the first worker would wait for it otherwise)."""
        if self.forks is not None:
            try:
                self.forks.wait_ready(timeout)
            except OSError:
                self.close_forks()              # workers then start with python -I -S

    def close_forks(self) -> None:
        """End the fork server (workers then start with ``python -I -S``)."""
        if self.forks is not None:
            self.forks.close()
            self.forks = None
            atexit.unregister(self.close_forks)     # nothing left to end at exit

    def cleanup(self) -> None:
        self.close_forks()
        remove_tree(self.root)


def remove_tree(path: Path) -> None:
    """Remove ``path``, also where a submission took the permissions away from its files."""
    def retry(func, p, _exc):
        try:
            os.chmod(os.path.dirname(p), 0o700)
            os.chmod(p, 0o700)
            func(p)
        except OSError:
            pass
    shutil.rmtree(path, onexc=retry) if sys.version_info >= (3, 12) else shutil.rmtree(path, onerror=retry)
