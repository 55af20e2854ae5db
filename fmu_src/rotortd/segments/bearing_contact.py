"""Sustained contact with the real touchdown bearing (docs/model.md §10): ``BearingContact``.

Frame and units: inertial, SI. The state is the two bodies' own, in Cartesian form:

    y = (x, y, x', y', psi, Omega, x_b, y_b, x_b', y_b', omega_b)

the rotor's geometric centre z, its velocity, spin angle and speed; the race's centre z_b,
its velocity and spin (constant zero where the option is off). With Delta = z - z_b,
n = Delta/|Delta|, the penetration delta = |Delta| - c_r, its rate delta' = Re(conj(n)
(z' - z_b')), the whirl rate theta' = Im(conj(n) (z' - z_b'))/|Delta| and the slip
v_rel = R Omega + Im(conj(n) (z' - z_b')) - R_b omega_b (10.5), every acceleration is affine
in the contact force -(N + i F_t) n on the rotor (+(N + i F_t) n on the race):

    (delta'', v_rel') = (a_n, a_t) - W (N, F_t)

with (a_n, a_t) the accelerations without contact force and W the pair's Delassus matrix
(10.8; the race's tangential share R_b^2/J_b only while it turns). The contact's discrete
state (``ContactState``) picks (N, F_t):

- compliant law: N = K delta^p (1 + chi delta') (10.6), or 0 while ``clamped`` (the law's
  value negative inside the penetration); rigid law: N from delta'' = 0;
- sliding (s = +-1): F_t = mu s N; sticking (s = 0): F_t from v_rel' = 0;
- a turning race: its drag T_b = -T_b0 s_b - c_bw omega_b (s_b the sense it turns in); a
  race held at rest (``race_held``): omega_b' = 0, the frame's static torque -R_b F_t.

The segment integrates the eleven states with Gragg-Bulirsch-Stoer extrapolation
(``gbs``) at RTOL per step on every component, as ``spin_contact.SpinContact`` does, with
the contact's integrals as auxiliary quadratures: int N, int F_t, int F_c (complex), the
friction heat int F_t v_rel, the contact damping's heat int (N - K delta^p) delta', the
race drag's heat int -T_b omega_b, the support damper's int c_b |z_b'|^2 and the impulse of
the force the support passes to the frame, int F_s (complex). Under the rigid law the
constraint delta = 0 (and v_rel = 0 in sticking) is held at the acceleration level; each
accepted step ends with the state projected back onto it (the position radially, the
velocities by the impulse through W that cancels delta' and, sticking, v_rel), a change of
the order of the step's error. Events (each a function positive while the segment lasts,
checked at each step's end and midpoint and located as in SpinContact):

- SEPARATE: delta reaches 0 (compliant; the contact opens);
- LIFT_OFF: N reaches 0 (rigid: lift-off; compliant: the law's value, N clamps at 0);
- CLAMP_END: the clamped law's value reaches 0 again (1 + chi delta' = 0);
- SLIP_ZERO (sliding: v_rel reaches 0), SLIP_START (sticking: |F_t| reaches mu N);
- RACE_STOP: a race turning against static friction (T_b0 > 0) reaches omega_b = 0;
- BREAKAWAY: the static torque that holds the race reaches T_b0.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from ..contact.events import (
    BREAKAWAY,
    CLAMP_END,
    LIFT_OFF,
    RACE_STOP,
    SEPARATE,
    SLIP_START,
    SLIP_ZERO,
    Event,
)
from ..contact.search import WORK_MAX
from ..contact.wall import ContactWorkExceeded
from . import gbs
from .roots import ROOT_ITERS, illinois
from .spin_contact import H_FRACTION, RTOL, HeldInputs

Vector = list[float]
RHS_WORK = 2 * gbs.RHS_WORK
"""Work units per right-hand side: twice the spin-state contact's (measured 5.7 us against
3.1 us a call, and 21 components against 9 in the extrapolation's sweeps)."""
STEP_WORK = 2 * gbs.STEP_WORK
"""Work units per extrapolated step beyond its right-hand sides (as RHS_WORK)."""
_R_SLIDE, _R_STICK, _CLAMPED, _C_SLIDE, _C_STICK = range(5)
"""The contact's kinds in BearingModel (the rigid law's below _CLAMPED)."""
_NAN25 = (math.nan,) * 25
NY = 11
"""State components: x, y, x', y', psi, Omega, x_b, y_b, x_b', y_b', omega_b."""
NQ = 10
"""Quadratures: int N, int F_t, Re/Im int F_c, E_fric, E_damp_c, E_drag, E_support,
Re/Im int F_s."""


