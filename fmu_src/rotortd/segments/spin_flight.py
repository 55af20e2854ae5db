"""Free flight of a rigid rotor whose spin speed is a state
(docs/model.md §8, "Segments and their errors").

Frame and units: inertial, SI. State: geometric centre ``z`` (m, complex), ``v = z'`` (m/s),
spin angle ``psi`` (rad, unwrapped) and ``Omega = psi'`` (rad/s). With E = e^{i(psi + phi)},
F = a (F_bias - c v - k z) + F_ext (N, at the geometric centre):

    J Omega' = T_drive + e_c Im(conj(F) E)
    m z''    = F - i m g + m e_c (Omega^2 - i Omega') E        (i.e. m z_G'' = F - i m g)

``SpinFlight(...).run(rem, limit)`` advances at most ``rem`` seconds and stops at the first
contact with the clearance circle |z| = c_r.

Trajectory
----------
* Closed form (a == 0 and F_ext == 0, the drop scene; in general whenever F vanishes
  identically): the mass centre z_G = z + e_c E moves on a parabola and psi is quadratic,
  z(t) = z_G0 + z_G0' t - i g t^2/2 - e_c E0 e^{i(Omega0 t + alpha t^2/2)}, alpha =
  T_drive/J; evaluated directly at every point (no drift).
* Otherwise a Taylor method of order ORDER (24) with the coefficients from the recurrences of
  the ODE written for z_G (``_taylor``: two convolutions per order, conj(F) * E and
  Omega * E). Each step's length h makes the last two terms of the z and Omega series at most
  TAYLOR_TOL (1e-16) times their scales (c_r; max(|Omega|, w), w the flight's fastest rate),
  the Jorba-Zou criterion; with the series' geometric decay that bounds the truncation error
  of a step by about 2e-16 of the scale (an estimate from the tail, not an enclosure). The
  dense output is the Taylor polynomial itself (no extra RHS evaluations).
  Stated error: per step <= 2e-16 (truncation) plus the rounding of the series sums, i.e. a
  few eps, relative to c_r in position, to the step's velocity scale c_r w in velocity and
  to max(|Omega|, w) in Omega; over a flight it accumulates with the number of steps k as
  assumed by the search, RHO_INT + k RHO_STEP (8 eps + 2 eps per step). Measured against a
  40-digit mpmath Taylor integration in the model's own form (tests/test_spin_flight.py):
  dense output over 0.1 s (14 steps) within 1.2e-15 c_r in position, 1.0e-15 c_r w in
  velocity, 2.3e-16 relative in Omega; the tests require <= 1e-13 c_r and <= 1e-12.

Contact search (certificate)
----------------------------
The gap is G(t) = |z|^2/c_r^2 - 1 (dimensionless). At a point s, with z, v, a = z'',
j = z''' from the ODE at the point's state,

    G' = 2 Re(conj(z) v)/c_r^2,  G'' = 2(|v|^2 + Re(conj(z) a))/c_r^2,
    G''' = 2(3 Re(conj(v) a) + Re(conj(z) j))/c_r^2,
    |G''''| <= G4 = (6 A^2 + 8 V Jm + 2 c_r L)/c_r^2 on [s, s + tau],

where V, W, D, A, Jm, L bound |v|, |Omega|, |Omega'|, |z''|, |z'''|, |z''''| on [s, s + tau]
while |z| <= c_r (``bounds``: an a-priori bootstrap V >= |v(s)| + tau A(V, W), W >=
|Omega(s)| + tau D(V), checked after doubling the increments of two fixed-point sweeps,
tau halved until it holds; then the derivative chain of the ODE: |F'|, |Omega''|, |F''|,
|Omega'''|). As u^4/24 <= (tau/4) u^3/6, G(s + u) <= p(u) = G + G' u + G'' u^2/2 +
(G''' + G4 tau/4 + band) u^3/6 for u in [0, tau]; band = 16 eps of the bound of |G'''|
(rounding), and in the integrated case G, G', G'' get, in addition, the method's point
error 3 rho (rho = RHO_INT + k RHO_STEP relative, times the size of the coefficient's terms;
G''' gets 3 rho of its bound), which also widens the bands of the wall classification.
The step to p's first root (events.safe_step, the left end of its bracket) is safe: a
contact before it would be a first exit at which the bound, valid up to it, is negative.
Far from the wall tau = min(remaining, HORIZON/w) and the trajectory advances by tau. In the
closed form the whole flight is first tried at once: |z(t)| <= |z_G0| + |z_G0'| t + g t^2/2 +
e_c < c_r on [0, rem] proves it clear with one evaluation.

Resolution: a point is at the wall when G >= -TOL_G (16 eps: |z| within ~8 eps of c_r, a few
ulp). There: moving outward with a resolvable excursion (G' above its rounding band and
G + G'^2/(2|G''|) > TOL_G) is an impact, polished by Newton on G to |G| <= 4 eps (the contact
time is then within the conditioning limit eps c_r/rdot); G' zero to its band with the motion
curving outward (G'' above its band, or zero to it with G''' > 0) is a touch, also a contact;
moving inward continues with G clamped to 0; tangential with G'' <= 0 is a grazing pass that
steps on by a grace step (``_grace``: the time within which no excursion beyond TOL_G can be
resolved). So a crossing deeper than TOL_G can never be missed (closed form: rigorous up
to the rounding of the point evaluation, a few eps; integrated: as long as the method's
point error stays within the assumed rho, an estimate that the tests check, not an
enclosure), and a touch within a few ulp is either reported as contact or passed.

Work: one unit per point evaluation (a state with its z'' and z'''), one per bound
(``bounds``), one per bracket iteration of the safe step (events.Work.iters) and ORDER per
Taylor step (one per order of the recurrences). Deterministic: nothing depends on the clock.
Bound of the number of advances: an advance from a point with G < -TOL_G either moves by
its whole tau (= min(remaining, HORIZON/w), or less where the a-priori bootstrap halves it)
or to p's first root u*, and p must gain TOL_G there, so u* >= min(TOL_G/(3 G1+),
(2 TOL_G/(3 G2+))^(1/2), (2 TOL_G/c3+)^(1/3)) with G1+, G2+, c3+ the positive parts, all
bounded on [0, rem] by the same bounds (the bracket returns at least (1 - 1e-6) u*); at the
wall, an exit ends the flight, a departure is followed by a step of at least the root of
G' + G'' u/2 + c3 u^2/6, and a grace step is >= (6 TOL_G/G3max)^(1/3). So the count is finite
for any finite input. That bound is loose; in practice a transversal approach converges in
3-6 advances (fourth order), a near-graze is passed in about 6 (the distance to the
tangency point squares each advance) and a drop-scene flight (1-10 ms, Omega ~ 180 rad/s)
takes 35 work units, 3.1e5 instructions (callgrind), 30 us on average (closed form; 200
random flights after an impact, CPython 3.11), and with the bearing on (Taylor; median flight
16 ms) 131 units, 3.9e6 instructions, ~0.37 ms. ``limit`` caps it all: ContactWorkExceeded
(with the units used) as soon as the count passes it.
"""

