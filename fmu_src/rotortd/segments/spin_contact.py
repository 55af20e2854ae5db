"""Sustained contact with the spin as a state (docs/model.md §8): sliding and rolling.

Frame and units: inertial, SI. On the circle z = c_r n, n = e^{i theta}; with
E = e^{i(psi + phi)}, beta = psi + phi - theta, B = e_c sin(beta), A = R - e_c cos(beta)
(``rigid``), the known forces F_o = F_amb + F_ext - i m g + m e_c Omega^2 E and the torque
T_o = e_c Im(conj(F_amb + F_ext) E) of the bearing and the external force about the mass
centre, the contact force -(N + i F_t) n obeys

    N - m B Omega'               = Re(conj(n) F_o) + m c_r theta'^2        (normal)
    m c_r theta'' + m e_c cos(beta) Omega' = Im(conj(n) F_o) - F_t         (tangential)
    J Omega' + B N + A F_t       = T_drive + T_o                           (spin)

- Sliding (slip s = sign v_rel, v_rel = R Omega + c_r theta'): F_t = mu s N; the 2x2 for
  (N, Omega') has the determinant J + m B (B + mu s A) = m J (W_nn + mu s W_nt) > 0 where
  the problem is well posed (``rigid.check_well_posed``). State (theta, theta', psi, Omega).
- Rolling (v_rel = 0): Omega = -c_r theta'/R; the 3x3 gives
  Omega' = (T_drive + T_o - B rhs_n - A F_ot)/I_P with I_P = J + m (A^2 + B^2), the inertia
  about the contact point. State (theta, psi, Omega).

Both are integrated by Gragg-Bulirsch-Stoer extrapolation (``gbs``) at RTOL = 1e-13 per
step on every component, the contact impulses (int N, int F_t, int F_c) and the friction
dissipation (int mu N |v_rel|) carried as error-controlled quadratures. The step is capped
at H_FRACTION (one radian) of the fastest rotation (theta', Omega, beta'), and the event
functions (N, v_rel, mu N - |F_t|) are checked at each step's end and at its midpoint (the
cubic Hermite interpolant of the state from both ends' values and slopes), so a sign change
is seen unless it starts and ends within half a step; it is then located by re-integrating
the step with its column count fixed (Illinois regula falsi, to 4 ulp of the time).
Events (``rotortd.contact.events.Event``): LIFT_OFF (N reaches 0), SLIP_ZERO (v_rel
reaches 0 in sliding), SLIP_START (|F_t| reaches mu N in rolling).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

from ..contact.events import LIFT_OFF, SLIP_START, SLIP_ZERO
from ..contact.search import WORK_MAX
from ..contact.wall import ContactTally, ContactWorkExceeded, SegmentEnd
from ..params import RotorParams
from . import dry_whirl_orbit, gbs, rolling_spin_fast
from .gbs import RHS_WORK, STEP_WORK
from .roots import ROOT_ITERS, illinois

RTOL = 1e-13
"""Relative tolerance per extrapolated step, every component."""
H_FRACTION = 1.0
"""Largest step, in radians of the fastest rotation of the contact (theta', Omega, beta')."""
Vector = list[float]


@dataclass(slots=True)
class HeldInputs:
    """What a segment holds (SI): parameters, inertia J (kg m^2), amb_on a, the external
    force F_ext (N, at the geometric centre) and the drive torque T_drive (N m). (Slotted,
    not frozen: built every step with the spin a state, where a frozen record's
    construction cost 7k instructions more; nothing changes it once built.)"""

    p: RotorParams
    J: float
    a: float
    F_ext: complex
    T_drive: float


@dataclass(frozen=True, slots=True)
class ContactForces:
    """The contact's forces at one state (SI): N (N), F_t (N), theta'' (rad/s^2),
    Omega' (rad/s^2)."""

    N: float
    F_t: float
    ddtheta: float
    dOmega: float


_NAN6 = (math.nan,) * 6