@dataclass(frozen=True, slots=True)
class BearingLaw:
    """What a contact segment holds of the bearing (SI): the race's spin (``turns``: J_b
    kg m^2, T_b0 N m, c_bw N m s, bore R_b m), its support (``support``: m_b kg, k_b N/m,
    c_b N s/m) and the contact law (``compliant``: K N/m^p, the exponent p; else rigid)."""

    turns: bool
    J_b: float
    T_b0: float
    c_bw: float
    R_b: float
    support: bool
    m_b: float
    k_b: float
    c_b: float
    compliant: bool
    K: float
    p: float


@dataclass(frozen=True, slots=True)
class ContactState:
    """The contact's discrete state: slip sign ``s`` (+-1 sliding, 0 sticking); ``clamped``
    (compliant law: N held at 0 inside the penetration); ``chi`` (s/m, the compliant law's
    damping c_d/v_in of this contact); ``race_held`` (a turning race held at rest by static
    friction); ``s_b`` (+-1: the sense of the race's drag law while it turns)."""

    s: float
    clamped: bool = False
    chi: float = 0.0
    race_held: bool = False
    s_b: float = 1.0


@dataclass(frozen=True, slots=True)
class BearingForces:
    """The contact at one state (SI): N, F_t (N), delta (m), delta' (m/s), v_rel (m/s), the
    normal n, the compliant law's value N_law (N; NaN under the rigid law), its elastic part
    K delta^p (N), the race's drag T_b (N m), the rate of N (N/s; compliant law, else NaN)
    and the derivative of y."""

    N: float
    F_t: float
    delta: float
    ddelta: float
    vrel: float
    n: complex
    N_law: float
    N_el: float
    T_b: float
    dN: float
    dy: Vector


