"""The co-simulation scenes: parameters per component, stop time, step (SI units).

Every scene couples the drivetrain to the bearing with the spin as a state of the bearing
(docs/cosimulation.md): ``RotorTouchdown.integrate_spin = true`` with ``J`` the whole
spinning inertia (J_ROTOR = m R^2/2 of the chapter's rotor, the drivetrain's J), and
``Drivetrain.follow_speed = true``: the drivetrain reads the spin (``Omega_in`` from
``RotorTouchdown.Omega_out``) and returns its motor plus drag torque (``T_drive``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

OMEGA_RUN = 184.2          # rad/s, the chapter's speed
T_FAIL = 0.1               # s, bearing failure in the drop test
J_ROTOR = 0.04             # kg m^2, polar inertia m R^2/2 of the chapter's rotor (50 kg, 40 mm)

SPIN = {"integrate_spin": True, "J": J_ROTOR}   # the bearing owns the spin (a state)
FOLLOW = {"follow_speed": True, "J": J_ROTOR}   # the drivetrain follows it


@dataclass(frozen=True)
class Scene:
    """A system scene: start values per component (parameters and unconnected inputs)."""

    name: str
    title: str
    stop_time: float                        # s
    step: float                             # s, default communication step
    rotor: dict[str, Any] = field(default_factory=dict)
    drive: dict[str, Any] = field(default_factory=dict)
    events: dict[str, Any] = field(default_factory=dict)

    def components(self) -> dict[str, dict[str, Any]]:
        """Start values by component instance name."""
        return {"RotorTouchdown": self.rotor, "Drivetrain": self.drive,
                "TouchdownEvents": self.events}


DROP = Scene(
    name="drop", title="Bearing failure at speed (drop test)", stop_time=0.35, step=1e-4,
    rotor={"g": 9.81, "levitate": True, "start_steady": True, "Omega": OMEGA_RUN, **SPIN},
    drive={**FOLLOW, "b": 1e-4, "motor": 1, "Omega0": OMEGA_RUN, "Omega_set": OMEGA_RUN,
           "Kp": 0.2, "Ki": 2.0, "T_max": 5.0},
    events={"t_fail": T_FAIL, "amb_before": 1.0, "amb_after": 0.0},
)

RUNDOWN = Scene(
    name="rundown", title="Run-down through the critical speed sqrt(k/m) = 140 rad/s",
    stop_time=0.6, step=1e-4,
    rotor={"g": 9.81, "levitate": True, "start_steady": True, "Omega": 220.0, **SPIN},
    drive={**FOLLOW, "b": 0.06, "motor": 0, "Omega0": 220.0, "T_motor_in": 0.0},
    events={},
)

FORCE = Scene(
    name="force", title="External force step pushes the rotor into the bearing",
    stop_time=0.4, step=1e-4,
    rotor={"g": 9.81, "levitate": True, "start_steady": True, "Omega": OMEGA_RUN,
           "e_c": 0.15e-3, "c": 3000.0, **SPIN},
    drive={**FOLLOW, "b": 1e-4, "motor": 1, "Omega0": OMEGA_RUN, "Omega_set": OMEGA_RUN,
           "Kp": 0.2, "Ki": 2.0, "T_max": 5.0},
    events={"t_force_on": 0.03, "t_force_off": 0.1, "F_y_step": -1500.0},
)

REAL_BEARING = {"mu": 0.15, "d": 0.9,
                "race_turns": True, "J_b": 2e-4, "T_b0": 0.02, "c_bw": 1e-5, "omega_b0": 0.0,
                "support_compliant": True, "m_b": 2.0, "k_b": 5e7, "c_b": 2e3,
                "contact_compliant": True, "k_c": 1e9, "p_c": 1.0}
"""The real touchdown bearing of issue 24 (docs/model.md §10, docs/bearing.md): a turning
race on a sprung support with a compliant contact."""

DROP_BEARING = Scene(
    name="drop_bearing", title="Drop test onto the real bearing (turning race, sprung "
    "support, compliant contact) under the PI drive", stop_time=0.35, step=1e-4,
    rotor={**DROP.rotor, **REAL_BEARING}, drive=DROP.drive, events=DROP.events,
)

SCENES: dict[str, Scene] = {s.name: s for s in (DROP, RUNDOWN, FORCE, DROP_BEARING)}

DROP_TORQUE = Scene(
    name="drop_torque", title="Drop test with a constant drive torque (no PI, no drag)",
    stop_time=DROP.stop_time, step=DROP.step, rotor=DROP.rotor,
    drive={**FOLLOW, "b": 0.0, "motor": 0, "T_motor_in": 2.0},
    events=DROP.events,
)
"""Test variant: the drivetrain's T_drive is the constant T_motor_in, independent of the
spin, so the coupled run must equal the bearing FMU run alone (tests/test_cosim.py)."""

VARIANTS: dict[str, Scene] = {DROP_TORQUE.name: DROP_TORQUE}
ALL_SCENES: dict[str, Scene] = {**SCENES, **VARIANTS}

# component-to-component connections (start component, output, end component, input)
CONNECTIONS: tuple[tuple[str, str, str, str], ...] = (
    ("RotorTouchdown", "Omega_out", "Drivetrain", "Omega_in"),
    ("Drivetrain", "T_drive", "RotorTouchdown", "T_drive"),
    ("TouchdownEvents", "amb_on", "RotorTouchdown", "amb_on"),
    ("TouchdownEvents", "F_x", "RotorTouchdown", "F_x"),
    ("TouchdownEvents", "F_y", "RotorTouchdown", "F_y"),
)

# outputs recorded by every engine (component, variable)
RECORDED: tuple[tuple[str, str], ...] = (
    ("Drivetrain", "Omega"), ("Drivetrain", "H_bearing"), ("Drivetrain", "H_motor"),
    ("Drivetrain", "H_drag"), ("Drivetrain", "T_motor"), ("Drivetrain", "T_drive"),
    ("Drivetrain", "T_drag"), ("Drivetrain", "pi_integral"),
    ("RotorTouchdown", "T_f"), ("RotorTouchdown", "x"), ("RotorTouchdown", "y"),
    ("RotorTouchdown", "vx"), ("RotorTouchdown", "vy"), ("RotorTouchdown", "r_rel"),
    ("RotorTouchdown", "F_bx"), ("RotorTouchdown", "F_by"), ("RotorTouchdown", "F_n"),
    ("RotorTouchdown", "mode"), ("RotorTouchdown", "n_impacts"),
    ("RotorTouchdown", "t_last_impact"), ("RotorTouchdown", "v_last_impact"),
    ("RotorTouchdown", "Omega_out"), ("RotorTouchdown", "psi"),
    ("RotorTouchdown", "E_diss"), ("RotorTouchdown", "F_amb_x"), ("RotorTouchdown", "F_amb_y"),
    ("RotorTouchdown", "F_n_peak"), ("RotorTouchdown", "omega_b"),
    ("TouchdownEvents", "amb_on"), ("TouchdownEvents", "F_x"), ("TouchdownEvents", "F_y"),
)

FMU_FILES: dict[str, str] = {"RotorTouchdown": "RotorTouchdown.fmu",
                             "Drivetrain": "Drivetrain.fmu",
                             "TouchdownEvents": "TouchdownEvents.fmu"}