class ContactModel:
    """The held inputs as plain floats, and the contact's forces at a state in real
    arithmetic (SI; one cos/sin pair each for theta and psi + phi)."""

    __slots__ = ("J", "R", "T", "ac", "ak", "c_r", "cr_ak", "e_c", "fx", "fy", "m", "m_cr", "m_ec",
                 "mg", "mu", "phi")

    def __init__(self, h: HeldInputs) -> None:
        p = h.p
        F1 = h.a * p.bias_force + h.F_ext  # the constant forces at the geometric centre (N)
        self.m, self.c_r, self.R, self.e_c, self.phi = p.m, p.c_r, p.R, p.e_c, p.phi
        self.mu, self.J, self.T, self.mg = p.mu, h.J, h.T_drive, p.m * p.g
        self.ac, self.ak = h.a * p.c, h.a * p.k
        # products of constants, formed once (each is the leading product of the expressions
        # below, evaluated left to right, so the same bits): kg m, kg m, N
        self.m_ec, self.m_cr, self.cr_ak = p.m * p.e_c, p.m * p.c_r, p.c_r * self.ak
        self.fx, self.fy = F1.real, F1.imag

    def _known(self, ct: float, st: float, dtheta: float, psi: float, Omega: float
               ) -> tuple[float, float, float, float, float, float]:
        """(B, A, rhs_n, F_ot, T, cos beta) at the contact state with n = ct + i st:
        rhs_n = Re(conj(n) F_o) + m c_r theta'^2 (N), F_ot = Im(conj(n) F_o) (N),
        T = T_drive + T_o (N m)."""
        c_r, e_c = self.c_r, self.e_c
        ang = psi + self.phi
        cE, sE = math.cos(ang), math.sin(ang)
        w, ck, ca = c_r * dtheta, self.cr_ak, self.ac
        Fr = self.fx + ca * w * st - ck * ct  # F_amb + F_ext, z = c_r n, v = i c_r theta' n
        Fi = self.fy - ca * w * ct - ck * st
        T = self.T + e_c * (Fr * sE - Fi * cE)
        u = self.m_ec * Omega * Omega
        Gr, Gi = Fr + u * cE, Fi - self.mg + u * sE  # F_o
        cb, sb = cE * ct + sE * st, sE * ct - cE * st  # e^{i beta} = conj(n) E
        return (e_c * sb, self.R - e_c * cb, Gr * ct + Gi * st + self.m_cr * dtheta * dtheta,
                Gi * ct - Gr * st, T, cb)

    def normal_tol(self, theta: float, dtheta: float, psi: float, Omega: float) -> float:
        """The rounding band of N (N): 64 eps times the magnitudes of its terms."""
        ct, st = math.cos(theta), math.sin(theta)
        _, A, _, _, T, _ = self._known(ct, st, dtheta, psi, Omega)
        scale = (abs(self.fx) + abs(self.fy) + self.mg + (self.ac * abs(dtheta) + self.ak)
                 * self.c_r + self.m_ec * Omega * Omega + self.m_cr * dtheta * dtheta
                 + abs(T) / max(abs(A), 1e-300))
        return 64.0 * 2.220446049250313e-16 * scale

    def sliding(self, s: float, theta: float, dtheta: float, psi: float, Omega: float
                ) -> tuple[float, float, float, float, float, float]:
        """(N, F_t, theta'', Omega', cos theta, sin theta) of sliding with slip sign s."""
        try:
            ct, st = math.cos(theta), math.sin(theta)
            B, A, rn, Fot, T, cb = self._known(ct, st, dtheta, psi, Omega)
        except ValueError:  # an angle overflowed to inf in a trial step: NaN rejects it
            return _NAN6
        m, mus = self.m, self.mu * s
        k = B + mus * A
        dW = (T - k * rn) / (self.J + m * B * k)
        N = rn + m * B * dW
        Ft = mus * N
        return N, Ft, (Fot - Ft - self.m_ec * cb * dW) / self.m_cr, dW, ct, st

    def rolling(self, theta: float, psi: float, Omega: float
                ) -> tuple[float, float, float, float, float, float]:
        """(N, F_t, theta'', Omega', cos theta, sin theta) of rolling (theta' = -R Omega/c_r)."""
        try:
            ct, st = math.cos(theta), math.sin(theta)
            B, A, rn, Fot, T, _ = self._known(ct, st, -self.R * Omega / self.c_r, psi, Omega)
        except ValueError:  # as in sliding
            return _NAN6
        m = self.m
        dW = (T - B * rn - A * Fot) / (self.J + m * (A * A + B * B))
        return rn + m * B * dW, Fot + m * A * dW, -self.R * dW / self.c_r, dW, ct, st