class BearingModel:
    """The held inputs, the bearing's law and the contact's state as plain floats; the
    forces and derivatives at a state (SI, inertial)."""

    def __init__(self, h: HeldInputs, law: BearingLaw, cs: ContactState) -> None:
        p = h.p
        self.h, self.law, self.cs = h, law, cs
        self.m, self.J, self.R, self.e_c, self.phi = p.m, h.J, p.R, p.e_c, p.phi
        self.c_r, self.mu, self.mg, self.T = p.c_r, p.mu, p.m * p.g, h.T_drive
        F1 = h.a * p.bias_force + h.F_ext  # constant forces at the centre (N)
        self.F1x, self.F1y = F1.real, F1.imag
        self.ac, self.ak = h.a * p.c, h.a * p.k
        self.im, self.iJ = 1.0 / p.m, 1.0 / h.J
        self.turning = law.turns and not cs.race_held
        self.iJb = 1.0 / law.J_b if self.turning else 0.0
        self.w_b = law.R_b * law.R_b * self.iJb
        self.i_mb = 1.0 / law.m_b if law.support else 0.0
        self.kb, self.cb = (law.k_b, law.c_b) if law.support else (0.0, 0.0)
        self.Tb0 = law.T_b0 * cs.s_b if self.turning else 0.0
        self.cbw = law.c_bw if self.turning else 0.0
        if law.compliant:
            self.kind = _CLAMPED if cs.clamped else (_C_SLIDE if cs.s != 0.0 else _C_STICK)
        else:
            self.kind = _R_SLIDE if cs.s != 0.0 else _R_STICK
        self.mus = self.mu * cs.s

    def _eval(self, y: Vector) -> tuple[float, ...]:
        """The one definition of the contact's mechanics at y (module docstring), in real
        arithmetic: (N, F_t, delta, delta', v_rel, n_x, n_y, N_law, N_el, T_b, the relative
        acceleration Delta'' (x, y), |Delta|, theta', then the eleven derivatives of y).
        NaN everywhere where a trial state overflowed (an angle or a power out of range):
        the integrator then rejects the step."""
        try:
            return self._mechanics(y)
        except (ValueError, OverflowError, ZeroDivisionError):
            return _NAN25

    def _mechanics(self, y: Vector) -> tuple[float, ...]:
        """``_eval`` without its guard."""
        x, yy, vx, vy, psi, Om, xb, yb, vxb, vyb, wb = y[:11]
        R, R_b, e_c = self.R, self.law.R_b, self.e_c
        Dx, Dy = x - xb, yy - yb
        r = math.hypot(Dx, Dy)
        nx, ny = Dx / r, Dy / r
        ux, uy = vx - vxb, vy - vyb
        dd = nx * ux + ny * uy
        wt = nx * uy - ny * ux
        dth = wt / r
        vrel = R * Om + wt - R_b * wb
        ang = psi + self.phi
        cE, sE = math.cos(ang), math.sin(ang)
        Fx = self.F1x - self.ac * vx - self.ak * x  # F_amb + F_ext (N)
        Fy = self.F1y - self.ac * vy - self.ak * yy
        dOm0 = (self.T + e_c * (Fx * sE - Fy * cE)) * self.iJ
        O2 = Om * Om
        zx0 = Fx * self.im + e_c * (O2 * cE + dOm0 * sE)
        zy0 = (Fy - self.mg) * self.im + e_c * (O2 * sE - dOm0 * cE)
        bx0 = -(self.kb * xb + self.cb * vxb) * self.i_mb
        by0 = -(self.kb * yb + self.cb * vyb) * self.i_mb
        T_b = -self.Tb0 - self.cbw * wb
        wbd0 = T_b * self.iJb
        qx, qy = zx0 - bx0, zy0 - by0
        a_n = nx * qx + ny * qy + r * dth * dth
        a_t = R * dOm0 + nx * qy - ny * qx - dth * dd - R_b * wbd0
        B = e_c * (nx * sE - ny * cE)  # e_c Im(e^{i beta}), e^{i beta} = conj(n) E
        A = R - e_c * (nx * cE + ny * sE)
        iJ, im, i_mb = self.iJ, self.im, self.i_mb
        Wnn = im + B * B * iJ + i_mb
        Wnt = A * B * iJ
        Wtt = im + A * A * iJ + i_mb + self.w_b
        delta = r - self.c_r
        kind = self.kind
        N_law = N_el = math.nan
        if kind >= _CLAMPED:  # the compliant law
            law = self.law
            N_el = law.K * delta ** law.p if delta > 0.0 else 0.0
            N_law = N_el * (1.0 + self.cs.chi * dd)
            if kind == _CLAMPED:
                N = Ft = 0.0
            elif kind == _C_SLIDE:
                N = N_law
                Ft = self.mus * N
            else:
                N = N_law
                Ft = (a_t - Wnt * N) / Wtt
        elif kind == _R_SLIDE:
            N = a_n / (Wnn + self.mus * Wnt)
            Ft = self.mus * N
        else:
            det = Wnn * Wtt - Wnt * Wnt
            N = (Wtt * a_n - Wnt * a_t) / det
            Ft = (Wnn * a_t - Wnt * a_n) / det
        Px, Py = N * nx - Ft * ny, N * ny + Ft * nx  # (N + i F_t) n: the force on the race
        dOm = dOm0 - (B * N + A * Ft) * iJ
        dW = e_c * (dOm - dOm0)
        zx = zx0 - Px * im + dW * sE
        zy = zy0 - Py * im - dW * cE
        bx, by = bx0 + Px * i_mb, by0 + Py * i_mb
        wbd = wbd0 + R_b * Ft * self.iJb
        return (N, Ft, delta, dd, vrel, nx, ny, N_law, N_el, T_b, zx - bx, zy - by, r, dth,
                vx, vy, zx, zy, Om, dOm, vxb, vyb, bx, by, wbd)

    def forces(self, y: Vector) -> BearingForces:
        """The contact's forces and the derivative of y at y."""
        e = self._eval(y)
        N, Ft, delta, dd, vrel, nx, ny, N_law, N_el, T_b, ax, ay, r, dth = e[:14]
        dN = math.nan
        if self.kind >= _CLAMPED:
            dN = 0.0
            if delta > 0.0 and self.kind != _CLAMPED:
                ddd = nx * ax + ny * ay + r * dth * dth  # delta''
                chi = self.cs.chi
                dN = self.law.p * N_el / delta * dd * (1.0 + chi * dd) + N_el * chi * ddd
        return BearingForces(N, Ft, delta, dd, vrel, complex(nx, ny), N_law, N_el, T_b, dN,
                             list(e[14:]))

    def free_normal_acceleration(self, y: Vector) -> float:
        """delta'' (m/s^2) at y without contact force: a_n of the module docstring."""
        free = replace(self.law, compliant=True)  # clamped: N = F_t = 0
        f = BearingModel(self.h, free, replace(self.cs, clamped=True)).forces(y)
        D = complex(y[0] - y[6], y[1] - y[7])
        r = abs(D)
        n = D / r
        w = n.conjugate() * complex(y[2] - y[8], y[3] - y[9])
        acc = n.conjugate() * complex(f.dy[2] - f.dy[8], f.dy[3] - f.dy[9])
        return acc.real + w.imag * w.imag / r

    def rhs(self, _u: float, y: Vector) -> Vector:
        """d/du of the state and of the quadratures (module docstring)."""
        e = self._eval(y)
        N, Ft, _, dd, vrel, nx, ny, _, N_el, T_b = e[:10]
        if self.law.support:
            Fsx = self.kb * y[6] + self.cb * y[8]
            Fsy = self.kb * y[7] + self.cb * y[9]
            E_sup = self.cb * (y[8] * y[8] + y[9] * y[9])
        else:
            Fsx, Fsy, E_sup = N * nx - Ft * ny, N * ny + Ft * nx, 0.0
        damp = (N - N_el) * dd if self.kind >= _CLAMPED else 0.0
        return [*e[14:], N, Ft, Ft * ny - N * nx, -N * ny - Ft * nx, Ft * vrel, damp,
                -T_b * y[10], E_sup, Fsx, Fsy]

    def events(self, y: Vector) -> list[tuple[Event, float]]:
        """The event functions at y (module docstring), each positive while the segment
        lasts."""
        f = self.forces(y)
        law, cs = self.law, self.cs
        out: list[tuple[Event, float]] = []
        if law.compliant:
            out.append((SEPARATE, f.delta))
            if cs.clamped:
                return [*out, (CLAMP_END, -f.N_law), *self._race_events(y, f)]
            out.append((LIFT_OFF, f.N_law))
        else:
            out.append((LIFT_OFF, f.N))
        if self.mu == 0.0:  # no friction: the slip has no events
            pass
        elif cs.s != 0.0:
            out.append((SLIP_ZERO, cs.s * f.vrel))
        else:
            out.append((SLIP_START, self.mu * f.N - abs(f.F_t)))
        return out + self._race_events(y, f)

    def _race_events(self, y: Vector, f: BearingForces) -> list[tuple[Event, float]]:
        law = self.law
        if not law.turns or law.T_b0 == 0.0:
            return []
        if self.cs.race_held:
            return [(BREAKAWAY, law.T_b0 - law.R_b * abs(f.F_t))]
        return [(RACE_STOP, self.cs.s_b * y[10])]

    def project(self, y: Vector) -> None:
        """Rigid law: put y back onto the constraint (in place): the rotor's centre onto the
        circle |z - z_b| = c_r, then the impulse through W that cancels delta' (and v_rel,
        sticking) on both bodies."""
        law = self.law
        z, zb = complex(y[0], y[1]), complex(y[6], y[7])
        D = z - zb
        n = D / abs(D)
        z = zb + self.c_r * n
        y[0], y[1] = z.real, z.imag
        f = self.forces(y)
        E = cmath.exp(1j * (y[4] + self.phi))
        eb = n.conjugate() * E
        B, A = self.e_c * eb.imag, self.R - self.e_c * eb.real
        Wnn = 1.0 / self.m + B * B / self.J + self.i_mb
        if self.cs.s != 0.0:
            Pn, Pt = f.ddelta / Wnn, 0.0
        else:
            Wnt = A * B / self.J
            Wtt = 1.0 / self.m + A * A / self.J + self.i_mb + self.w_b
            det = Wnn * Wtt - Wnt * Wnt
            Pn = (Wtt * f.ddelta - Wnt * f.vrel) / det
            Pt = (Wnn * f.vrel - Wnt * f.ddelta) / det
        P = complex(Pn, Pt) * n
        dOm = -(B * Pn + A * Pt) / self.J
        v = complex(y[2], y[3]) - P / self.m - 1j * self.e_c * dOm * E
        y[2], y[3], y[5] = v.real, v.imag, y[5] + dOm
        if law.support:
            vb = complex(y[8], y[9]) + P * self.i_mb
            y[8], y[9] = vb.real, vb.imag
        if self.turning:
            y[10] += law.R_b * Pt / law.J_b


