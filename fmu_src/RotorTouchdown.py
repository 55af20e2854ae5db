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
        # Needed: without a function of its own in this script, fmi2Instantiate
        # segfaults (PythonFMU 0.7.0 execs the script in a fresh namespace, which seems
        # to be kept alive only by the script's own functions).
        super().__init__(**kwargs)