from __future__ import annotations

import bisect
import cmath
import math
from operator import mul

from ..bodies.bearing import CounterBody
from ..contact.events import CONTACT
from ..contact.search import WORK_MAX, Work, _negative_throughout, safe_step
from ..contact.wall import ContactWorkExceeded, SegmentEnd
from ..params import RotorParams

EPS = 2.220446049250313e-16
TINY = 5e-324
TOL_G = 16.0 * EPS
"""Contact resolution of G = |z|^2/c_r^2 - 1: G >= -TOL_G is at the wall (|z| within ~8 eps)."""
POLISH_G = 4.0 * EPS
"""Newton on G stops once |G| <= POLISH_G."""
HORIZON = 0.5
"""Longest interval one bound covers, in units of 1/w (w the flight's fastest rate)."""
ORDER = 24
"""Order of the Taylor method (integrated case)."""
POINT_WORK = 2
"""Work units per point evaluation (a state with its second and third derivatives)
and per bound."""
TAYLOR_WORK = 2 * ORDER
"""Work units per Taylor step (its recurrences). Two units per point and two per order
keep the time of a unit near the held core's (docs/model.md 7): at one unit each the
integrated flight measured 2.9 us per unit, against 1.0-1.9 us for the held core."""
DENSE_WORK = ORDER // 3
"""Work units per integrated point beyond POINT_WORK: the dense output evaluates five
Taylor polynomials of ORDER terms (measured 15 us per point; 8 more units keep it near the
held core's time per unit; FMU fuzz case 157 ran 10,143 impacts of integrated flights in
one step at 2.1 us per unit before)."""
TAYLOR_TOL = 1e-16
"""Tail tolerance of a Taylor step, relative to the scales c_r (z) and max(|Omega|, w) (Omega)."""
STEP_MAX = 256.0
"""Longest Taylor step, in units of 1/w (reached only by series that end early)."""
RHO_INT = 8.0 * EPS
"""Relative point error of the integrated state in the flight's first Taylor step (its
truncation plus the rounding of the series), which the search adds to its bound."""
RHO_STEP = 2.0 * EPS
"""Growth of that point error per Taylor step (accumulated rounding and truncation): the
point error assumed in step k (from 0) is RHO_INT + k RHO_STEP. Measured: the error of the
dense output stays below 6 eps (1.2e-15 c_r) over 14 steps (0.1 s) in tests/test_spin_flight.py
scenes, against the 36 eps assumed there."""


def free_acceleration(F: complex, m: float, g: float, e_c: float, J: float, T: float,
                      Omega: float, E: complex) -> tuple[complex, float]:
    """(z'' (m/s^2), Omega' (rad/s^2)) of the rotor in free flight, its spin a state, SI,
    inertial: F (N) the bearing and external force at the geometric centre, m (kg), g
    (m/s^2), e_c (m), J (kg m^2), T the drive torque (N m), Omega (rad/s) and E =
    e^{i(psi + phi)}. From m z_G'' = F - i m g, z_G = z + e_c E, and J Omega' = T +
    e_c Im(conj(F) E)."""
    dOmega = (T + e_c * (F.conjugate() * E).imag) / J
    return F / m - 1j * g + e_c * complex(Omega * Omega, -dOmega) * E, dOmega