def sliding_forces(h: HeldInputs, s: float, theta: float, dtheta: float, psi: float,
                   Omega: float) -> ContactForces:
    """The forces of sliding with slip sign s at a state."""
    return ContactForces(*ContactModel(h).sliding(s, theta, dtheta, psi, Omega)[:4])


def rolling_forces(h: HeldInputs, theta: float, psi: float, Omega: float) -> ContactForces:
    """The forces of rolling (v_rel = 0, theta' = -R Omega/c_r) at a state."""
    return ContactForces(*ContactModel(h).rolling(theta, psi, Omega)[:4])


if TYPE_CHECKING:
    from .dry_whirl_driven import LevelTable

OrbitLike: TypeAlias = "dry_whirl_orbit.Orbit | LevelTable | None"
"""What rolling keeps from step to step: the orbit (T_drive = 0) or the level table (T_drive
held) of its last step, if any."""
_DRIVEN: list[Any] = []
"""``dry_whirl_driven``, imported at its first use: a run without a drive torque in dry
whirl (the held-speed core, most scenes) does not carry the module's objects, which the
garbage collector would traverse all run long (+0.5 % of the held core's limit cycle at
1e-3 s steps, measured with callgrind)."""


def orbit_advance(prev: OrbitLike, h: HeldInputs, theta: float, psi: float, Omega: float,
                  rem: float, limit: int, step0: float
                  ) -> tuple[SegmentEnd | None, OrbitLike]:
    """Roll rem (s) on the orbit's Fourier form: ``dry_whirl_orbit.advance`` without drive
    torque, ``dry_whirl_driven.advance`` with one held (the same arguments and answer)."""
    if h.T_drive == 0.0:
        return dry_whirl_orbit.advance(prev, h, theta, psi, Omega, rem, limit, step0)
    if not _DRIVEN:
        from . import dry_whirl_driven
        _DRIVEN.append(dry_whirl_driven)
    return _DRIVEN[0].advance(prev, h, theta, psi, Omega, rem, limit, step0)


