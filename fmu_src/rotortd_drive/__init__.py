"""rotortd_drive: the drivetrain of the rotor-touchdown FMUs.

Pure Python (``math`` only), shipped inside the FMUs as ``resources/rotortd_drive``; the
name is unique to this project because every PythonFMU instance in a process shares
``sys.modules``. SI units throughout.

- :class:`DriveParams`, :class:`DriveCore`: ``J Omega' = T_motor - b Omega + T_bearing``
  with the motor a held torque input or a PI speed controller with a torque limit, advanced
  exactly for inputs held over a step (piecewise closed form). With ``hold_speed`` (the
  Drivetrain FMU's ``follow_speed``) the spin is held at a speed read from outside (the
  bearing's spin state, ``rotortd.SpinCore``) and the step returns the motor and drag
  torques for it.
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

__all__ = [
    "MOTOR_PI",
    "MOTOR_TORQUE",
    "DriveCore",
    "DriveError",
    "DriveParams",
    "DriveReport",
    "held_speed_report",
]
