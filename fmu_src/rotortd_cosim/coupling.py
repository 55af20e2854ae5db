"""Coupling error of the held-Omega Jacobi coupling and of the integrate_spin remedy.

Runs the drop scene's physics in process on the same code the FMUs run (``rotortd``
core, ``rotortd_drive``) with a Jacobi master of the engines' semantics (each component
sees the other's outputs of the previous communication point), so the study can go down
to 1e-6 s steps quickly. SI units.
"""

from __future__ import annotations

import rotortd
from rotortd_drive import MOTOR_PI, DriveCore, DriveParams, SpinCoupler

from .scenes import DROP, OMEGA_RUN, T_FAIL


def _start() -> tuple[rotortd.TouchdownCore, DriveCore]:
    p = rotortd.RotorParams(g=9.81)
    core = rotortd.TouchdownCore.on_steady_whirl(p, OMEGA_RUN)
    d = DROP.drive
    drive = DriveCore(DriveParams(J=d["J"], b=d["b"], motor=MOTOR_PI, Kp=d["Kp"],
                                  Ki=d["Ki"], T_max=d["T_max"]), OMEGA_RUN)
    return core, drive


def jacobi_drop(h: float, t_end: float) -> tuple[float, float, int]:
    """Held-Omega coupling at communication step h [s]; (Omega [rad/s], the momentum
    residual J dOmega - sum of impulses [N m s], impacts) at t_end."""
    core, drive = _start()
    t_f = 0.0
    for k in range(round(t_end / h)):
        amb = 1.0 if k * h < T_FAIL - 1e-12 else 0.0
        omega = drive.Omega
        rep = core.step(h, omega, amb_on=amb)
        drive.step(h, t_f, 0.0, OMEGA_RUN)
        t_f = rep.T_f
    res = drive.params.J * (drive.Omega - OMEGA_RUN) - (drive.H_motor + drive.H_drag
                                                        + drive.H_bearing)
    return drive.Omega, res, core.n_impacts


def spin_drop(h: float, h_spin: float, t_end: float) -> tuple[float, int]:
    """integrate_spin coupling: the bearing integrates the spin at h_spin, the drivetrain
    (follow_speed) returns its motor + drag torque each communication step h."""
    core, drive = _start()
    spin = SpinCoupler(drive.params.J, h_spin, OMEGA_RUN)
    t_drive = 0.0
    for k in range(round(t_end / h)):
        amb = 1.0 if k * h < T_FAIL - 1e-12 else 0.0
        spin.step(core, h, t_drive, amb_on=amb)
        drive.Omega = spin.Omega
        rep = drive.step(h, 0.0, 0.0, OMEGA_RUN, hold_speed=True)
        t_drive = rep.T_motor + rep.T_drag
    return spin.Omega, core.n_impacts
