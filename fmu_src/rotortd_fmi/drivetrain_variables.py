"""The variable table of the FMU Drivetrain (see ``variables``): the single source of its
names, causalities, types, starts, units, ranges, descriptions and tunable set. The order
of the rows is the order of registration. The ranges are the drivetrain core's domain
(``rotortd_drive.DriveParams.validate``: J, T_max > 0 are checked there as strict bounds)."""

from __future__ import annotations

from .variables import INPUT, PARAMETER, Var, fixed, names, output


def _param(name: str, start: float, unit: str, lo: float | None, description: str, *,
           tunable: bool = False) -> Var:
    return Var(name, PARAMETER, "Real", start, unit, lo, None, description, tunable)


def _input(name: str, start: float, unit: str, description: str) -> Var:
    return Var(name, INPUT, "Real", start, unit, None, None, description)


TABLE: tuple[Var, ...] = (
    _param("J", 0.04, "kg.m2", 0.0, "Polar inertia of rotor and drive, > 0"),
    _param("Omega0", 184.2, "rad/s", None, "Initial spin speed, finite"),
    _param("psi0", 0.0, "rad", None, "Initial spin angle, finite"),
    _param("b", 1e-4, "N.m.s", 0.0, "Viscous drag coefficient; tunable", tunable=True),
    _param("Kp", 0.2, "N.m.s", 0.0, "PI proportional gain; tunable", tunable=True),
    _param("Ki", 2.0, "N.m", 0.0, "PI integral gain; tunable", tunable=True),
    _param("T_max", 5.0, "N.m", 0.0, "PI torque limit |T_motor| <= T_max, > 0; tunable",
           tunable=True),
    Var("motor", PARAMETER, "Integer", 0, "", 0, 1,
        "Motor model: 0 torque input T_motor_in, 1 PI speed controller"),
    fixed("follow_speed", "Boolean", False,
          "Omega follows the input Omega_in (the spin is integrated elsewhere, e.g. "
          "RotorTouchdown with integrate_spin)"),
    _input("T_bearing", 0.0, "N.m", "Torque from the bearing (RotorTouchdown.T_f), held over "
                                    "the step"),
    _input("T_motor_in", 0.0, "N.m", "Motor torque if motor = 0 (torque input), held"),
    _input("Omega_set", 184.2, "rad/s", "Speed set-point of the PI controller (motor = 1)"),
    _input("Omega_in", 0.0, "rad/s", "Spin speed imposed from outside if follow_speed"),
    output("Omega", "rad/s", "Spin speed at the end of the step"),
    output("psi", "rad", "Spin angle wrapped to (-pi, pi]"),
    output("T_motor", "N.m", "Motor torque averaged over the step"),
    output("T_drag", "N.m", "Drag torque -b Omega averaged over the step"),
    output("T_drive", "N.m", "T_motor + T_drag averaged over the step (to "
                             "RotorTouchdown.T_drive)"),
    output("pi_integral", "rad", "PI integrator state, integral of Omega_set - Omega"),
    output("H_motor", "N.m.s", "Angular impulse of the motor since the start, cumulative"),
    output("H_drag", "N.m.s", "Angular impulse of the drag since the start, cumulative"),
    output("H_bearing", "N.m.s", "Angular impulse of T_bearing since the start, cumulative"),
    output("pi_regime", "", "PI regime at the end of the step: 0 linear, 1 saturated, 2 on "
                            "the limit with the integrator following it", 0, 2, "Integer"),
)

TUNABLE = names(TABLE, PARAMETER, tunable=True)
FIXED = names(TABLE, PARAMETER, tunable=False)
REAL_PARAMETERS = tuple(v.name for v in TABLE if v.causality == PARAMETER and v.type == "Real")
INPUTS = names(TABLE, INPUT)