class SpinFlight:
    """One free flight from (z, v, psi, Omega) under inputs held constant (module docstring).

    p: rotor parameters; J: polar inertia about the mass centre (kg m^2, > 0); a: AMB on in
    [0, 1]; F_ext: external force at the geometric centre (N, complex, without gravity);
    T_drive: drive torque (N m). ``force_integration`` uses the Taylor method even when the
    closed form applies (for tests). ``bearing``: the counter-body (``rotortd.bodies.bearing``);
    None is the chapter's, fixed at the origin. When its centre moves (``bearing.moves``)
    the search follows the gap to it, G = |z - c(s)|^2/c_r^2 - 1, with the bounds of its
    path added to the rotor's (|z - c| <= c_r, |z| <= c_r + |c|).
    """

    __slots__ = ("E0", "F0", "F0_abs", "F_ext", "J", "Om0", "Om_scale", "T", "_k", "_limit",
                 "_starts", "_steps", "a", "alpha", "bearing", "cA", "closed", "cr", "ec",
                 "f0m", "f0m_abs", "g", "horizon", "kA", "m", "moving", "p", "psi0", "v0", "w",
                 "wG0", "z0", "zG0")
    # (slots: more attributes than an instance's shared-key dict holds; without them every
    # run's self._limit rebuilt the instance's dict, +3 % of a closed-form flight's step)

    def __init__(
        self,
        p: RotorParams,
        J: float,
        a: float,
        F_ext: complex,
        T_drive: float,
        z: complex,
        v: complex,
        psi: float,
        Omega: float,
        *,
        force_integration: bool = False,
        bearing: CounterBody | None = None,
    ) -> None:
        _check_finite(J, a=a, F_ext=F_ext, T_drive=T_drive, z=z, v=v, psi=psi, Omega=Omega)
        self.p = p
        self.J = float(J)
        self.a = float(a)
        self.F_ext = complex(F_ext)
        self.T = float(T_drive)
        self.z0, self.v0 = complex(z), complex(v)
        self.psi0, self.Om0 = float(psi), float(Omega)
        self.cr = p.c_r
        self.ec = p.e_c
        self.m = p.m
        self.g = p.g
        self.E0 = cmath.exp(1j * (self.psi0 + p.phi))
        self.alpha = self.T / self.J
        # F = F0 - ac v - ak z (N); z_G'' = F/m - i g
        self.F0 = self.a * p.bias_force + self.F_ext
        self.cA = self.a * p.c
        self.kA = self.a * p.k
        # closed form whenever F vanishes identically (a == 0 and F_ext == 0, or a bearing
        # with c = k = 0 and no bias)
        self.closed = (self.F0 == 0j and self.cA == 0.0 and self.kA == 0.0
                       and not force_integration)
        self.f0m = self.F0 / self.m - 1j * self.g  # constant part of z_G'' (m/s^2)
        self.f0m_abs = abs(self.f0m)
        self.F0_abs = abs(self.F0)
        self.bearing = bearing
        self.moving = bearing is not None and bearing.moves
        self.w = w = self._rate_scale()
        if self.moving:
            self.w = w = max(w, bearing.rate)
        self.horizon = HORIZON / w
        self.Om_scale = max(abs(self.Om0), w)
        if self.closed:
            self.zG0 = self.z0 + self.ec * self.E0
            self.wG0 = self.v0 + 1j * self.ec * self.Om0 * self.E0
        else:
            self._steps: list[tuple[float, float,
                                    list[tuple[complex, complex, complex, float, float]],
                                    float]] = []
            self._starts: list[float] = []
            self._k = 0  # index of the Taylor step of the last dense point

    def _rate_scale(self) -> float:
        """The flight's rate scale w (rad/s): the largest of the spin, the speed over c_r,
        the bearing's rates, the forces' and the drive's."""
        cr = self.cr
        return max(
            abs(self.Om0),
            abs(self.v0) / cr,
            math.sqrt(self.kA / self.m),
            self.cA / self.m,
            math.sqrt((self.f0m_abs + self.ec * abs(self.Om0) ** 2) / cr),
            abs(self.alpha) ** 0.5,
            math.sqrt(self.ec * (self.F0_abs + self.kA * cr) / self.J),
            1e-9,
        )

    # ---------------------------------------------------------------- trajectory
    def state(self, s: float, work: Work) -> tuple[complex, complex, float, float, complex]:
        """(z, v, psi - psi0, Omega, E) at local time s (s >= 0), m, m/s, rad, rad/s."""
        work.evals += POINT_WORK
        if self.closed:
            Om0, al = self.Om0, self.alpha
            dpsi = s * (Om0 + 0.5 * al * s)
            E = self.E0 * cmath.exp(1j * dpsi)
            Om = Om0 + al * s
            ec = self.ec
            z = self.zG0 + s * (self.wG0 - 0.5j * self.g * s) - ec * E
            v = self.wG0 - 1j * self.g * s - 1j * ec * Om * E
            return z, v, dpsi, Om, E
        return self._dense(s, work)

    def derivs(self, z: complex, v: complex, Om: float, E: complex) -> tuple[complex, complex]:
        """(z'', z''') in m/s^2, m/s^3 from the ODE at the state (z, v, Omega, E)."""
        ec, J = self.ec, self.J
        F = self.F0 - self.cA * v - self.kA * z
        acc, Omd = free_acceleration(F, self.m, self.g, ec, J, self.T, Om, E)
        F1 = -self.cA * acc - self.kA * v
        Omdd = ec * (F1.conjugate() * E + F.conjugate() * (1j * Om) * E).imag / J
        jerk = F1 / self.m + ec * complex(3.0 * Om * Omd, Om * Om * Om - Omdd) * E
        return acc, jerk

    def _taylor(self, z0: complex, v0: complex, Om0: float, E0: complex
                ) -> tuple[list[complex], list[complex], list[float]]:
        """Taylor coefficients (z_k, E_k, Omega_k) of the flight from (z0, v0, Omega0, E0).

        With z_G = z + e_c E: (k+1)(k+2) zG_{k+2} = F_k/m - i g [k=0], F_k = F0 [k=0] -
        a c (k+1) z_{k+1} - a k z_k; (k+1) J Omega_{k+1} = T [k=0] + e_c Im(sum conj(F_j)
        E_{k-j}); (k+2) E_{k+2} = i sum Omega_j E_{k+1-j}."""
        N = ORDER
        ec, m, cA, kA, J = self.ec, self.m, self.cA, self.kA, self.J
        zc = [z0, v0]
        Ec = [E0, 1j * Om0 * E0]
        Oc = [Om0]
        Fc: list[complex] = []  # conj(F_k)
        for k in range(N - 1):
            Fk = -cA * (k + 1) * zc[k + 1] - kA * zc[k]
            if k == 0:
                Fk += self.F0
            Fc.append(Fk.conjugate())
            tq = ec * sum(map(mul, Fc, Ec[k::-1])).imag
            if k == 0:
                tq += self.T
            Oc.append(tq / (J * (k + 1)))
            Ek2 = (1j / (k + 2)) * sum(map(mul, Oc, Ec[k + 1::-1]))
            Ec.append(Ek2)
            zG = Fk / m
            if k == 0:
                zG -= 1j * self.g
            zc.append(zG / ((k + 1) * (k + 2)) - ec * Ek2)
        return zc, Ec, Oc

    def _new_step(self, work: Work) -> None:
        """Append the next Taylor step (from the end of the last one, or the start)."""
        if work.total > self._limit:
            raise ContactWorkExceeded(
                f"free flight: work bound {self._limit} reached in the Taylor integration",
                work=work.total)
        if self._steps:
            t0, h = self._steps[-1][0], self._steps[-1][1]
            z, v, dpsi, Om, _ = self._poly(self._steps[-1], h)
        else:
            t0, h, z, v, dpsi, Om = 0.0, 0.0, self.z0, self.v0, 0.0, self.Om0
        E = self.E0 * cmath.exp(1j * dpsi)
        zc, Ec, Oc = self._taylor(z, v, Om, E)
        work.evals += TAYLOR_WORK
        N = ORDER
        hz = _tail_step(abs(zc[N - 1]), abs(zc[N]), TAYLOR_TOL * self.cr, N)
        ho = _tail_step(abs(Oc[N - 2]), abs(Oc[N - 1]), TAYLOR_TOL * self.Om_scale, N - 1)
        hstep = min(hz, ho, STEP_MAX / self.w)
        t1 = t0 + h
        # Horner rows from the top degree N down to 0: z, v = z', E, Omega, psi - psi(t1)
        rows = list(zip(
            zc[::-1],
            [0j, *(k * zc[k] for k in range(N, 0, -1))],
            Ec[::-1],
            [0.0, *Oc[::-1]],
            [*(Oc[k - 1] / k for k in range(N, 0, -1)), 0.0],
        ))
        self._steps.append((t1, hstep, rows, dpsi))
        self._starts.append(t1)

    @staticmethod
    def _poly(step: tuple[float, float, list[tuple[complex, complex, complex, float, float]],
                          float],
              u: float) -> tuple[complex, complex, float, float, complex]:
        """Evaluate a Taylor step at local offset u: (z, v, dpsi, Omega, E) by Horner."""
        z = v = E = 0j
        Om = ps = 0.0
        for cz, cv, cE, cO, cp in step[2]:
            z = z * u + cz
            v = v * u + cv
            E = E * u + cE
            Om = Om * u + cO
            ps = ps * u + cp
        return z, v, step[3] + ps, Om, E

    def _dense(self, s: float, work: Work) -> tuple[complex, complex, float, float, complex]:
        """The integrated state at s from the Taylor step that covers it."""
        while not self._steps or s > self._steps[-1][0] + self._steps[-1][1]:
            self._new_step(work)
        i = max(bisect.bisect_right(self._starts, s) - 1, 0)
        self._k = i
        step = self._steps[i]
        work.evals += DENSE_WORK
        return self._poly(step, s - step[0])

    # ---------------------------------------------------------------- bounds
    def bounds(self, V0: float, W0: float, tau: float, s: float = 0.0
               ) -> tuple[float, float, float]:
        """(tau', G3max, G4max): on [s, s + tau'] (tau' <= tau, while |z - c| <= c_r), with
        |v(s)| = V0 and |Omega(s)| = W0, |G'''| <= G3max and |G''''| <= G4max (1/s^3, 1/s^4).
        With a moving counter-body its path's bounds on [s, s + tau] are added."""
        ec, J, cr, m = self.ec, self.J, self.cr, self.m
        cA, kA = self.cA, self.kA
        if self.moving:
            assert self.bearing is not None
            Cb, Vb, Ab, Jb, Lb = self.bearing.path_bounds(s, tau)
            kA = kA * (cr + Cb) / cr  # |z| <= c_r + |c| in the spring's force
        T = abs(self.T)
        if self.closed:
            W = W0 + tau * abs(self.alpha)
            D = abs(self.alpha)
            A = self.g + ec * (W * W + D)
            V = V0 + tau * A
            Fm = F1 = F2 = B2 = B3 = 0.0
        else:
            for _ in range(200):
                V, W = V0, W0
                for _ in range(2):
                    Fm = self.F0_abs + cA * V + kA * cr
                    D = (T + ec * Fm) / J
                    A = self.f0m_abs + (cA * V + kA * cr) / m + ec * (W * W + D)
                    V, W = V0 + tau * A, W0 + tau * D
                V, W = 2.0 * V - V0 + TINY, 2.0 * W - W0 + TINY  # twice the increments
                Fm = self.F0_abs + cA * V + kA * cr
                D = (T + ec * Fm) / J
                A = self.f0m_abs + (cA * V + kA * cr) / m + ec * (W * W + D)
                if V0 + tau * A <= V and W0 + tau * D <= W:
                    break
                tau *= 0.5
            else:
                raise ContactWorkExceeded(
                    f"free flight: no a-priori bound of the motion from |v| = {V0!r} m/s, "
                    f"|Omega| = {W0!r} rad/s within 2^-200 of the horizon", work=0)
            F1 = cA * A + kA * V
            B2 = ec * (F1 + Fm * W) / J
        Jm = F1 / m + ec * (3.0 * W * D + B2 + W * W * W)
        if not self.closed:
            F2 = cA * Jm + kA * A
            B3 = ec * (F2 + 2.0 * F1 * W + Fm * (D + W * W)) / J
        WD = W * W + D
        L = F2 / m + ec * (2.0 * D * D + 2.0 * W * B2 + B3 + 2.0 * W * (2.0 * W * D + B2)
                           + WD * WD)
        if self.moving:  # the relative motion z - c
            V, A, Jm, L = V + Vb, A + Ab, Jm + Jb, L + Lb
        c2 = cr * cr
        G3 = (6.0 * V * A + 2.0 * cr * Jm) / c2
        G4 = (6.0 * A * A + 8.0 * V * Jm + 2.0 * cr * L) / c2
        return tau, G3, G4

    # ---------------------------------------------------------------- search
    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Advance at most ``rem`` s; stop at the first contact; raise ContactWorkExceeded
        (with ``work``) if more than ``limit`` work units would be needed."""
        if not rem >= 0.0:
            raise ValueError(f"rem = {rem!r} s: it must be >= 0")
        work = Work()
        self._limit = limit
        if self.closed and not self.moving:
            return self._run_closed(rem, limit, work)
        if not self.closed and not self.moving and rem <= self.horizon:
            end = self._run_quiet(rem, limit)  # a short flight proved clear at once
            if end is not None:
                return end
        moving, path = self.moving, self.bearing.path if self.moving else None
        if not self.closed:  # (a closed form searched against a moving counter-body)
            self._steps.clear()  # every run integrates afresh: work independent of history
            self._starts.clear()
        self._k = 0
        cr = self.cr
        ic2 = 1.0 / (cr * cr)
        s = 0.0
        z, v, dpsi, Om, E = self.state(0.0, work)
        while True:
            if work.total > limit:
                raise ContactWorkExceeded(
                    f"free flight: work bound {limit} reached at t = {s!r} s of {rem!r} s",
                    work=work.total)
            acc, jerk = self.derivs(z, v, Om, E)
            rho = RHO_INT + RHO_STEP * self._k
            if moving:  # the motion relative to the counter-body's centre
                c, c1, c2, c3 = path(s)
                zr, vr, acc, jerk = z - c, v - c1, acc - c2, jerk - c3
            else:
                zr, vr = z, v
            zc = zr.conjugate()
            g0 = (zr * zc).real * ic2 - 1.0
            g1 = 2.0 * (zc * vr).real * ic2
            g2 = 2.0 * ((vr * vr.conjugate()).real + (zc * acc).real) * ic2
            g3 = 2.0 * (3.0 * (vr.conjugate() * acc).real + (zc * jerk).real) * ic2
            az, av = abs(zr), abs(vr)
            M1 = 2.0 * az * av * ic2
            M2 = 2.0 * (av * av + az * abs(acc)) * ic2
            if g0 + 3.0 * rho >= -TOL_G:  # at the wall to resolution and the point error
                kind = self._at_wall(g0, g1, g2, g3, M1, M2, 3.0 * rho)
                if kind == "impact":
                    if s == 0.0:
                        return self._end(0.0, z, v, dpsi, Om, CONTACT, work)
                    return self._polish(s, z, v, dpsi, Om, rem, work)
                if kind == "touch":
                    return self._end(s, z, v, dpsi, Om, CONTACT, work)
                if kind == "graze":
                    if s >= rem:
                        return self._end(rem, z, v, dpsi, Om, None, work)
                    s = min(rem, s + self._grace(v, Om, g3, work, s))
                    z, v, dpsi, Om, E = self.state(s, work)
                    continue
                # leaving the wall (G' < -its band, which holds the point error)
                g0, g1, g2 = 0.0, g1 + 3.0 * rho * M1, g2 + 3.0 * rho * M2
            else:  # the point error, in every coefficient of the bound
                g0 += 3.0 * rho
                g1 += 3.0 * rho * M1
                g2 += 3.0 * rho * M2
            remaining = rem - s
            if remaining <= 0.0:
                return self._end(rem, z, v, dpsi, Om, None, work)
            work.evals += POINT_WORK
            tau, G3m, G4m = self.bounds(abs(v) if moving else av, abs(Om),
                                        min(remaining, self.horizon), s)
            c3 = g3 + 0.25 * tau * G4m + (16.0 * EPS + 3.0 * rho) * G3m + TINY
            u = safe_step(g0, g1, g2, c3, tau, work)
            if u is None:
                u = tau
            elif u <= 0.0:  # on the wall, nothing moving it: a touch
                return self._end(s, z, v, dpsi, Om, CONTACT, work)
            s = s + u if u < remaining else rem
            z, v, dpsi, Om, E = self.state(s, work)

    def _run_quiet(self, rem: float, limit: int) -> SegmentEnd | None:
        """``run`` of a short integrated flight (rem <= the horizon) proved clear of the wall
        by one bound, then advanced by one Taylor expansion of the order rem needs
        (``short_taylor``); None when either fails (the caller runs the general search,
        whose work then starts afresh). The proof is the general loop's first bound with
        TOL_G added to G: p(u) + TOL_G < 0 on [0, rem], so no point of the step, its end
        included, is within the contact resolution (docs/model.md 8, "Quiet steps")."""
        work = Work()
        z, v, Om, E = self.z0, self.v0, self.Om0, self.E0
        work.evals += POINT_WORK
        acc, jerk = self.derivs(z, v, Om, E)
        ic2 = 1.0 / (self.cr * self.cr)
        zc = z.conjugate()
        vc = v.conjugate()
        az, av = abs(z), abs(v)
        err = 3.0 * RHO_INT  # the point error of the expansion, as the general loop's
        g0 = (z * zc).real * ic2 - 1.0 + err + TOL_G
        if g0 >= 0.0:
            return None
        g1 = 2.0 * ((zc * v).real + err * az * av) * ic2
        g2 = 2.0 * ((v * vc).real + (zc * acc).real + err * (av * av + az * abs(acc))) * ic2
        g3 = 2.0 * (3.0 * (vc * acc).real + (zc * jerk).real) * ic2
        work.evals += POINT_WORK
        tau, G3m, G4m = self.bounds(av, abs(Om), rem)
        if tau < rem:
            return None
        c3 = g3 + 0.25 * rem * G4m + (16.0 * EPS + err) * G3m + TINY
        if not _negative_throughout(g0, g1, g2, c3, rem):
            return None
        end = self.short_taylor(rem)
        if end is None:
            return None
        z, v, dpsi, Om, n = end
        work.evals += 2 * n + POINT_WORK
        if work.total > limit:
            return None
        return SegmentEnd(rem, z=z, v=v, psi=self.psi0 + dpsi, Omega=Om, work=work.total)

    def short_taylor(self, h: float) -> tuple[complex, complex, float, float, int] | None:
        """(z, v, psi - psi0, Omega, n) at h (s) from the start, by the Taylor series of
        the order n that h needs: the recurrences of ``_taylor`` written for the
        coefficients times h^k (Z_k = z_k h^k, ...), stopped at the first order whose last
        two terms of the z and Omega series are at most TAYLOR_TOL times their scales (the
        criterion of a Taylor step of ``_new_step``, met at h itself); None when ORDER
        does not reach it (docs/model.md 8, "Quiet steps")."""
        ec, kA = self.ec, self.kA
        tol_z, tol_o = TAYLOR_TOL * self.cr, TAYLOR_TOL * self.Om_scale
        E0, Om0, z0 = self.E0, self.Om0, self.z0
        cAh, hJe, ih = self.cA / h, h * ec / self.J, 1j * h
        h2m = h * h / self.m
        Z1 = self.v0 * h
        Zs = [z0, Z1]
        E1 = ih * Om0 * E0
        Er = [E1, E0]  # the E series, newest first: the convolutions need no slicing
        F0c = (self.F0 - cAh * Z1 - kA * z0).conjugate()
        Fc = [F0c]  # conj(F_k h^k)
        O1 = h * (self.T + ec * (F0c * E0).imag) / self.J
        Os = [Om0, O1]
        E2 = 0.5j * h * (Om0 * E1 + O1 * E0)
        Er.insert(0, E2)
        Zs.append(0.5 * h2m * (F0c.conjugate() - 1j * self.m * self.g) - ec * E2)
        for k in range(1, ORDER - 1):
            Fk = -cAh * (k + 1) * Zs[k + 1] - kA * Zs[k]
            Fc.append(Fk.conjugate())
            Ok = hJe * sum(map(mul, Fc, Er[1:])).imag / (k + 1)
            Os.append(Ok)
            Ek2 = (ih / (k + 2)) * sum(map(mul, Os, Er))
            Er.insert(0, Ek2)
            Zk2 = h2m * Fk / ((k + 1) * (k + 2)) - ec * Ek2
            Zs.append(Zk2)
            if (abs(Zk2) <= tol_z and abs(Ok) <= tol_o and abs(Zs[k + 1]) <= tol_z
                    and abs(Os[k]) <= tol_o):
                break
        else:
            return None
        n = len(Zs) - 1
        z = v = 0j
        for j in range(n, 0, -1):  # the small terms first
            z += Zs[j]
            v += j * Zs[j]
        Om = ps = 0.0
        for j in range(len(Os) - 1, -1, -1):
            Om += Os[j]
            ps += Os[j] / (j + 1)
        return z + z0, v / h, h * ps, Om, n

    def _run_closed(self, rem: float, limit: int, work: Work) -> SegmentEnd:
        """``run`` for the closed form: the same steps as the general loop, with the point
        (``state``, ``derivs``) and the bound (``bounds``) evaluated inline (the drop scene
        runs this every flight; tests compare it with the forced Taylor path)."""
        cr = self.cr
        ic2 = 1.0 / (cr * cr)
        ec, g, al, Om0, E0 = self.ec, self.g, self.alpha, self.Om0, self.E0
        zG0, wG0 = self.zG0, self.wG0
        aal = abs(al)
        ig = 1j * g
        horizon = self.horizon
        exp = cmath.exp
        band3 = 16.0 * EPS
        s = 0.0
        work.evals += POINT_WORK
        # the whole flight at once: |z| <= |z_G0| + |z_G0'| t + g t^2/2 + e_c
        if abs(zG0) + rem * (abs(wG0) + 0.5 * g * rem) + ec < cr * (1.0 - 8.0 * EPS):
            z, v, dpsi, Om, _ = self.state(rem, work)
            return self._end(rem, z, v, dpsi, Om, None, work)
        dpsi = 0.0
        Om = Om0
        ecE = ec * E0
        z, v = self.z0, self.v0
        while True:
            if work.total > limit:
                raise ContactWorkExceeded(
                    f"free flight: work bound {limit} reached at t = {s!r} s of {rem!r} s",
                    work=work.total)
            acc = complex(Om * Om, -al) * ecE - ig
            jerk = complex(3.0 * Om * al, Om * Om * Om) * ecE
            zc = z.conjugate()
            vc = v.conjugate()
            g0 = (z * zc).real * ic2 - 1.0
            g1 = 2.0 * (zc * v).real * ic2
            g2 = 2.0 * ((v * vc).real + (zc * acc).real) * ic2
            g3 = 2.0 * (3.0 * (vc * acc).real + (zc * jerk).real) * ic2
            av = abs(v)
            if g0 >= -TOL_G:
                az = abs(z)
                M1 = 2.0 * az * av * ic2
                M2 = 2.0 * (av * av + az * abs(acc)) * ic2
                kind = self._at_wall(g0, g1, g2, g3, M1, M2)
                if kind == "impact":
                    if s == 0.0:
                        return self._end(0.0, z, v, dpsi, Om, CONTACT, work)
                    return self._polish(s, z, v, dpsi, Om, rem, work)
                if kind == "touch":
                    return self._end(s, z, v, dpsi, Om, CONTACT, work)
                if kind == "graze":
                    if s >= rem:
                        return self._end(rem, z, v, dpsi, Om, None, work)
                    s = min(rem, s + self._grace(v, Om, g3, work))
                    z, v, dpsi, Om, E = self.state(s, work)
                    ecE = ec * E
                    continue
                g0, g1 = 0.0, min(g1, 0.0)  # leaving the wall
            remaining = rem - s
            if remaining <= 0.0:
                return self._end(rem, z, v, dpsi, Om, None, work)
            # bounds(), closed form
            work.evals += POINT_WORK
            tau = remaining if remaining < horizon else horizon
            W = abs(Om) + tau * aal
            A = g + ec * (W * W + aal)
            V = av + tau * A
            W2 = W * W
            Jm = ec * W * (3.0 * aal + W2)
            L = ec * (3.0 * aal * aal + W2 * (6.0 * aal + W2))
            G3m = (6.0 * V * A + 2.0 * cr * Jm) * ic2
            G4m = (6.0 * A * A + 8.0 * V * Jm + 2.0 * cr * L) * ic2
            c3 = g3 + 0.25 * tau * G4m + band3 * G3m + TINY
            u = safe_step(g0, g1, g2, c3, tau, work)
            if u is None:
                u = tau
            elif u <= 0.0:  # on the wall, nothing moving it: a touch
                return self._end(s, z, v, dpsi, Om, CONTACT, work)
            s = s + u if u < remaining else rem
            # state(s), closed form
            work.evals += POINT_WORK
            dpsi = s * (Om0 + 0.5 * al * s)
            ecE = ec * (E0 * exp(1j * dpsi))
            Om = Om0 + al * s
            z = zG0 + s * (wG0 - 0.5 * ig * s) - ecE
            v = wG0 - ig * s - 1j * Om * ecE

    @staticmethod
    def _at_wall(g0: float, g1: float, g2: float, g3: float, M1: float, M2: float,
                 err: float = 0.0) -> str:
        """Classify a point at the wall: "impact", "touch", "leave" or "graze". g0..g3: G and
        its derivatives; M1, M2: the sizes of the terms of G' and G''; err: the relative
        point error of the state (integrated case), which widens the bands of G' and G''."""
        tol1 = (16.0 * EPS + err) * M1 + 1e-300
        tol2 = (64.0 * EPS + err) * M2 + 1e-300
        if g1 > tol1 and (g2 >= 0.0 or g0 + g1 * g1 / (-2.0 * g2) > TOL_G):
            return "impact"  # outward, with an excursion beyond the wall above resolution
        if g1 < -tol1:
            return "leave"
        if g2 > tol2 or (g2 >= -tol2 and g3 > 0.0):
            return "touch"
        return "graze"

    def _grace(self, v: complex, Om: float, g3: float, work: Work, s: float = 0.0) -> float:
        """Step (s) past a tangential point (G within TOL_G of 0, G' within its band, G'' <= 0
        to its band): the larger of (a) the time within which the bound of |G'''| cannot move
        G by TOL_G, and (b) when G''' < 0, the time the cubic term needs to bring G 8 TOL_G
        inside, capped at 2|G'''|/G4max so that the quartic term stays below half of it.
        Within it no excursion beyond the resolution can form."""
        work.evals += POINT_WORK
        tau, G3m, G4m = self.bounds(abs(v), abs(Om), self.horizon, s)
        t_bound = (6.0 * TOL_G / max(G3m, 1e-300)) ** (1.0 / 3.0)
        t_cubic = 0.0
        if g3 < 0.0:
            t_cubic = min((48.0 * TOL_G / -g3) ** (1.0 / 3.0), 2.0 * -g3 / max(G4m, 1e-300))
        return min(max(t_bound, t_cubic), tau)

    def _polish(self, s: float, z: complex, v: complex, dpsi: float, Om: float, rem: float,
                work: Work) -> SegmentEnd:
        """Newton on G from a point within TOL_G of the wall moving outward; best point."""
        ic2 = 1.0 / (self.cr * self.cr)
        g0, g1 = self._gap(s, z, v, ic2)
        best = (abs(g0), s, z, v, dpsi, Om)
        for _ in range(6):
            if g1 <= 0.0 or abs(g0) <= POLISH_G:
                break
            s_new = s - g0 / g1
            if s_new == s:
                break
            s = s_new
            z, v, dpsi, Om, _ = self.state(s, work)
            g0, g1 = self._gap(s, z, v, ic2)
            if abs(g0) < best[0]:
                best = (abs(g0), s, z, v, dpsi, Om)
        _, s, z, v, dpsi, Om = best
        if s > rem:  # the root lies beyond the segment: end there, just inside the wall
            z, v, dpsi, Om, _ = self.state(rem, work)
            return self._end(rem, z, v, dpsi, Om, None, work)
        return self._end(s, z, v, dpsi, Om, CONTACT, work)

    def _gap(self, s: float, z: complex, v: complex, ic2: float) -> tuple[float, float]:
        """(G, G') at s of the rotor's (z, v): the gap to the counter-body's circle."""
        if self.moving:
            assert self.bearing is not None
            c, c1, _, _ = self.bearing.path(s)
            z, v = z - c, v - c1
        zc = z.conjugate()
        return (z * zc).real * ic2 - 1.0, 2.0 * (zc * v).real * ic2

    def _end(self, s: float, z: complex, v: complex, dpsi: float, Om: float,
             event: str | None, work: Work) -> SegmentEnd:
        """The segment's end at s; a contact's z is projected onto the circle."""
        if event is CONTACT and self.moving:
            assert self.bearing is not None
            c = self.bearing.path(s)[0]
            r = abs(z - c)
            if r > 0.0:
                z = c + (z - c) * (self.cr / r)
        elif event is CONTACT:
            r = abs(z)
            if r > 0.0:
                z = z * (self.cr / r)
        return SegmentEnd(s, event=event, z=z, v=v, psi=self.psi0 + dpsi, Omega=Om,
                          work=work.total)


def _check_finite(J: float, **values: complex) -> None:
    """ValueError unless J (kg m^2) is finite and > 0 and every value is finite."""
    if 0.0 < J < math.inf and cmath.isfinite(sum(values.values())):
        return  # (the common case at once: a finite sum has finite terms)
    if not (J > 0.0 and math.isfinite(J)):
        raise ValueError(f"J = {J!r} kg m^2: it must be finite and > 0")
    for name, x in values.items():
        if not cmath.isfinite(complex(x)):
            raise ValueError(f"{name} = {x!r} is not finite")


def _tail_step(a: float, b: float, tol: float, N: int) -> float:
    """Step h with a h^(N-1) <= tol and b h^N <= tol (inf when both coefficients are 0)."""
    h = math.inf
    if a > 0.0:
        h = (tol / a) ** (1.0 / (N - 1))
    if b > 0.0:
        h = min(h, (tol / b) ** (1.0 / N))
    return h
