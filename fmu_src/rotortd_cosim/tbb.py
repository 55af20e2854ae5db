"""libtbb.so.12 for ecospy and its native ``ecos`` CLI, found without root.

ecospy's ``libecosc.so`` and its ``ecos`` binary link against ``libtbb.so.12``, which
neither ecospy nor the system provides by default. The ``tbb`` package on the Python
package index (in the project's ``[test]`` extra) installs it into the environment's
``lib/``, which no loader searches. :func:`load_libtbb` finds it there and loads it
process-wide (``RTLD_GLOBAL``), so that importing ecospy afterwards resolves it; its
directory goes on ``LD_LIBRARY_PATH`` for the ``ecos`` CLI (``rotortd_cosim.engines``).

    python -m rotortd_cosim.tbb     # prints that directory (empty if the system has it)
"""

from __future__ import annotations

import ctypes
import functools
import sys
from importlib import metadata
from pathlib import Path

LIBTBB = "libtbb.so.12"


def _candidates() -> list[Path]:
    """Where an environment's libtbb.so.12 can be: <prefix>/lib/, then the file list of
    the installed ``tbb`` distribution (covers ``--user`` and other install schemes)."""
    found = [Path(p) / "lib" / LIBTBB for p in dict.fromkeys((sys.prefix, sys.exec_prefix))]
    try:
        files = metadata.distribution("tbb").files or []
    except metadata.PackageNotFoundError:
        files = []
    found += [Path(f.locate()).resolve() for f in files if f.name == LIBTBB]
    return list(dict.fromkeys(found))


@functools.cache
def load_libtbb() -> Path | None:
    """Load libtbb.so.12 into this process with ``RTLD_GLOBAL``, from the environment
    first, else from the system loader's paths (e.g. Debian's ``libtbb12``). Call it
    before importing ecospy. Returns the file loaded from the environment (its directory
    is what the ``ecos`` CLI needs on ``LD_LIBRARY_PATH``), or None when the system
    loader found it or the platform is not Linux (nothing to do there).

    Raises OSError naming what to install when it is nowhere.
    """
    if not sys.platform.startswith("linux"):
        return None
    tried = _candidates()
    for path in tried:
        if path.is_file():
            ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
            return path
    try:
        ctypes.CDLL(LIBTBB, mode=ctypes.RTLD_GLOBAL)
    except OSError:
        pass
    else:
        return None
    looked = ", ".join(str(p) for p in tried)
    raise OSError(
        f"{LIBTBB} (needed by ecospy and its ecos CLI) not found: looked in {looked} and "
        f"the system library paths. Install the 'tbb' package into this environment "
        f"(python -m pip install tbb; the project's test extra pins it: "
        f"python -m pip install -e \".[test]\"), or the system package libtbb12 (Debian).")


if __name__ == "__main__":
    lib = load_libtbb()
    print("" if lib is None else lib.parent)
