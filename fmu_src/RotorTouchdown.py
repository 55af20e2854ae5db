"""PythonFMU entry script of the FMU RotorTouchdown.

PythonFMU 0.7 compiles this script on every fmi2Instantiate, so it stays a few lines: the
adapter is ``rotortd_fmi.touchdown`` (shipped as resources/rotortd_fmi), compiled once per
process. Compiling the adapter here cost about 5 ms per instance.
"""

from rotortd_fmi import touchdown as _adapter

VARIABLE_META = _adapter.VARIABLE_META  # read by build.py


class RotorTouchdown(_adapter.RotorTouchdownAdapter):
    """The FMU's slave class; see ``rotortd_fmi.touchdown.RotorTouchdownAdapter``."""

    def __init__(self, **kwargs: object) -> None:
        # Needed: PythonFMU 0.7 execs this script in a fresh namespace that only the
        # script's own functions keep alive. Without one, fmi2Instantiate segfaults.
        super().__init__(**kwargs)