@dataclass(frozen=True, slots=True)
class BearingEnd:
    """Where a contact segment stopped: after ``duration`` s, the state y (NY floats), the
    quadratures q (NQ floats, module docstring), the event (None: rem reached), the peak
    normal force (N), the work units used and the integrator's next step (s)."""

    duration: float
    y: Vector
    q: Vector
    event: Event | None
    N_peak: float
    work: int
    next_step: float


class BearingContact:
    """One contact segment with the real bearing from the state y0 (NY floats)."""

    def __init__(self, h: HeldInputs, law: BearingLaw, cs: ContactState, y0: Vector,
                 step0: float = math.inf) -> None:
        self.model = BearingModel(h, law, cs)
        self.y0 = list(y0)
        p = h.p
        f = self.model.forces(self.y0)
        dth = (n_c := f.n.conjugate() * (complex(y0[2], y0[3]) - complex(y0[8], y0[9]))
               ).imag / p.c_r
        Om = y0[5]
        rates = [abs(Om), abs(dth), abs(dth - Om), math.sqrt(abs(f.N) / (p.m * p.c_r)),
                 math.sqrt(p.k / p.m), 1.0]
        m_eff = 1.0 / (1.0 / p.m + self.model.i_mb)
        if law.support:
            rates += [math.sqrt(law.k_b / law.m_b), law.c_b / law.m_b]
        if law.compliant:
            k_lin = law.p * law.K * max(f.delta, 1e-5) ** (law.p - 1.0)
            rates += [math.sqrt(k_lin / m_eff), cs.chi * max(f.N_el, 0.0) / m_eff]
        w = max(rates)
        self.h_max = H_FRACTION / w
        self.step0 = min(step0, self.h_max) if step0 < math.inf else 0.1 * self.h_max
        vs = max(abs(complex(y0[2], y0[3])), abs(n_c), p.c_r * w)
        Ws = max(abs(Om), vs / p.R)
        wbs = max(abs(y0[10]), p.R * Ws / law.R_b)
        xs = RTOL * p.c_r
        self.tol_state = [xs, xs, RTOL * vs, RTOL * vs, RTOL * (1.0 + abs(y0[4])), RTOL * Ws,
                          xs, xs, RTOL * vs, RTOL * vs, RTOL * wbs]
        Fs = max(abs(f.N) * (1.0 + p.mu), p.m * p.c_r * w * w)
        self.tol_rate = [RTOL * Fs] * 4 + [RTOL * Fs * vs] * 4 + [RTOL * Fs] * 2
        """Tolerance per second of step of the quadratures."""

    def _margin(self, y: Vector) -> float:
        """The least event function (its first zero is the first event)."""
        return min(v for _, v in self.model.events(y))

    def _sweep(self) -> Callable[[float, Vector, Vector, float, int], Vector]:
        rhs = self.model.rhs
        return lambda u0, y0, f0, H, n: gbs.midpoint(rhs, u0, y0, f0, H, n)

    def run(self, rem: float, limit: int = WORK_MAX) -> BearingEnd:
        """Advance at most rem (s) and limit work units; stop at the first event."""
        model = self.model
        rigid = not model.law.compliant
        y = self.y0 + [0.0] * NQ
        u, H, work = 0.0, self.step0, 0
        f0 = model.rhs(u, y)
        N_peak = abs(f0[NY])
        sweep = self._sweep()
        event = None
        while u < rem:
            if work > limit:
                raise ContactWorkExceeded(
                    f"contact with the real bearing: {work} work units in {u!r} s", work)
            Hs = min(H, self.h_max, rem - u)
            scale = self.tol_state + [t * Hs + RTOL * abs(q)
                                      for t, q in zip(self.tol_rate, y[NY:])]
            y1, err, k, nfev = gbs.extrapolated_step(sweep, u, y, f0, Hs, scale, k_min=4)
            work += RHS_WORK * nfev + STEP_WORK
            if not err <= 1.0:
                H = 0.25 * Hs if err != err else gbs.next_step_size(Hs, err, k)
                continue
            if rigid:
                model.project(y1)
            f1 = model.rhs(u + Hs, y1)
            work += 2 * RHS_WORK
            hit = self._event_in_step(sweep, u, y, f0, y1, f1, Hs, k, scale)
            if hit is not None:
                tau, y_ev, w2 = hit
                top, w3 = self._peak_in_step(sweep, u, y, f0, y_ev, tau, k, scale)
                work += w2 + w3
                u, y = u + tau, y_ev
                event = min(model.events(y), key=lambda e: e[1])[0]
                N_peak = max(N_peak, top)
                break
            top, w2 = self._peak_in_step(sweep, u, y, f0, y1, Hs, k, scale)
            N_peak, work = max(N_peak, top), work + w2
            u = rem if Hs == rem - u else u + Hs
            y, f0 = y1, f1
            H = gbs.next_step_size(Hs, err, k)
        return BearingEnd(u, y[:NY], y[NY:], event, N_peak, work, H)

    def _peak_in_step(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                      y1: Vector, Hs: float, k: int, scale: Vector) -> tuple[float, int]:
        """(the largest N in the accepted step, work): the ends' N, and under the compliant
        law, where N' turns from positive to not positive in the step, the peak bracketed
        by Illinois on N' (the step re-integrated with k columns). A step is at most a
        radian of the contact's natural frequency, so N has at most one interior maximum
        in it, where N' decreases: on a bracket [a, b] of it, N(a) + (b - a) N'(a) and
        N(b) - (b - a) N'(b) both bound the peak from above. The search stops once the
        smaller of the two excesses, (b - a) min(N'(a), -N'(b)), is at most RTOL of the
        larger end value, which it returns (or at 4 ulp of the time)."""
        model = self.model
        fa, fb = model.forces(y), model.forces(y1)
        peak = max(fa.N, fb.N)
        if not (fa.dN > 0.0 >= fb.dN):
            return peak, 0
        work = 0
        seen = {0.0: (fa.dN, fa.N), Hs: (fb.dN, fb.N)}

        def at(tau: float) -> tuple[float, float]:
            nonlocal work
            yt, _, _, nfev = gbs.extrapolated_step(sweep, u, y, f0, tau, scale, k_fixed=k)
            work += RHS_WORK * nfev + STEP_WORK
            ft = model.forces(yt)
            seen[tau] = ft.dN, ft.N
            return ft.dN, ft.N

        def narrow(a: float, b: float, _fb: float) -> bool:
            (dNa, Na), (dNb, Nb) = seen[a], seen[b]
            return (b - a) * min(dNa, -dNb) <= RTOL * max(Na, Nb) \
                or b - a <= 4.0 * math.ulp(u + b) or dNb == 0.0

        a, b, _ = illinois(at, 0.0, fa.dN, Hs, fb.dN, fb.N, narrow, ROOT_ITERS)
        return max(peak, seen[a][1], seen[b][1]), work

    @staticmethod
    def _hermite(y: Vector, f0: Vector, y1: Vector, f1: Vector, Hs: float, x: float
                 ) -> Vector:
        """The cubic Hermite interpolant of the state at the fraction x of the step."""
        h00 = (1.0 + 2.0 * x) * (1.0 - x) ** 2
        h10 = x * (1.0 - x) ** 2
        h01 = x * x * (3.0 - 2.0 * x)
        h11 = x * x * (x - 1.0)
        return [h00 * a + h10 * Hs * fa + h01 * b + h11 * Hs * fb
                for a, b, fa, fb in zip(y[:NY], y1[:NY], f0[:NY], f1[:NY])]

    def _event_in_step(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                       y1: Vector, f1: Vector, Hs: float, k: int, scale: Vector
                       ) -> tuple[float, Vector, int] | None:
        """An event in the accepted step (0, Hs]: the least event function negative at its
        end, or at its midpoint by the cubic Hermite interpolant (a dip that returns by the
        end), then located; None if there is none."""
        if self._margin(y1) <= 0.0:
            return self._locate(sweep, u, y, f0, Hs, k, scale)
        if self._margin(self._hermite(y, f0, y1, f1, Hs, 0.5)) <= 0.0:
            return self._locate(sweep, u, y, f0, 0.5 * Hs, k, scale)
        return None

    def _locate(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                b: float, k: int, scale: Vector) -> tuple[float, Vector, int] | None:
        """The first event in (0, b] on the step re-integrated with k columns: (tau, state
        there, work); None when every event function is positive at b after all. Each event
        function is located on its own (Illinois, to 4 ulp of the time; their units differ,
        so their minimum is not located as one function): one that is not positive at b,
        then again before its zero while another is not positive there."""
        work = 0
        rigid = not self.model.law.compliant
        model = self.model

        def state(tau: float) -> Vector:
            nonlocal work
            yt, _, _, nfev = gbs.extrapolated_step(sweep, u, y, f0, tau, scale, k_fixed=k)
            work += RHS_WORK * nfev + STEP_WORK
            if rigid:
                model.project(yt)
            return yt

        start = [v for _, v in model.events(y)]
        yb = state(b)
        ends = [v for _, v in model.events(yb)]
        neg = [i for i, v in enumerate(ends) if v <= 0.0]
        if not neg:
            return None
        for _ in range(len(start)):
            i = neg[0]

            def at(x: float, i: int = i) -> tuple[float, Vector]:
                yt = state(x)
                return model.events(yt)[i][1], yt

            _, b, yb = illinois(at, 0.0, start[i], b, ends[i], yb,
                                lambda a, b, fb: b - a <= 4.0 * math.ulp(u + b) or fb == 0.0,
                                ROOT_ITERS)
            ends = [v for _, v in model.events(yb)]
            neg = [j for j, v in enumerate(ends) if v <= 0.0 and j != i]
            if not neg:
                break
        return b, yb, work
