"""Exact free flight of the rotor centre between events (docs/model.md §1).

Frame and units: inertial, SI. ``z`` (m) and ``v = z'`` (m/s) are complex. Over one
segment the inputs ``Omega`` (rad/s), ``F_ext`` (N) and the bearing state ``a`` are held,
so per unit mass

    z'' = -beta z' - kappa z + f0 + F1 e^{i psi(t)},   psi(t) = psi0 + Omega t,

with beta = a c/m (1/s), kappa = a k/m (1/s^2), f0 = (a F_bias - i m g + F_ext)/m (m/s^2)
and F1 = e_c Omega^2 e^{i phi} (m/s^2). With A = [[0, 1], [-kappa, -beta]] (real) and
eigenvalues l1, l2, Duhamel's formula gives for a flight of length s

    [z; v](s) = exp(A s) [z0; v0] + int_0^s exp(A r) dr [0; f0]
                + e^{i psi0} e^{i Omega s} int_0^s exp((A - i Omega) r) dr [0; F1].

All three matrix functions are written with divided differences of exp on the nodes
{l1 s, l2 s}, {0, l1 s, l2 s} and {0, (l1 - i Omega) s, (l2 - i Omega) s} (divdiff.py),
which are entire in the nodes: one code path covers k = 0, c = 0, critical damping,
(near-)resonance and Omega = 0 without dividing by anything that can vanish.

The imbalance reaction torque (``imb_integral``, ``imb_impulse``) needs the integral of the
co-rotating position, K(s) = int_0^s z(u) e^{-i Omega u} du (m s). Integrating Duhamel's
formula against e^{-i Omega u}, with a = (l1 - i Omega) s, b = (l2 - i Omega) s,
w = -i Omega s and g(A) = g(l1) I + g[l1, l2] (A - l1 I) for the first row:

    K = (s exp[0, a] - l1 s^2 exp[0, a, b]) z0 + s^2 exp[0, a, b] v0
        + s^3 exp[0, a, b, w] f0 + s^3 exp[0, 0, a, b] F1 E0,

again entire in the nodes (divdiff.dd4 for the four-node differences).
"""

from __future__ import annotations

import cmath
import math
from typing import NamedTuple

from ..params import RotorParams
from .divdiff import dd2, dd3, dd4

IMB_COND = 1e-2
"""imb_integral_ends solves for K from the flight's two ends only when |kappa - Omega^2 +
i beta Omega| >= IMB_COND (kappa + Omega^2 + beta |Omega|) (rounding amplified at most
100-fold); nearer resonance, or with kappa = Omega = 0, it uses the closed form."""
MODAL_GAIN = 4.0
"""Largest ratio of the modal amplitudes to the state's scale for which the search
evaluates the flight by modes (FlightModel.modes)."""


class FlightCoeffs(NamedTuple):
    """Coefficients of the flight map over a fixed length ``s`` (s), inertial frame, SI.

    z(s) = p11 z0 + p12 v0 + f0 qz0 + F1 E0 qzs,   v(s) = p21 z0 + p22 v0 + f0 qv0 + F1 E0 qvs,
    E0 = e^{i psi0}; ``rot`` = e^{i Omega s}.
    """

    s: float
    p11: float
    p12: float
    p21: float
    p22: float
    qz0: complex
    qv0: complex
    qzs: complex
    qvs: complex
    rot: complex


class ImbCoeffs(NamedTuple):
    """Coefficients of K(s) = int_0^s z(u) e^{-i Omega u} du (m s) over a flight of fixed
    length s (module docstring): K = kz z0 + kv v0 + kf f0 + kF F1 E0 (kz in s, kv in s^2,
    kf and kF in s^3), inertial frame."""

    kz: complex
    kv: complex
    kf: complex
    kF: complex