class SpinContact:
    """One contact segment, sliding (s = +-1) or rolling (s = 0), from
    (theta, theta', psi, Omega); in rolling theta' = -R Omega/c_r is implied."""

    accelerate = True
    """Declared accelerator: rolling with the bearing's damper off (a c = 0) is advanced by
    its energy integral (``rolling_spin_fast.DryWhirl``, docs/notes/dry-whirl-quadrature.md)
    where that applies and no event can occur; False: always the integrator below."""
    follow_orbit = True
    """Declared accelerator: rolling is advanced on its orbit, the 2-D Fourier form of the
    energy integral kept across steps (``dry_whirl_orbit`` with T_drive = 0,
    docs/notes/dry-whirl-quadrature.md §8; ``dry_whirl_driven`` with T_drive held, its
    coefficients as functions of the level, §10); False: the panels of ``DryWhirl``
    instead."""

    def __init__(self, h: HeldInputs, s: float, theta: float, dtheta: float, psi: float,
                 Omega: float, step0: float = math.inf, n_slack: float = 0.0,
                 orbit: OrbitLike = None, asked: bool = False) -> None:
        self.h, self.s = h, s
        self.orbit = orbit  # rolling: the dry whirl orbit of the previous step, if any
        self.asked = asked  # the orbit refused this segment already, and ``orbit`` is its
        # answer (``SpinSteps._spin_roll_step``): not asked again
        self.n_slack = n_slack  # N (N): lift-off only once N < -n_slack
        self.rolling = s == 0.0
        self.y0: Vector = ([theta, psi, Omega] if self.rolling
                           else [theta, dtheta, psi, Omega])
        self.nq = len(self.y0)
        self.step0 = step0
        self.dth_per_W = -h.p.R / h.p.c_r
        self._start = (theta, dtheta, psi, Omega)
        self._ready = False
        self._on_orbit = not asked and self.orbit_applies(h, self.rolling)
        if not self._on_orbit:
            self._setup()

    @classmethod
    def orbit_applies(cls, h: HeldInputs, rolling: bool) -> bool:
        """The orbit (``orbit_advance``) is tried first: rolling, the accelerators on and
        a c = 0."""
        return (rolling and cls.accelerate and cls.follow_orbit
                and rolling_spin_fast.applies(h))

    def _setup(self) -> None:
        """The contact model, the integrator's step bounds and tolerances (not built where
        the orbit takes the segment)."""
        self._ready = True
        h, step0 = self.h, self.step0
        theta, dtheta, psi, Omega = self._start
        self.model = ContactModel(h)
        p = h.p
        N0 = self._forces(self.y0)[0]
        w = max(abs(dtheta), abs(Omega), abs(dtheta - Omega),
                math.sqrt(abs(N0) / (p.m * p.c_r)), math.sqrt(p.k / p.m), 1.0)
        self.h_max = H_FRACTION / w
        self.step0 = min(step0, self.h_max) if step0 < math.inf else 0.1 * self.h_max
        Fs = max(abs(N0) * (1.0 + p.mu), p.m * p.c_r * w * w)
        Ws = max(abs(Omega), p.c_r * w / p.R)
        self.tol_state = ([RTOL * (1.0 + abs(theta)), RTOL * (1.0 + abs(psi)), RTOL * Ws]
                          if self.rolling else
                          [RTOL * (1.0 + abs(theta)), RTOL * w, RTOL * (1.0 + abs(psi)),
                           RTOL * Ws])
        self.tol_rate = [RTOL * Fs] * 4 + [RTOL * Fs * (p.R * Ws + p.c_r * w)]
        """Tolerance per second of step of the quadratures int N, int F_t, int F_c, E_diss."""

    def _forces(self, y: Vector) -> tuple[float, float, float, float, float, float]:
        if self.rolling:
            return self.model.rolling(y[0], y[1], y[2])
        return self.model.sliding(self.s, y[0], y[1], y[2], y[3])

    def rhs(self, _u: float, y: Vector) -> Vector:
        """d/du of the state and of (int N, int F_t, Re int F_c, Im int F_c, E_diss)."""
        if self.rolling:
            N, Ft, _, dW, ct, st = self.model.rolling(y[0], y[1], y[2])
            return [self.dth_per_W * y[2], y[2], dW, N, Ft,
                    Ft * st - N * ct, -N * st - Ft * ct, 0.0]
        N, Ft, dd, dW, ct, st = self.model.sliding(self.s, y[0], y[1], y[2], y[3])
        vrel = self.model.R * y[3] + self.model.c_r * y[1]
        return [y[1], dd, y[3], dW, N, Ft, Ft * st - N * ct, -N * st - Ft * ct,
                abs(Ft * vrel)]

    def events(self, y: Vector) -> list[tuple[str, float]]:
        """The event functions at y, each positive while the segment lasts: N (lift-off),
        and in rolling mu N - |F_t| (slip start), in sliding s v_rel (slip zero)."""
        N, Ft = self._forces(y)[:2]
        if self.rolling:
            return [(LIFT_OFF, N + self.n_slack),
                    (SLIP_START, self.model.mu * N - abs(Ft))]
        vrel = self.model.R * y[3] + self.model.c_r * y[1]
        return [(LIFT_OFF, N + self.n_slack), (SLIP_ZERO, vrel * self.s)]

    def _margin(self, y: Vector) -> float:
        """The least event function (continuous; its first zero is the first event)."""
        return min(v for _, v in self.events(y))

    def _sweep(self) -> Callable[[float, Vector, Vector, float, int], Vector]:
        rhs = self.rhs
        return lambda u0, y0, f0, H, n: gbs.midpoint(rhs, u0, y0, f0, H, n)

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Advance at most rem (s) and limit work units; stop at the first event."""
        orbit = self.orbit if self.asked else None  # declared accelerators
        # (docs/notes/dry-whirl-quadrature.md; as set on the class at construction and on
        # the instance now); None = not here
        if self._on_orbit and self.accelerate and self.follow_orbit:
            fast, orbit = orbit_advance(self.orbit, self.h, *self.y0, rem, limit,
                                        self.step0)
            if fast is not None:
                return fast
        if not self._ready:
            self._setup()
        if self.rolling and self.accelerate and rolling_spin_fast.applies(self.h):
            fast = rolling_spin_fast.DryWhirl(self.h, *self.y0).advance(rem, limit, self.step0)
            if fast is not None:
                fast.orbit = orbit
                return fast
        y = self.y0 + [0.0] * 5
        nq = self.nq
        u, H, work = 0.0, self.step0, 0
        f0 = self.rhs(u, y)
        N_peak = abs(f0[nq])
        sweep = self._sweep()
        event = None
        while u < rem:
            if work > limit:
                raise ContactWorkExceeded(
                    f"{'rolling' if self.rolling else 'sliding'} with the spin as a state: "
                    f"{work} work units in {u!r} s", work)
            Hs = min(H, self.h_max, rem - u)
            scale = self.tol_state + [t * Hs + RTOL * abs(q)
                                      for t, q in zip(self.tol_rate, y[nq:])]
            y1, err, k, nfev = gbs.extrapolated_step(sweep, u, y, f0, Hs, scale, k_min=4)
            work += RHS_WORK * nfev + STEP_WORK
            if not err <= 1.0:
                H = 0.25 * Hs if err != err else gbs.next_step_size(Hs, err, k)
                continue
            f1 = self.rhs(u + Hs, y1)
            work += 2 * RHS_WORK
            hit = self._event_in_step(sweep, u, y, f0, y1, f1, Hs, k, scale)
            if hit is not None:
                tau, y, w2 = hit
                work += w2
                u += tau
                event = min(self.events(y), key=lambda e: e[1])[0]
                N_peak = max(N_peak, abs(self._forces(y)[0]))
                break
            u = rem if Hs == rem - u else u + Hs
            y, f0 = y1, f1
            N_peak = max(N_peak, abs(f1[nq]))
            H = gbs.next_step_size(Hs, err, k)
        return self._end(u, y, event, N_peak, work, H)

    def _event_in_step(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                       y1: Vector, f1: Vector, Hs: float, k: int, scale: Vector
                       ) -> tuple[float, Vector, int] | None:
        """An event in the accepted step (0, Hs]: the least event function negative at its
        end, or at its midpoint by the cubic Hermite interpolant of the state (a dip that
        returns by the end), then located; None if there is none."""
        if self._margin(y1) <= 0.0:
            return self._locate(sweep, u, y, f0, Hs, k, scale)
        nq = self.nq
        mid = [0.5 * (a + b) + 0.125 * Hs * (fa - fb)
               for a, b, fa, fb in zip(y[:nq], y1[:nq], f0[:nq], f1[:nq])]
        if self._margin(mid) <= 0.0:
            return self._locate(sweep, u, y, f0, 0.5 * Hs, k, scale)
        return None

    def _locate(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                b: float, k: int, scale: Vector) -> tuple[float, Vector, int] | None:
        """The first zero of the event function in (0, b] by regula falsi (Illinois) on
        the step re-integrated with k columns: (tau, state there, work); None when the
        function is positive at b after all (a midpoint estimate that was wrong)."""
        work = 0

        def at(tau: float) -> tuple[Vector, float]:
            nonlocal work
            yt, _, _, nfev = gbs.extrapolated_step(sweep, u, y, f0, tau, scale, k_fixed=k)
            work += RHS_WORK * nfev + STEP_WORK
            return yt, self._margin(yt)

        fa = self._margin(y)
        yb, fb = at(b)
        if fb > 0.0:
            return None
        _, b, yb = illinois(lambda x: at(x)[::-1], 0.0, fa, b, fb, yb,
                            lambda a, b, fb: b - a <= 4.0 * math.ulp(u + b) or fb == 0.0,
                            ROOT_ITERS)
        return b, yb, work

    def _end(self, u: float, y: Vector, event: str | None, N_peak: float, work: int,
             next_step: float) -> SegmentEnd:
        p = self.h.p
        if self.rolling:
            theta, psi, Omega = y[0], y[1], y[2]
            dtheta = -p.R * Omega / p.c_r
        else:
            theta, dtheta, psi, Omega = y[0], y[1], y[2], y[3]
        q = y[self.nq:]
        mc = p.m * p.c_r  # the tally is per unit m c_r (wall.ContactTally)
        tally = ContactTally(I_n=q[0] / mc, I_c=complex(q[2], q[3]) / mc, I_t=q[1] / mc,
                             I_e=q[4] / (mc * p.c_r), peak=N_peak / mc, work=work)
        return SegmentEnd(u, theta, dtheta, event, tally, next_step, psi=psi,
                          Omega=Omega, work=work)
