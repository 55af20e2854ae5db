"""rotortd: exact event-driven simulator of a rotor in its touchdown bearing.

Pure Python on ``math``/``cmath`` (no numpy, no pythonfmu), so it is fast for scalar
work and safe inside any FMI host. SI units and the inertial frame unless stated.
The FMU adapter (``fmu_src/rotortd_fmi/touchdown.py``) is a thin layer over ``TouchdownCore``
(the spin held over each step) and ``SpinCore`` (the spin as a state, docs/model.md §8),
with the chapter's fixed rigid bearing or a real one (``BearingParams``, docs/model.md §10).
"""

from .bodies.race import BearingParams, RealRace
from .contact.impact import Impact
from .contact.wall import WallForces
from .limits import LIMITS, CrossParameterError, Limit
from .params import TUNABLE, InputError, ParameterError, RotorParams, ScaledParams
from .segments.rub import RubEquilibrium, forward_rub_equilibria
from .step.simulator import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    STATUS_OK,
    STATUS_WORK_CAP,
    WORK_MAX,
    Kinematics,
    SpinCore,
    StepReport,
    TouchdownCore,
    restore_core,
    work_cap,
)

__all__ = [
    "LIMITS",
    "MODE_FREE",
    "MODE_ROLLING",
    "MODE_SLIDING",
    "STATUS_OK",
    "STATUS_WORK_CAP",
    "TUNABLE",
    "WORK_MAX",
    "BearingParams",
    "CrossParameterError",
    "Impact",
    "InputError",
    "Kinematics",
    "Limit",
    "ParameterError",
    "RealRace",
    "RotorParams",
    "RubEquilibrium",
    "ScaledParams",
    "SpinCore",
    "StepReport",
    "TouchdownCore",
    "WallForces",
    "forward_rub_equilibria",
    "restore_core",
    "work_cap",
]
