"""Exit-order workaround for PythonFMU 0.7.0's binary on Linux (issue 18).

The abort ("corrupted double-linked list", exit 134) some processes hit after a clean run is a
use-after-free in PythonFMU's own binary at process exit, not in this package's Python code.
Upstream source of release 0.7.0: NTNU-IHB/PythonFMU f301adc (the 0.7.0 version bump),
pythonfmu/pythonfmu-export/src/pythonfmu/PySlaveInstance.cpp. The file is unchanged at src/ in
6e6f489. Line numbers:

- :667  ``std::shared_ptr<PyState> pyState{}`` is a namespace-scope global. Its C++ static
  destructor is registered with ``__cxa_atexit`` when the binary is loaded.
- :676  ``createInstance`` (fmi2Instantiate) fills it when empty: ``std::make_shared<PyState>()``
  allocates one 128-byte block (control block plus PyState). :681 copies it into a local
  ``fmu_data`` only, so no instance holds a reference.
- :693-696 ``finalizePythonInterpreter()`` does ``pyState = nullptr``; :722-725 call it from
  ``__attribute__((destructor)) onLibraryUnload`` (the binary's ELF destructor).

The binary has STB_GNU_UNIQUE symbols, so glibc marks it NODELETE. FMPy's freeInstance
dlcloses it, but it stays mapped until the process exits. ``exit()`` first runs the
``__cxa_atexit`` handlers, including the static destructor of ``pyState``. That destructor
frees the 128-byte block and leaves both pointers of the shared_ptr in place. ``_dl_fini``
then runs ``onLibraryUnload``, and ``pyState = nullptr`` releases the stale control block again:
a ``lock xadd`` on its use count, 8 bytes into the freed chunk. Valgrind reports this as
"Invalid read of size 4 at finalizePythonInterpreter ... 8 bytes inside a block of size 128
free'd by __run_exit_handlers", on every run. If the chunk sits in a glibc bin with its own
header, those bytes are its ``bk`` link, and the next unlink aborts with "corrupted
double-linked list". The heap layout at exit decides that, so the abort is rare and
machine-dependent (issue 18 saw 3 of about 330 runs; 0 of 2300 runs on the machine where the
cause was found), while valgrind reports the invalid access on every run.

With the project's loader (``fmu_src/native/fmu_loader.c``) PythonFMU's binary is
``binaries/linux64/<id>_pythonfmu.so`` beside it; every ``*.so`` there is tried, and only the
one that exports ``finalizePythonInterpreter`` is registered.

This module avoids the path from our side. For the loaded binary of this FMU, it registers
that binary's exported ``finalizePythonInterpreter`` as an exit handler with ``__cxa_atexit``.
The registration happens at instantiation, after the binary's static constructors, and exit
handlers run last-registered first. So ``pyState`` is released while it is still intact: the
PyState, whose thread has already finished in a Python host, is destroyed cleanly and the
shared_ptr is left empty. The static destructor and ``onLibraryUnload`` then find it empty and
do nothing. This is the order a real dlclose would give (fini_array: onLibraryUnload first).
The binary is pinned with an extra dlopen reference so the registered pointer stays valid.

Nothing here raises: a failure only leaves the process as it was without the workaround.
Standard library only.
"""

from __future__ import annotations

import ctypes
import os
import sys
from pathlib import Path

# binaries whose finalizePythonInterpreter is registered as an exit handler (by path)
registered: dict[str, int] = {}   # path -> address of finalizePythonInterpreter
_seen: set[str] = set()           # resources directories already handled
_pinned: list[ctypes.CDLL] = []   # our dlopen references: never dlclosed


def register_exit_order(resources: object) -> None:
    """Make the loaded PythonFMU binary next to ``resources`` release its ``pyState`` before
    its static destructor runs at exit (see the module docstring). Idempotent and cheap
    after the first call for a given resources directory; never raises."""
    if not sys.platform.startswith("linux") or not resources:
        return
    key = str(resources)
    if key in _seen:
        return
    _seen.add(key)
    try:
        binaries = Path(key).parent / "binaries" / "linux64"
        for so in sorted(binaries.glob("*.so")):
            _register(str(so))
    except Exception:  # nothing may escape into PythonFMU's C wrapper
        pass


def _register(path: str) -> None:
    if path in registered:
        return
    try:
        # RTLD_NOLOAD: only a binary this process has already loaded (the builder, which
        # instantiates the class at build time, loads none, so nothing happens there).
        lib = ctypes.CDLL(path, mode=os.RTLD_NOLOAD | os.RTLD_NOW)
        func = lib.finalizePythonInterpreter
    except (OSError, AttributeError):
        return
    libc = ctypes.CDLL(None)
    cxa_atexit = libc.__cxa_atexit
    cxa_atexit.argtypes = (ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)
    cxa_atexit.restype = ctypes.c_int
    address = ctypes.cast(func, ctypes.c_void_p).value
    # dso_handle NULL: run by exit() only. The handler ignores the extra argument.
    if address and cxa_atexit(address, None, None) == 0:
        _pinned.append(lib)
        registered[path] = address
