"""PythonFMU entry script of the FMU Drivetrain (adapter: ``rotortd_fmi.drivetrain``).

Kept to a few lines because PythonFMU 0.7 compiles it on every fmi2Instantiate.
"""

from rotortd_fmi import drivetrain as _adapter

VARIABLE_META = _adapter.VARIABLE_META  # read by build.py


class Drivetrain(_adapter.DrivetrainAdapter):
    """The FMU's slave class; see ``rotortd_fmi.drivetrain.DrivetrainAdapter``."""

    def __init__(self, **kwargs: object) -> None:
        # Needed: without a function of its own in this script, fmi2Instantiate
        # segfaults (PythonFMU 0.7.0 execs the script in a fresh namespace, which seems
        # to be kept alive only by the script's own functions).
        super().__init__(**kwargs)
