"""rotortd_drive: drivetrain and spin-coupling helpers for the rotor-touchdown FMUs.

Pure Python (``math`` only), shipped inside the FMUs as ``resources/rotortd_drive``; the
name is unique to this project because every PythonFMU instance in a process shares
``sys.modules``. SI units throughout.

- :class:`DriveParams`, :class:`DriveCore`: ``J Omega' = T_motor - b Omega + T_bearing``
  with the motor a held torque input or a PI speed controller with a torque limit, advanced
  exactly for inputs held over a step (piecewise closed form).
- :class:`SpinCoupler`: integrates the spin inside the bearing FMU by sub-stepping the
  touchdown core and applying the exact friction impulse of each sub-step.
"""

from .drive import (
    MOTOR_PI,
    MOTOR_TORQUE,
    DriveCore,
    DriveError,
    DriveParams,
    DriveReport,
    held_speed_report,
)
from .spin import SpinCoupler, SpinReport

__all__ = [
    "MOTOR_PI",
    "MOTOR_TORQUE",
    "DriveCore",
    "DriveError",
    "DriveParams",
    "DriveReport",
    "SpinCoupler",
    "SpinReport",
    "held_speed_report",
]
