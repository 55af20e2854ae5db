"""The variable table of the FMU RotorTouchdown (see ``variables``): the single source of its
names, causalities, types, starts, units, ranges, descriptions and tunable set.

The order of the rows is the order of registration, hence of the value references.
"""

from __future__ import annotations

from .variables import INPUT, OUTPUT, PARAMETER, Var, fixed, limited, names, output

TABLE: tuple[Var, ...] = (
    # parameters of the rotor and bearing (rotortd.RotorParams)
    limited("m", PARAMETER, 50.0, "Rotor mass"),
    limited("c", PARAMETER, 1400.0, "AMB damping (PD controller); tunable", tunable=True),
    limited("k", PARAMETER, 9.8e5, "AMB stiffness (PD controller); tunable", tunable=True),
    limited("e_c", PARAMETER, 0.3e-3, "Imbalance eccentricity; tunable", tunable=True),
    limited("phi", PARAMETER, 0.21, "Imbalance phase; tunable", tunable=True),
    limited("c_r", PARAMETER, 0.7e-3, "Radial clearance of the touchdown bearing"),
    limited("R", PARAMETER, 0.04, "Rotor radius at the touchdown bearing"),
    limited("mu", PARAMETER, 0.15, "Coulomb friction coefficient rotor/TDB; tunable",
            tunable=True),
    limited("d", PARAMETER, 0.95, "Newton coefficient of restitution; tunable", tunable=True),
    limited("g", PARAMETER, 0.0, "Gravity acting in -y (9.81 for a horizontal rotor)"),
    # initial state
    limited("x0", PARAMETER, 0.0, "Initial position x, |(x0, y0)| <= c_r; ignored if "
                                  "start_steady"),
    limited("y0", PARAMETER, 0.0, "Initial position y, |(x0, y0)| <= c_r; ignored if "
                                  "start_steady"),
    limited("vx0", PARAMETER, 0.0, "Initial velocity x; ignored if start_steady"),
    limited("vy0", PARAMETER, 0.0, "Initial velocity y; ignored if start_steady"),
    limited("psi0", PARAMETER, 0.0, "Initial spin angle"),
    # spin
    limited("J", PARAMETER, 0.04, "Polar inertia of the rotor about its mass centre, used if "
                                  "integrate_spin (must exceed m mu e_c (R + e_c))"),
    limited("h_spin", PARAMETER, 1e-6, "Deprecated, no effect (the spin state is exact); "
                                       "kept so that existing system files load"),
    fixed("levitate", "Boolean", True,
          "AMB bias force +i m g holds the rotor centred against gravity"),
    fixed("start_steady", "Boolean", False,
          "Start on the steady free whirl (error if not admissible); overrides x0, y0, vx0, "
          "vy0"),
    fixed("integrate_spin", "Boolean", False,
          "The spin is a state of the rotor (one rigid body with inertia J, driven by "
          "T_drive); the input Omega is then only the initial speed, Omega_out the spin"),
    fixed("impact_log", "String", "",
          "If not empty: CSV path; every impact is appended (time, x, y, vx-, vy-, vx+, vy+, "
          "rdot, P_n, P_t, stick)"),
    # inputs, held over a step
    limited("Omega", INPUT, 184.2, "Spin speed, held over the step; with integrate_spin "
                                   "only the initial speed, ignored afterwards"),
    limited("F_x", INPUT, 0.0, "External force on the rotor, x"),
    limited("F_y", INPUT, 0.0, "External force on the rotor, y"),
    limited("amb_on", INPUT, 1.0, "Magnetic bearing state: 1 on, 0 failed"),
    limited("T_drive", INPUT, 0.0, "Drive torque on the rotor (motor minus drag), held "
                                   "over the step, used if integrate_spin"),
    # outputs
    output("x", "m", "Rotor centre position x, inertial, |(x, y)| <= c_r while the race's "
                     "centre stays at the origin", shows="x"),
    output("y", "m", "Rotor centre position y, inertial, |(x, y)| <= c_r while the race's "
                     "centre stays at the origin", shows="y"),
    output("vx", "m/s", "Rotor centre velocity x, inertial", shows="vx"),
    output("vy", "m/s", "Rotor centre velocity y, inertial", shows="vy"),
    output("r_rel", "1", "Radial position relative to clearance r/c_r, r measured from the "
                         "race's centre", 0.0, shows="r_rel"),
    output("u_re", "1", "Co-rotating scaled position Re U, U = z exp(-i psi)/c_r, |U| <= 1",
           shows="u_re"),
    output("u_im", "1", "Co-rotating scaled position Im U, |U| <= 1", shows="u_im"),
    output("du_re", "1", "Co-rotating scaled velocity Re dU/dt, t = Omega tau; 0 when "
                         "Omega = 0", shows="du_re"),
    output("du_im", "1", "Co-rotating scaled velocity Im dU/dt, t = Omega tau; 0 when "
                         "Omega = 0", shows="du_im"),
    output("psi", "rad", "Spin angle wrapped to (-pi, pi]", shows="psi_wrapped"),
    output("whirl_rate", "rad/s", "Inertial whirl rate theta' (rate of the polar angle of z "
                                  "seen from the race's centre)", shows="whirl_rate"),
    output("v_rel", "m/s", "Slip velocity at the contact point R Omega + c_r theta' (with a "
                           "real bearing: minus the race's surface speed)", shows="v_rel"),
    output("F_bx", "N", "Bearing (contact) force on the rotor x, step-averaged, impulses as "
                        "P/h"),
    output("F_by", "N", "Bearing (contact) force on the rotor y, step-averaged, impulses as "
                        "P/h"),
    output("F_n", "N", "Normal contact force, step-averaged", 0.0),
    output("F_n_peak", "N", "Peak normal contact force within the step: with "
                            "contact_compliant the true peak of N; under the rigid law the "
                            "peak of the sustained contact force, impacts going to P_n (0 in "
                            "a step of flight and impacts only)", 0.0),
    output("P_n", "N.s", "Normal contact impulse within the step", 0.0),
    output("T_f", "N.m", "Friction torque on the spin, step-averaged; < 0 brakes a positive "
                         "spin"),
    output("T_imb", "N.m", "Imbalance reaction torque on the spin e_c Im(conj(F_amb + F_ext + "
                           "F_c) exp(i(psi + phi))), step-averaged, impacts as P/h; a "
                           "drivetrain that owns the spin inertia integrates "
                           "J Omega' = T_drive + T_f + T_imb (with integrate_spin the same "
                           "torque, already in the spin state)"),
    output("F_amb_x", "N", "Magnetic bearing force x at the end of the step", shows="F_amb_x"),
    output("F_amb_y", "N", "Magnetic bearing force y at the end of the step", shows="F_amb_y"),
    output("t_last_impact", "s", "Time of the last impact; 0 before any impact",
           shows="t_last_impact"),
    output("v_last_impact", "m/s", "Normal speed rdot- of the last impact; 0 before any", 0.0,
           shows="v_last_impact"),
    output("E_diss", "J", "Energy dissipated by contact (impacts, contact damping, friction), "
                          "cumulative", 0.0, shows="E_diss"),
    output("Omega_out", "rad/s", "Spin speed at the end of the step: the spin state if "
                                 "integrate_spin, else the input Omega", shows="Omega"),
    output("mode", "", "Contact mode at the end of the step: 0 free, 1 sliding, 2 rolling",
           0, 2, "Integer", shows="mode"),
    output("n_impacts", "", "Number of impacts since the start, cumulative", 0, None,
           "Integer", shows="n_impacts"),
    output("n_impacts_step", "", "Number of impacts within the last step", 0, None,
           "Integer"),
    output("in_contact", "", "Rotor in sustained contact (mode != 0) at the end of the step",
           type_="Boolean"),
    # the real touchdown bearing (docs/model.md §10); appended, so that the value
    # references above stay as they were. Fixed; every option needs integrate_spin.
    fixed("race_turns", "Boolean", False,
          "The touchdown bearing's inner race turns (J_b, T_b0, c_bw, omega_b0)"),
    limited("J_b", PARAMETER, 2e-4, "Polar inertia of the turning race, used if race_turns"),
    limited("T_b0", PARAMETER, 0.02, "Race drag: constant (Coulomb) part, also the static "
                                     "friction that holds it at rest; used if race_turns"),
    limited("c_bw", PARAMETER, 1e-5, "Race drag: viscous part; used if race_turns"),
    limited("omega_b0", PARAMETER, 0.0, "Initial spin of the race; used if race_turns"),
    fixed("support_compliant", "Boolean", False,
          "The race's centre sits on an isotropic spring-damper (m_b, k_b, c_b)"),
    limited("m_b", PARAMETER, 2.0, "Mass of the race and housing on the support; used if "
                                   "support_compliant"),
    limited("k_b", PARAMETER, 5e7, "Support stiffness; used if support_compliant"),
    limited("c_b", PARAMETER, 2e3, "Support damping; used if support_compliant"),
    fixed("contact_compliant", "Boolean", False,
          "Compliant contact N = K delta^p_c (1 + chi delta') with the restitution d exact "
          "(d = 0 refused); else the rigid impact law"),
    limited("k_c", PARAMETER, 1e9, "Contact stiffness at 10 um penetration; used if "
                                   "contact_compliant"),
    limited("p_c", PARAMETER, 1.0, "Contact law exponent: 1 linear, 10/9 line contact "
                                   "(roller), 1.5 Hertz point contact (ball); used if "
                                   "contact_compliant"),
    output("omega_b", "rad/s", "Spin of the race at the end of the step (0 unless "
                               "race_turns)"),
    output("x_b", "m", "Race centre x, inertial (0 unless support_compliant)"),
    output("y_b", "m", "Race centre y, inertial (0 unless support_compliant)"),
    output("vx_b", "m/s", "Race centre velocity x (0 unless support_compliant)"),
    output("vy_b", "m/s", "Race centre velocity y (0 unless support_compliant)"),
    output("F_sx", "N", "Force the bearing's support passes to the frame x, step-averaged "
                        "(with a rigid support the contact force on the race, impulses as "
                        "P/h)"),
    output("F_sy", "N", "Force the bearing's support passes to the frame y, step-averaged"),
    output("P_fric", "W", "Friction power at the contact, step-averaged (impacts as their "
                          "heat/h); 0 with all bearing options off", 0.0),
    output("E_fric", "J", "Friction heat put into the bearing, cumulative; 0 with all "
                          "bearing options off (E_diss then holds it)", 0.0),
    output("E_drag", "J", "Heat of the race's drag, cumulative (0 unless race_turns)", 0.0),
)

BY_NAME = {v.name: v for v in TABLE}
REAL_BEARING = tuple(v.name for v in TABLE[TABLE.index(BY_NAME["race_turns"]):])
"""The rows of the real bearing (appended in FMU state version 3): a state of version 1 or
2 lacks them, and they take their start values (all options off) when it is restored."""
PARAMETERS = names(TABLE, PARAMETER)
TUNABLE: frozenset[str] = frozenset(names(TABLE, PARAMETER, tunable=True))
FIXED = names(TABLE, PARAMETER, tunable=False)
INPUTS = names(TABLE, INPUT)
OUTPUTS = names(TABLE, OUTPUT)
RANGED_PARAMETERS = tuple(v.name for v in TABLE
                          if v.causality == PARAMETER and v.type == "Real")
"""Real parameters: each has a closed range (rotortd.limits) checked at initialisation."""
