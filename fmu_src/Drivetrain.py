"""PythonFMU entry script of the FMU Drivetrain (adapter: ``rotortd_fmi.drivetrain``).

Kept to a few lines because PythonFMU 0.7 compiles it on every fmi2Instantiate.
"""

from rotortd_fmi import drivetrain as _adapter

VARIABLE_META = _adapter.VARIABLE_META  # read by build.py


class Drivetrain(_adapter.DrivetrainAdapter):
    """The FMU's slave class; see ``rotortd_fmi.drivetrain.DrivetrainAdapter``."""

    def __init__(self, **kwargs: object) -> None:
        # Needed: PythonFMU 0.7 execs this script in a fresh namespace that only the
        # script's own functions keep alive. Without one, fmi2Instantiate segfaults.
        super().__init__(**kwargs)
