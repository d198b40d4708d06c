"""Take away the current process's ability to open sockets, with a seccomp filter.

Landlock (:mod:`.landlock`) confines files, TCP bind and connect (ABI 4+) and signals,
but not UDP, raw or Unix-domain sockets: after it, a worker could still send a DNS query
or any UDP datagram, talk to a service's Unix socket (``/var/run/docker.sock``, D-Bus),
or, as root, open raw and packet sockets. :func:`deny_sockets` installs a seccomp BPF
filter (needs only ``PR_SET_NO_NEW_PRIVS``, so it works unprivileged and in containers)
under which, for this process, all its threads and every process it starts:

- ``socket()`` fails with EACCES, for every address family (``socketpair()``, which
  reaches nothing outside the process, still works);
- ``io_uring_setup()`` fails (io_uring can open and connect sockets without ``socket()``);
- every system call of another ABI (32-bit ``int 0x80``, x32) fails with EPERM, so
  ``socketcall()`` cannot go around the filter.

Filters are inherited and cannot be removed. Imports: the standard library (``ctypes``).
"""

from __future__ import annotations

import ctypes
import errno
import platform
import struct

# audit architecture, seccomp(), socket(), io_uring_setup() for each supported machine
_ARCH = {"x86_64": (0xC000003E, 317, 41, 425), "aarch64": (0xC00000B7, 277, 198, 425)}
_X32_BIT = 0x40000000
_PR_SET_NO_NEW_PRIVS = 38
_SET_MODE_FILTER, _FLAG_TSYNC = 1, 1
_LD_ABS_W, _JEQ, _JGE, _RET = 0x20, 0x15, 0x35, 0x06
_ALLOW, _ERRNO = 0x7FFF0000, 0x00050000


def _op(code: int, k: int, jt: int = 0, jf: int = 0) -> bytes:
    return struct.pack("=HBBI", code, jt, jf, k)


def program(machine: str | None = None) -> bytes:
    """The BPF filter for ``machine`` (default: this one), as the kernel reads it."""
    arch, _, sock, uring = _ARCH[machine or platform.machine()]
    deny, refuse = _ERRNO | errno.EPERM, _ERRNO | errno.EACCES
    return b"".join([
        _op(_LD_ABS_W, 4),                      # seccomp_data.arch
        _op(_JEQ, arch, jt=1),                  # this ABI: go on; another: deny
        _op(_RET, deny),
        _op(_LD_ABS_W, 0),                      # seccomp_data.nr
        _op(_JGE, _X32_BIT, jt=0, jf=1),        # x32 system calls: deny
        _op(_RET, deny),
        _op(_JEQ, sock, jt=0, jf=1),
        _op(_RET, refuse),
        _op(_JEQ, uring, jt=0, jf=1),
        _op(_RET, deny),
        _op(_RET, _ALLOW),
    ])


def deny_sockets() -> bool:
    """Install the filter (see the module docstring) on every thread of this process.

    Returns False if this machine or kernel has no seccomp filters (nothing changed);
    raises OSError if seccomp is there but installing fails, so the caller never runs
    less confined than it believes.
    """
    if platform.system() != "Linux" or platform.machine() not in _ARCH:
        return False
    code = program()
    count = len(code) // 8
    filt = ctypes.create_string_buffer(code, len(code))
    prog = ctypes.create_string_buffer(struct.pack("@HP", count, ctypes.addressof(filt)))
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS) failed")
    nr = _ARCH[platform.machine()][1]
    if libc.syscall(nr, ctypes.c_uint(_SET_MODE_FILTER), ctypes.c_uint(_FLAG_TSYNC), prog) != 0:
        err = ctypes.get_errno()
        if err == errno.ENOSYS:  # a kernel built without seccomp
            return False
        raise OSError(err, "seccomp(SECCOMP_SET_MODE_FILTER) failed")
    return True