class ImbImpulse(NamedTuple):
    """The imbalance reaction's angular impulse over a free flight of fixed length s, as
    P_imb = Im(conj(E0) (bz z0 + bv v0 + b0) + bE) (N m s) with E0 = e^{i psi0}:
    P_imb = e_c Im(int conj(F_amb + F_ext) e^{i(psi + phi)} dt), F_amb = a (F_bias - c z' -
    k z) (FlightModel.imb_impulse). bz in N s, bv in N s^2, b0 and bE in N m s."""

    bz: complex
    bv: complex
    b0: complex
    bE: complex


class FlightModel:
    """Free flight under held inputs (inertial frame, SI); see the module docstring.

    Besides propagation it provides the bounds the event locator needs: with |z| <= c_r,
    |z''| <= beta |v| + K and |z'''| <= beta |z''| + kappa |v| + J, where
    K = kappa c_r + |f0| + |F1| (m/s^2) and J = |Omega| |F1| (m/s^3); and
    |z''''| <= beta |z'''| + kappa |z''| + L_rot with L_rot = |Omega| J (m/s^4).
    """

    _CACHE_SIZE = 8

    def __init__(self, params: RotorParams, Omega: float, F_ext: complex, amb: float) -> None:
        p = params
        self.params = p
        self.Omega = float(Omega)
        self.F_ext = complex(F_ext)
        self.amb = float(amb)
        self.beta = amb * p.c / p.m
        self.kappa = amb * p.k / p.m
        self.f0 = (amb * p.bias_force + p.gravity_force + self.F_ext) / p.m
        self.F1 = p.e_c * self.Omega * self.Omega * cmath.exp(1j * p.phi)
        self.c_r = p.c_r
        self.l1, self.l2 = _eigenvalues(self.beta, self.kappa)
        self.decay_rate = -max(self.l1.real, self.l2.real)
        """Slowest decay rate of the transient (1/s); 0 without stiffness or damping."""
        self.K = self.kappa * p.c_r + abs(self.f0) + abs(self.F1)
        self.J = abs(self.Omega) * abs(self.F1)
        self.L_rot = abs(self.Omega) * self.J
        """Omega^2 |F1| (m/s^4): the rotating force's term in the bound of |z''''|."""
        b, k, K, J, c = self.beta, self.kappa, self.K, self.J, p.c_r
        self.g3_poly = (2.0 * c * (b * K + J), 6.0 * K + 2.0 * c * (b * b + k), 6.0 * b)
        """(s0, s1, s2): events.g3_bound's 6 V A + 2 c_r Jm = s0 + s1 V + s2 V^2 (m^2/s^3),
        expanded in the speed bound V (m/s); every coefficient is >= 0."""
        self.g4_poly = (
            6.0 * K * K + 2.0 * c * (b * b * K + b * J + k * K + self.L_rot),
            20.0 * b * K + 8.0 * J + 2.0 * c * (b * b * b + 2.0 * b * k),
            14.0 * b * b + 8.0 * k,
        )
        """(q0, q1, q2): events.g3_slack's 6 A^2 + 8 V Jm + 2 c_r L = q0 + q1 V + q2 V^2
        (m^2/s^4), expanded in V; every coefficient is >= 0."""
        self.rate = max(abs(self.Omega), self.kappa**0.5, self.beta, (self.K / p.c_r) ** 0.5)
        """Fastest rate of the forced motion (rad/s): |Omega|, sqrt(kappa), beta and
        sqrt(K/c_r), the rate at which the largest force crosses the clearance."""
        self._cache: dict[float, FlightCoeffs] = {}
        self._imb_cache: dict[float, ImbImpulse] = {}
        W = self.Omega
        self._imb_den = complex(self.kappa - W * W, self.beta * W)
        """kappa - Omega^2 + i beta Omega (1/s^2): imb_integral_ends divides by it."""
        self._imb_ends = self._imb_den != 0 and abs(self._imb_den) >= IMB_COND * (
            self.kappa + W * W + self.beta * abs(W))
        """imb_integral_ends may use the flight's ends (else the closed form imb_integral)."""
        self.imb_eph = cmath.exp(1j * p.phi)
        """e^{i phi}, the imbalance's phase factor."""

    # -- propagation --------------------------------------------------------------------

    def coeffs(self, s: float, cache: bool = False) -> FlightCoeffs:
        """Flight-map coefficients for length ``s`` >= 0 (s); cached when ``cache``."""
        hit = self._cache.get(s)
        if hit is not None:
            return hit
        co = self._compute_coeffs(s)
        if cache:
            if len(self._cache) >= self._CACHE_SIZE:
                self._cache.clear()
            self._cache[s] = co
        return co

    def _compute_coeffs(self, s: float) -> FlightCoeffs:
        la, lb = self.l1, self.l2
        W = self.Omega
        ea = cmath.exp(la * s)
        d2 = s * dd2(la * s, lb * s)
        d30 = s * s * dd3(0j, la * s, lb * s)
        iw = 1j * W
        d3s = s * s * dd3(0j, (la - iw) * s, (lb - iw) * s)
        rot = cmath.exp(iw * s)
        return FlightCoeffs(
            s=s,
            p11=(ea - la * d2).real,
            p12=d2.real,
            p21=(-self.kappa * d2).real,
            p22=(ea + lb * d2).real,
            qz0=d30.real + 0j,
            qv0=d2.real + 0j,
            qzs=rot * d3s,
            qvs=d2.real + iw * rot * d3s,
            rot=rot,
        )

    def propagate(
        self, z0: complex, v0: complex, E0: complex, s: float, cache: bool = False
    ) -> tuple[complex, complex]:
        """State (z, v) after a flight of ``s`` seconds from (z0, v0) with e^{i psi0} = E0."""
        if s == 0.0:
            return z0, v0
        co = self.coeffs(s, cache)
        g = self.F1 * E0
        z = co.p11 * z0 + co.p12 * v0 + self.f0 * co.qz0 + g * co.qzs
        v = co.p21 * z0 + co.p22 * v0 + self.f0 * co.qv0 + g * co.qvs
        return z, v

    # -- the imbalance reaction torque (module docstring) ---------------------------------

    def imb_coeffs(self, s: float) -> ImbCoeffs:
        """Coefficients of K(s) = int_0^s z e^{-i Omega u} du (m s) for length s >= 0 (s)."""
        la, lb = self.l1, self.l2
        iw = 1j * self.Omega
        a, b, w = (la - iw) * s, (lb - iw) * s, -iw * s
        s2 = s * s
        g12 = s2 * dd3(0j, a, b)
        s3 = s2 * s
        return ImbCoeffs(s * dd2(0j, a) - la * g12, g12, s3 * dd4(0j, a, b, w),
                         s3 * dd4(0j, 0j, a, b))

    def imb_integral(self, z0: complex, v0: complex, E0: complex, s: float) -> complex:
        """K = int_0^s z(u) e^{-i Omega u} du (m s) of the flight from (z0, v0) with
        e^{i psi0} = E0: the co-rotating position z e^{-i psi}, integrated, times E0."""
        if s == 0.0:
            return 0j
        k = self.imb_coeffs(s)
        return k.kz * z0 + k.kv * v0 + k.kf * self.f0 + k.kF * (self.F1 * E0)

    def imb_integral_ends(self, z0: complex, v0: complex, E0: complex, z1: complex,
                          v1: complex, s: float) -> complex:
        """imb_integral's K (m s) from both ends (z0, v0) and (z1, v1) of the flight, which
        the caller already has: multiplying the flight's equation by e^{-i Omega u} and
        integrating by parts, K (kappa - Omega^2 + i beta Omega) = f0 int e^{-i Omega u} du
        + F1 E0 s - [z' e^{-i Omega u}]_0^s - (beta + i Omega) [z e^{-i Omega u}]_0^s. Its
        rounding is absolute, about eps (|v| + (beta + |Omega|) |z| + ...)/|den|, however
        short the flight. The closed form (imb_integral) near resonance (IMB_COND), and
        where the quotient overflows (a subnormal Omega makes den subnormal while K is
        finite)."""
        if not self._imb_ends:
            return self.imb_integral(z0, v0, E0, s)
        W = self.Omega
        w = -1j * W * s
        rot = cmath.exp(w)
        rhs = self.F1 * E0 * s - (v1 * rot - v0) - complex(self.beta, W) * (z1 * rot - z0)
        if self.f0:
            rhs += self.f0 * (s * dd2(w, 0j))
        K = rhs / self._imb_den
        return K if cmath.isfinite(K) else self.imb_integral(z0, v0, E0, s)

    def imb_impulse_ends(self, z0: complex, v0: complex, E0: complex, z1: complex,
                         v1: complex, s: float) -> float:
        """imb_impulse's P_imb (N m s) of this flight from (z0, v0) with e^{i psi0} = E0 to
        (z1, v1) after s seconds, without the coefficients: -e_c Im(e^{-i phi} conj(E0)
        int F e^{-i Omega u} du) with K from imb_integral_ends (cheap for a length that
        does not recur)."""
        p, m, W = self.params, self.params.m, self.Omega
        w = -1j * W * s
        rot = cmath.exp(w)
        dz = z1 * rot - z0  # [z e^{-i Omega u}]_0^s
        pint = s * dd2(w, 0j) if self.f0 or self.amb * p.bias_force or self.F_ext else 0j
        if self._imb_ends:  # K as in imb_integral_ends, sharing rot and pint
            K = (self.F1 * E0 * s - (v1 * rot - v0) - complex(self.beta, W) * dz
                 + self.f0 * pint) / self._imb_den
        else:
            K = self.imb_integral(z0, v0, E0, s)
        cc, kk = self.beta * m, self.kappa * m  # a c (N s/m), a k (N/m)
        IF = (self.amb * p.bias_force + self.F_ext) * pint - cc * (dz + 1j * W * K) - kk * K
        return -p.e_c * ((E0 * self.imb_eph).conjugate() * IF).imag

    def imb_impulse(self, s: float) -> ImbImpulse:
        """Coefficients (cached by s) of the imbalance reaction's angular impulse over a free
        flight of s seconds (ImbImpulse): with E = e^{i(psi + phi)} and F = F_amb + F_ext,
        int conj(F) E dt = conj(int F conj(E) dt), int F conj(E) = e^{-i phi} conj(E0) int F
        e^{-i Omega u} du, and int F e^{-i Omega u} = (a F_bias + F_ext) conj(int e^{i Omega
        u}) - a c ([z e^{-i Omega u}]_0^s + i Omega K) - a k K, linear in (z0, v0, E0)
        through the flight map (coeffs) and K (imb_coeffs)."""
        hit = self._imb_cache.get(s)
        if hit is not None:
            return hit
        p, m = self.params, self.params.m
        co, k = self.coeffs(s), self.imb_coeffs(s)
        crot = co.rot.conjugate()
        cc, kk = self.beta * m, self.kappa * m  # a c (N s/m), a k (N/m)
        dk = complex(kk, cc * self.Omega)  # a k + i Omega a c
        fc = m * self.f0 - p.gravity_force  # a F_bias + F_ext (N)
        az = -cc * (co.p11 * crot - 1.0) - dk * k.kz
        av = -cc * co.p12 * crot - dk * k.kv
        a0 = (fc * (s * dd2(-1j * self.Omega * s, 0j)) - cc * self.f0 * co.qz0 * crot
              - dk * k.kf * self.f0)
        aE = (-cc * co.qzs * crot - dk * k.kF) * self.F1
        ph = -p.e_c * cmath.exp(-1j * p.phi)
        out = ImbImpulse(ph * az, ph * av, ph * a0, ph * aE)
        if len(self._imb_cache) >= self._CACHE_SIZE:
            self._imb_cache.clear()
        self._imb_cache[s] = out
        return out

    def accel(self, z: complex, v: complex, E: complex) -> complex:
        """Free-flight acceleration z'' (m/s^2) at state (z, v) and phasor E = e^{i psi}."""
        return -self.beta * v - self.kappa * z + self.f0 + self.F1 * E

    def jerk(self, v: complex, acc: complex, E: complex) -> complex:
        """Free-flight jerk z''' (m/s^3) from v, z'' and E = e^{i psi}."""
        return -self.beta * acc - self.kappa * v + 1j * self.Omega * self.F1 * E

    # -- global exclusion -----------------------------------------------------------------

    def sup_radius_bound(self, z0: complex, v0: complex, E0: complex) -> float:
        """Upper bound (m) of sup_{t >= 0} |z(t)| of the unconstrained flight, or inf.

        z = Z0 + Z1 e^{i psi(t)} + z_h(t): the steady response to the constant and the
        rotating force plus a homogeneous transient. |Z0 + Z1 e^{i psi}| <= |Z0| + |Z1|;
        the transient is bounded by the decaying quadratic form of the damped oscillator
        (underdamped) or by e^{l1 t}(|zeta0| + |eta0 - mu zeta0| t) (any damping).
        Returns inf where no finite bound exists (kappa = 0, undamped resonance).
        """
        steady, transient = self.radius_bound_parts(z0, v0, E0)
        bound = steady + transient
        return bound if bound == bound else math.inf  # NaN from inf - inf: no bound

    def radius_bound_parts(self, z0: complex, v0: complex, E0: complex) -> tuple[float, float]:
        """(|Z0| + |Z1|, bound of the transient) (m), the two terms of sup_radius_bound;
        (inf, inf) where no finite bound exists."""
        split = self._steady_split(z0, v0, E0)
        if split is None:
            return math.inf, math.inf
        Z0, Z1, zeta, eta = split
        return abs(Z0) + abs(Z1), _transient_bound(self.beta, self.kappa, zeta, eta)

    def _steady_split(
        self, z0: complex, v0: complex, E0: complex
    ) -> tuple[complex, complex, complex, complex] | None:
        """(Z0, Z1 E0, zeta, eta): the steady whirl z = Z0 + Z1 E0 e^{i Omega s} (m) and the
        transient's start zeta = z0 - Z0 - Z1 E0 (m), eta = v0 - i Omega Z1 E0 (m/s); None
        without stiffness or at undamped resonance (no steady whirl)."""
        kap, W = self.kappa, self.Omega
        den = complex(kap - W * W, self.beta * W)
        if kap <= 0.0 or den == 0:
            return None
        Z0 = self.f0 / kap
        Z1 = self.F1 * E0 / den
        return Z0, Z1, z0 - Z0 - Z1, v0 - 1j * W * Z1

    # -- modal evaluation (search) --------------------------------------------------------

    def modes(self, z0: complex, v0: complex, E0: complex) -> Modes | None:
        """The flight from (z0, v0, E0) as a sum of modes, when that is well conditioned.

        z(s) = Z0 + Z1 E0 e^{i Omega s} + a1 e^{l1 s} + a2 e^{l2 s}: one exponential per
        mode instead of the divided differences, so a point costs a fifth. Returns None
        (use ``propagate``) without stiffness, at resonance, at critical damping, or when
        the modal amplitudes exceed MODAL_GAIN times the state's own scale, i.e. whenever
        cancellation between modes could cost more than a few ulp of c_r.
        """
        la, lb, W = self.l1, self.l2, self.Omega
        split = self._steady_split(z0, v0, E0) if la != lb else None
        if split is None:
            return None
        Z0, Z1, zeta, eta = split
        a1 = (eta - lb * zeta) / (la - lb)
        a2 = (la * zeta - eta) / (la - lb)
        z_scale = max(abs(z0), self.c_r)
        v_scale = max(abs(v0), self.c_r * self.rate)
        amp_z = abs(Z0) + abs(Z1) + abs(a1) + abs(a2)
        amp_v = abs(W * Z1) + abs(la * a1) + abs(lb * a2)
        if not (amp_z <= MODAL_GAIN * z_scale and amp_v <= MODAL_GAIN * v_scale):
            return None
        return Modes(Z0, Z1, a1, a2, la, lb, 1j * W)


