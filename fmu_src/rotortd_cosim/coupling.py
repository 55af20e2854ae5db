"""The scenes' coupling in process: the engines' Jacobi master on the FMUs' own code.

Runs a scene's physics on the code the FMUs run (``rotortd`` core, ``rotortd_drive``) with
the Jacobi semantics of the engines (each component holds over step k the other's outputs
of communication point k; the first step gets the initial outputs), so studies can go down
to small steps quickly. Two couplings:

- :func:`spin_jacobi`, the scenes' coupling: the bearing owns the spin
  (``rotortd.SpinCore``, ``integrate_spin``, J the whole spinning inertia) and holds the
  drivetrain's ``T_drive`` (motor plus drag, ``DriveCore`` with ``hold_speed`` =
  ``follow_speed``) over a step; the drivetrain holds the bearing's ``Omega_out``. It
  reproduces an ecospy run of the same scene and step bit for bit (tests/test_cosim.py).
- :func:`jacobi_drop`, the former held-Omega coupling of the drop scene (the drivetrain
  owns the inertia, the bearing holds its ``Omega``, the drivetrain holds ``T_f``): kept
  to show its chatter in rolling (docs/cosimulation.md).

SI units: s, rad/s, N m, kg m^2.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import rotortd
from rotortd_drive import MOTOR_PI, DriveCore, DriveParams

from .scenes import DROP, OMEGA_RUN, T_FAIL, Scene

TIME_EPS = 1e-9  # s, as rotortd_fmi.events.TIME_EPS


@dataclass
class Trace:
    """Per communication point (the end of each step): time [s], spin Omega_out [rad/s],
    drive torque T_drive held over the next step [N m], mode, cumulative impacts."""

    time: list[float] = field(default_factory=list)
    Omega: list[float] = field(default_factory=list)
    T_drive: list[float] = field(default_factory=list)
    mode: list[int] = field(default_factory=list)
    n_impacts: list[int] = field(default_factory=list)

    def at(self, t: float) -> float:
        """Omega [rad/s] at the communication point nearest to t [s]."""
        k = min(range(len(self.time)), key=lambda i: abs(self.time[i] - t))
        return self.Omega[k]


def _events(scene: Scene, t: float) -> tuple[float, complex]:
    """(amb_on, F_ext [N]) the TouchdownEvents FMU outputs at time t [s]."""
    ev = scene.events
    te = t + TIME_EPS
    amb = ev.get("amb_before", 1.0) if te < ev.get("t_fail", 1e30) else ev.get(
        "amb_after", 0.0)
    on = ev.get("t_force_on", 1e30) <= te < ev.get("t_force_off", 1e30)
    force = complex(ev.get("F_x_step", 0.0), ev.get("F_y_step", 0.0)) if on else 0j
    return float(amb), force


def _rotor_params(scene: Scene) -> rotortd.RotorParams:
    names = {f for f in rotortd.RotorParams.__dataclass_fields__}
    kw = {k: v for k, v in scene.rotor.items() if k in names}
    return rotortd.RotorParams(**kw)


def _drive(scene: Scene, omega0: float) -> DriveCore:
    d = scene.drive
    keys = ("J", "b", "Kp", "Ki", "T_max")
    kw = {k: float(d[k]) for k in keys if k in d}
    return DriveCore(DriveParams(motor=int(d.get("motor", 0)), **kw), omega0)


def spin_jacobi(scene: Scene, h: float, t_end: float | None = None) -> Trace:
    """The scene's coupling (module docstring) at communication step h [s] up to t_end
    [s] (default: the scene's stop time); every step of the bearing must end OK."""
    r, d = scene.rotor, scene.drive
    omega0 = float(r["Omega"])
    amb, force = _events(scene, 0.0)
    if r.get("start_steady"):
        core = rotortd.SpinCore.on_steady_whirl(_rotor_params(scene), omega0, F_ext=force,
                                                amb_on=amb, J=float(r["J"]))
    else:
        core = rotortd.SpinCore(_rotor_params(scene), float(r["J"]), Omega0=omega0)
    drive = _drive(scene, omega0)
    t_in, w_set = float(d.get("T_motor_in", 0.0)), float(d.get("Omega_set", 184.2))
    t_drive, omega = 0.0, omega0
    out = Trace()
    n = round((scene.stop_time if t_end is None else t_end) / h)
    for k in range(n):
        amb, force = _events(scene, k * h)
        rep = core.step(h, F_ext=force, amb_on=amb, T_drive=t_drive)
        if rep.status != rotortd.STATUS_OK:
            raise RuntimeError(f"bearing step {k} (h = {h!r} s): {rep.message}")
        drive.Omega = omega                                # follow_speed: Omega_in
        dr = drive.step(h, 0.0, t_in, w_set, hold_speed=True)
        t_drive, omega = dr.T_motor + dr.T_drag, core.Omega
        out.time.append((k + 1) * h)
        out.Omega.append(omega)
        out.T_drive.append(t_drive)
        out.mode.append(core.mode)
        out.n_impacts.append(core.n_impacts)
    return out


def _held_start() -> tuple[rotortd.TouchdownCore, DriveCore]:
    p = rotortd.RotorParams(g=9.81)
    core = rotortd.TouchdownCore.on_steady_whirl(p, OMEGA_RUN)
    d = DROP.drive
    drive = DriveCore(DriveParams(J=d["J"], b=d["b"], motor=MOTOR_PI, Kp=d["Kp"],
                                  Ki=d["Ki"], T_max=d["T_max"]), OMEGA_RUN)
    return core, drive


def jacobi_drop(h: float, t_end: float) -> tuple[float, float, int]:
    """The former held-Omega coupling of the drop scene at communication step h [s]:
    (Omega [rad/s], the momentum residual J dOmega - sum of impulses [N m s], impacts)
    at t_end [s]. The bearing's J is then infinite (the imbalance reaction on the spin is
    lost) and rolling is unstable for J < m R^2 (docs/cosimulation.md)."""
    core, drive = _held_start()
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


def jacobi_drop_trace(h: float, t_end: float) -> Trace:
    """As :func:`jacobi_drop`, the whole trace (Omega of the drivetrain after each step)."""
    core, drive = _held_start()
    t_f = 0.0
    out = Trace()
    for k in range(round(t_end / h)):
        amb = 1.0 if k * h < T_FAIL - 1e-12 else 0.0
        rep = core.step(h, drive.Omega, amb_on=amb)
        dr = drive.step(h, t_f, 0.0, OMEGA_RUN)
        t_f = rep.T_f
        out.time.append((k + 1) * h)
        out.Omega.append(drive.Omega)
        out.T_drive.append(dr.T_motor + dr.T_drag)
        out.mode.append(core.mode)
        out.n_impacts.append(core.n_impacts)
    return out
