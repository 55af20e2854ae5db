"""What one step of TouchdownCore reports, and the context of a step taken segment by segment.

Frame and units: inertial, SI. ``StepReport`` is the step's one accumulator and its result;
``StepContext`` holds the step-scoped flags and the work count, passed down the step loop.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from ..contact.impact import Impact
from ..contact.search import WORK_MAX, Work
from ..contact.wall import ContactTally

MODE_FREE, MODE_SLIDING, MODE_ROLLING = 0, 1, 2
STATUS_OK, STATUS_WORK_CAP = 0, 1
_MODE_NAMES = {MODE_FREE: "lift_off", MODE_SLIDING: "sliding", MODE_ROLLING: "rolling"}


class WorkCapExceeded(RuntimeError):
    """A step exceeded its work cap."""


@dataclass(slots=True)
class StepReport:
    """What happened in one step (SI, inertial). Forces are step averages (impulse/h).

    Also the step's accumulator: while the step runs, impacts and contact segments add
    their impulses to P_contact, P_n, P_t, E_diss and F_n_peak (the contact force's peak;
    the impacts' P_n/h join it at the end), and the step's end turns the impulses into the
    averages F_contact, F_n and T_f (``TouchdownCore._finish``). P_imb, the imbalance
    reaction's angular impulse, is gathered as docs/model.md says (``TouchdownCore._imb_*``):
    each segment adds its integral of the co-rotating position, the step's end adds the
    boundary terms; T_imb = P_imb/h."""

    status: int = STATUS_OK
    message: str = ""
    impacts: list[Impact] = field(default_factory=list)
    F_contact: complex = 0j
    F_n: float = 0.0
    F_n_peak: float = 0.0
    P_n: float = 0.0
    T_f: float = 0.0
    E_diss: float = 0.0
    work: int = 0
    work_cap: int = 0
    transitions: list[tuple[float, str]] = field(default_factory=list)
    """Mode changes in the step: (t, "sliding" | "rolling" | "lift_off")."""
    P_contact: complex = 0j
    """Impulse of the contact on the rotor over the step (N s): F_contact = P_contact/h."""
    P_t: float = 0.0
    """Signed friction impulse (N s): T_f = -R P_t/h."""
    P_imb: float = 0.0
    """Angular impulse (N m s) of the imbalance reaction on the spin over the step, held
    Omega: int e_c Im(conj(F_amb + F_ext + F_c) e^{i(psi + phi)}) dt, impacts as impulses
    (F_amb = a (F_bias - c z' - k z); F_ext without gravity; F_c the contact force on the
    rotor). T_imb = P_imb/h."""
    T_imb: float = 0.0
    """Imbalance reaction torque on the spin (N m), step average P_imb/h: a drivetrain that
    owns the spin inertia integrates J Omega' = T_drive + T_f + T_imb."""
    P_support: complex = 0j
    """Real bearing (docs/model.md §10): impulse (N s) of the force the race's support
    passes to the frame over the step (with a rigid support, the contact's on the race)."""
    E_fric: float = 0.0
    """Real bearing: friction heat put into the contact over the step (J), impacts' share
    included."""
    F_support: complex = 0j
    """Real bearing: P_support/h (N), the support's force on the frame, step-averaged."""
    P_fric: float = 0.0
    """Real bearing: E_fric/h (W), the friction power, step-averaged."""

    def add_impact(self, imp: Impact, n: complex) -> None:
        """Add an impact at the unit contact normal n (inertial): the impact itself, its
        impulse on the rotor -(P_n + i P_t) n, its normal and friction impulses and its
        dissipation."""
        self.impacts.append(imp)
        self.P_contact -= complex(imp.P_n, imp.P_t) * n
        self.P_n += imp.P_n
        self.P_t += imp.P_t
        self.E_diss += imp.E_diss

    def add_contact(self, tal: ContactTally, mc: float, c_r: float) -> None:
        """Add a contact segment's integrals (per unit m c_r; mc = m c_r)."""
        self.P_contact += mc * tal.I_c
        self.P_n += mc * tal.I_n
        self.P_t += mc * tal.I_t
        self.E_diss += mc * c_r * tal.I_e
        self.F_n_peak = max(self.F_n_peak, mc * tal.peak)


class Kinematics(NamedTuple):
    """Outputs derived from the state (SI; u_*, du_* scaled co-rotating, t = Omega tau).

    x, y (m), vx, vy (m/s), r_rel = |z|/c_r, u = z e^{-i psi}/c_r, du = dU/dt (0 when
    Omega = 0), psi_wrapped (rad, (-pi, pi]), whirl_rate theta' (rad/s, inertial),
    v_rel = R Omega + c_r theta' (m/s), F_amb = a (F_bias - c v - k z) (N). A named tuple:
    the fields unpack in this order.
    """

    x: float
    y: float
    vx: float
    vy: float
    r_rel: float
    u_re: float
    u_im: float
    du_re: float
    du_im: float
    psi_wrapped: float
    whirl_rate: float
    v_rel: float
    F_amb_x: float
    F_amb_y: float


N_KINEMATICS = len(Kinematics._fields)


StateOutputs = namedtuple("StateOutputs", (
    *Kinematics._fields, "Omega", "mode", "n_impacts", "t_last_impact", "v_last_impact",
    "E_diss"))
StateOutputs.__doc__ = """What the state shows (``TouchdownCore.outputs``): the ``Kinematics``
fields, then the spin speed Omega (rad/s: the held input, or the state with the spin a
state), the mode (0 free, 1 sliding, 2 rolling) and the counters n_impacts, t_last_impact
(s), v_last_impact (m/s, the last impact's normal speed) and E_diss (J, dissipated so far).
A named tuple: the fields unpack in this order."""


class StepContext:
    """The context of a step taken segment by segment, passed down the step loop and
    never stored on the core: its work and work bound, the rounding error of its local
    time, and the flags that live for one step only. (Its impulses go to the StepReport.)"""

    __slots__ = ("cap", "first", "held", "imb_whole", "n_slack", "orbit_asked",
                 "roll_lenient", "rub_refused", "s_lo", "sticky_at", "work")

    def __init__(self, cap: int, rub_refused: bool = False) -> None:
        self.work = Work()
        self.cap = cap  # work bound (units)
        self.s_lo = 0.0  # rounding error of the step-local time (later), s
        self.roll_lenient = False  # zero slip proved stuck (_transition)
        self.sticky_at = math.nan  # where flight and contact swapped at N = 0
        self.n_slack = 0.0  # SpinCore: lift-off only below -n_slack (N), after sticky_at
        self.rub_refused = rub_refused  # the start state is not near a rub (_rub_step)
        self.first = True  # in the step's first segment (the step loop clears it)
        self.imb_whole = False  # P_imb of the whole step in closed form (_advance_free)
        self.held: Any = None  # SpinCore: the step's held inputs (spin_contact.HeldInputs)
        self.orbit_asked = False  # SpinCore: the dry whirl orbit refused the first
        # segment already (SpinSteps._spin_roll_step), and the core holds its answer

    def later(self, s: float, ds: float) -> float:
        """Step-local time s + ds (s), its rounding error kept in s_lo (2Sum): a long step
        of many events would otherwise drift by one rounding per event."""
        t = s + ds
        r = t - s
        self.s_lo += (s - (t - r)) + (ds - r)
        return t


def work_cap(*_args: object) -> int:
    """The work bound of one step (units): the constant WORK_MAX, whatever the scene and
    the step length (docs/model.md 7). The arguments (parameters, h, Omega, F_ext, amb_on,
    speed, as the former rate-based cap took them) are accepted and ignored."""
    return WORK_MAX


_SEGMENT_NAMES = {MODE_FREE: "free flight", MODE_SLIDING: "sliding", MODE_ROLLING: "rolling"}
_PROVED_FREE, _RUB = "proved free flight", "rub in closed form"  # _whole_step's choices


def stop_at_work_bound(rep: StepReport, st: StepContext, exc: Exception, t0: float, s: float,
                       h: float, where: str) -> None:
    """Record in ``rep`` that the step stopped at its work bound: STATUS_WORK_CAP and a
    message saying where (t0 the step's start, s how far into the step of h it got, in s;
    ``where`` names the segment). The exception's own work joins the step's count."""
    work = st.work
    work.iters += getattr(exc, "work", 0)
    # a segment that stops for another reason (no a-priori bound of a flight) says so: the
    # message claims the bound only when the step's count passed it
    why = (f"work bound reached: {work.total} > {st.cap} work units" if work.total > st.cap
           else f"stopped by the work bound's guard after {work.total} of {st.cap} work "
                "units")
    rep.status, rep.message = STATUS_WORK_CAP, (
        f"{why}; the core stopped at t = {t0 + s!r} s, {s!r} s into the step of {h!r} s, "
        f"in {where}: {exc}")