class Modes:
    """A free flight as a sum of modes (see FlightModel.modes); SI, inertial."""

    __slots__ = ("Z0", "Z1", "a1", "a2", "iw", "l1", "l2")

    def __init__(self, Z0: complex, Z1: complex, a1: complex, a2: complex, l1: complex,
                 l2: complex, iw: complex) -> None:
        self.Z0, self.Z1, self.a1, self.a2 = Z0, Z1, a1, a2
        self.l1, self.l2, self.iw = l1, l2, iw

    def at(self, s: float) -> tuple[complex, complex, complex]:
        """(z (m), v (m/s), e^{i Omega s}) at local time s (s)."""
        rot = cmath.exp(self.iw * s)
        e1 = self.a1 * cmath.exp(self.l1 * s)
        e2 = self.a2 * cmath.exp(self.l2 * s)
        zs = self.Z1 * rot
        return self.Z0 + zs + e1 + e2, self.iw * zs + self.l1 * e1 + self.l2 * e2, rot

    def g3_bound(self, s: float) -> float:
        """A bound (m^2/s^3) of |g'''| on [s, inf) for g = |z|^2 - c_r^2 along this flight.

        g is the sum over ordered pairs of modes of A_j conj(A_k) e^{(mu_j + conj mu_k) t},
        so |g'''| <= sum |A_j(s)| |A_k(s)| |mu_j + conj mu_k|^3 while no mode grows, plus 16
        eps of the largest such term for the amplitudes' rounding. Where the orbit osculates
        the circle, the terms that would be large vanish exactly (a circular whirl's own
        pair has mu + conj mu = 0), and this is smaller than the search's Taylor bound by up
        to 1e9 (contact.search.CREEP). inf when a mode grows (Re mu > 0)."""
        l1, l2 = self.l1, self.l2
        if l1.real > 0.0 or l2.real > 0.0:
            return math.inf
        amps = (abs(self.Z0), abs(self.Z1), abs(self.a1) * math.exp(l1.real * s),
                abs(self.a2) * math.exp(l2.real * s))
        rates = (0j, self.iw, l1, l2)
        total = top = 0.0
        for a, mu in zip(amps, rates):
            for b, nu in zip(amps, rates):
                r = abs(mu + nu.conjugate())
                total += a * b * (r * r * r)
                top = max(top, (a + b) * (a + b) * (r * r * r))
        return total + 16.0 * 2.220446049250313e-16 * top


def _eigenvalues(beta: float, kappa: float) -> tuple[complex, complex]:
    """Eigenvalues (1/s) of [[0, 1], [-kappa, -beta]], the more negative one first.

    The discriminant beta^2/4 - kappa is formed as a product to avoid cancellation
    near critical damping.
    """
    hb = 0.5 * beta
    rk = math.sqrt(kappa)
    disc = (hb - rk) * (hb + rk)
    if disc >= 0.0:
        r = math.sqrt(disc)
        return complex(-hb - r), complex(-hb + r)
    r = math.sqrt(-disc)
    return complex(-hb, -r), complex(-hb, r)


def _transient_bound(beta: float, kappa: float, zeta: complex, eta: complex) -> float:
    """sup_{t>=0} |z_h(t)| (m) for z_h'' + beta z_h' + kappa z_h = 0, z_h(0)=zeta, z_h'(0)=eta."""
    hb = 0.5 * beta
    rk = math.sqrt(kappa)
    disc = (hb - rk) * (hb + rk)
    best = math.inf
    if disc < 0.0:
        nu = math.sqrt(-disc)
        best = math.hypot(nu * abs(zeta), abs(eta + hb * zeta)) / nu
    alpha = kappa / (hb + math.sqrt(max(disc, 0.0))) if disc >= 0.0 else hb  # -Re l1
    if alpha > 0.0:
        A = abs(zeta)
        B = abs(eta + hb * zeta)
        sup = A if alpha * A >= B else (B / alpha) * math.exp(alpha * A / B - 1.0)
        best = min(best, sup)
    return best
