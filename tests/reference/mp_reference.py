"""Independent high-precision reference for the rotor / touchdown-bearing model.

This module is deliberately independent of the product code (``fmu_src/rotortd``):
it imports nothing from it and uses different numerical methods, so that the two
can be compared (docs/validation.md §1).

Model (SI units, inertial frame, complex position ``z = x + i y``), docs/model.md §1::

    m z'' = a (F_bias - c z' - k z) + m e_c Ω² exp(i(ψ + φ)) + F_ext_total,   ψ' = Ω

* ``F_bias = i m g`` if ``par["levitate"]`` else 0 (it is scaled by ``a``);
* gravity is part of the external force: ``F_ext_total = F_ext - i m g``;
* ``Ω``, ``F_ext`` and ``a`` are held constant over one call, the term
  ``i m e_c Ω' exp(i(ψ + φ))`` of a varying speed is therefore absent.

Methods (all in mpmath, default 50 significant digits plus guard digits):

* free flight: ``mpmath.expm`` of the 4x4 augmented matrix acting on
  ``(z, v, 1, e^{iψ})`` (one code path for k = 0, c = 0, critical damping,
  resonance and Ω = 0) -- no divided differences, no φ-functions;
* event location: dense sampling at ``Δt <= 1/(40 ω_max)``, exact high-order
  Taylor polynomials of the same linear flow inside each sample interval,
  sign changes of ``g = |z|² - c_r²`` and of ``g' = 2 Re(conj(z) z')`` (local
  maxima, i.e. grazing excursions), safeguarded Newton/bisection to full
  precision.  **Assumption:** ``g`` has at most one extremum inside each sample
  interval (see :func:`mp_first_impact`);
* impacts: the reset law (2) with the Coulomb stick cap;
* sustained contact: an automatic-differentiation Taylor-series integrator of
  the contact ODE (3) (own implementation, adaptive step and degree ~ digits),
  with event location for lift-off (N = 0 while decreasing) and for v_rel = 0;
* rolling: closed form.

Typical cost at the default precision (chapter parameters, Ω = 184 rad/s): one
``mp_flight`` ~10 ms; ``mp_first_impact`` ~60 ms per forcing period searched;
``mp_impact_sequence`` ~20 ms per impact; ``mp_sliding`` (dps 40) ~0.5-1 s per
forcing period of contact.

Parameters are passed as a plain dict with keys
``m, c, k, e_c, phi, c_r, R, mu, d, g, levitate``.  Complex inputs may be Python
``complex``; results are mpmath ``mpf``/``mpc`` values carrying the working
precision (dps + guard digits).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import mpmath
from mpmath import mp

Num = Any  # an mpmath mpf / mpc (mpmath ships no type stubs)
Params = dict[str, Any]

GUARD_DIGITS = 15
"""Extra decimal digits carried internally on top of the requested ``dps``."""

SAMPLES_PER_RAD = 40
"""Sampling density of the event search: interval <= 1/(SAMPLES_PER_RAD * ω_max)."""

_TAYLOR_MAX_TERMS = 400


# --------------------------------------------------------------------------------------
# parameters and the augmented linear flow (scaled units)
# --------------------------------------------------------------------------------------


def _mpc(x: Any) -> Num:
    """Convert a Python or mpmath number to an mpc at the current precision."""
    return mp.mpc(x)


def _mpf(x: Any) -> Num:
    """Convert a Python or mpmath real number to an mpf at the current precision."""
    return mp.mpf(x)


def _params(par: Params) -> dict[str, Num]:
    """Convert a parameter dict to mpf values (current precision); ``levitate`` -> 0/1."""
    keys = ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")
    p = {key: _mpf(par[key]) for key in keys}
    p["levitate"] = mp.one if par.get("levitate", True) else mp.zero
    return p


def _const_force(p: dict[str, Num], F_ext: Any, a: Num) -> Num:
    """Constant part of the non-contact force, N (inertial frame).

    ``a F_bias + F_ext - i m g`` with ``F_bias = i m g`` when levitating.
    """
    img = mp.mpc(0, 1) * p["m"] * p["g"]
    return a * p["levitate"] * img + _mpc(F_ext) - img


def _rate_scale(p: dict[str, Num], Omega: Num, F_c: Num, a: Num, v0: Num) -> Num:
    """Largest natural rate of the free flight, rad/s (0 if the flow is trivial).

    max(|Ω|, |λ|max of m λ² + a c λ + a k = 0 (bounded by a c/m + sqrt(a k/m)),
    sqrt(|F_c|/(m c_r)), |Ω| sqrt(e_c/c_r), |v0|/c_r).
    """
    m, c_r = p["m"], p["c_r"]
    rates = [
        abs(Omega),
        a * p["c"] / m + mp.sqrt(a * p["k"] / m),
        mp.sqrt(abs(F_c) / (m * c_r)),
        abs(Omega) * mp.sqrt(p["e_c"] / c_r),
        abs(v0) / c_r,
    ]
    return max(rates)


class _Flow:
    """Augmented linear flow of (1) in scaled units.

    State ``X = (z/c_r, v/(c_r ω_s), 1, e^{iψ})`` with scaled time ``τ = ω_s t``;
    ``dX/dτ = M X``.  ``ω_s`` is the rate scale of :func:`_rate_scale` (1 if 0), so
    that all entries of ``M`` acting on the dynamic part are O(1) or smaller.
    """

    def __init__(self, par: Params, Omega: Any, F_ext: Any, a: Any, v0: Any) -> None:
        p = _params(par)
        self.p = p
        self.Omega = _mpf(Omega)
        self.a = _mpf(a)
        self.F_c = _const_force(p, F_ext, self.a)
        ws = _rate_scale(p, self.Omega, self.F_c, self.a, _mpc(v0))
        self.trivial = ws == 0
        self.ws = ws if ws > 0 else mp.one
        self.M = self._matrix()

    def _matrix(self) -> Any:
        """The 4x4 complex matrix M of dX/dτ = M X (scaled)."""
        p, ws, a, Om = self.p, self.ws, self.a, self.Omega
        m, c_r = p["m"], p["c_r"]
        M = mp.matrix(4, 4)
        M[0, 1] = mp.one
        M[1, 0] = -a * p["k"] / (m * ws**2)
        M[1, 1] = -a * p["c"] / (m * ws)
        M[1, 2] = self.F_c / (m * c_r * ws**2)
        M[1, 3] = p["e_c"] * Om**2 / (c_r * ws**2) * mp.expj(p["phi"])
        M[3, 3] = mp.mpc(0, 1) * Om / ws
        return M

    def state(self, z: Any, v: Any, psi: Any) -> list[Num]:
        """Scaled augmented state from SI position (m), velocity (m/s), spin angle (rad)."""
        c_r = self.p["c_r"]
        return [_mpc(z) / c_r, _mpc(v) / (c_r * self.ws), mp.mpc(1), mp.expj(_mpf(psi))]

    def si(self, X: list[Num]) -> tuple[Num, Num]:
        """SI (z, v) from a scaled augmented state."""
        c_r = self.p["c_r"]
        return X[0] * c_r, X[1] * c_r * self.ws

    def apply(self, E: Any, X: list[Num]) -> list[Num]:
        """Matrix-vector product E X."""
        return [mp.fsum(E[i, j] * X[j] for j in range(4)) for i in range(4)]

    def expm(self, tau: Num) -> Any:
        """exp(M τ) by mpmath.expm (Taylor with scaling and squaring)."""
        return mpmath.expm(self.M * tau)

    def taylor(self, X: list[Num], dtau: Num) -> list[list[Num]]:
        """Coefficients C_n of X(u dtau) = Σ C_n u^n, u ∈ [0, 1], truncated below 2^-prec."""
        tol = mp.ldexp(mp.one, -mp.prec - 8) * max(mp.one, max(abs(x) for x in X))
        coeffs = [list(X)]
        cur = list(X)
        small = 0
        for n in range(1, _TAYLOR_MAX_TERMS):
            cur = [mp.fsum(self.M[i, j] * cur[j] for j in range(4)) * dtau / n for i in range(4)]
            coeffs.append(cur)
            small = small + 1 if max(abs(x) for x in cur) < tol else 0
            if small >= 2 and n >= 4:
                return coeffs
        raise RuntimeError("Taylor series of the flight did not converge; interval too long")


def _horner(coeffs: list[Num], u: Num) -> Num:
    """Evaluate Σ coeffs[n] u^n."""
    acc = mp.zero
    for cn in reversed(coeffs):
        acc = acc * u + cn
    return acc


def _dhorner(coeffs: list[Num], u: Num) -> Num:
    """Evaluate d/du Σ coeffs[n] u^n."""
    acc = mp.zero
    for n in range(len(coeffs) - 1, 0, -1):
        acc = acc * u + n * coeffs[n]
    return acc


class _IntervalPoly:
    """g(u) = |z̃(u)|² - 1 and its u-derivatives on one sample interval (u ∈ [0, 1])."""

    def __init__(self, coeffs: list[list[Num]]) -> None:
        self.coeffs = coeffs
        self.zc = [cn[0] for cn in coeffs]

    def g(self, u: Num) -> tuple[Num, Num, Num]:
        """(g, dg/du, d²g/du²) at u."""
        z = _horner(self.zc, u)
        dz = _dhorner(self.zc, u)
        d2z = mp.fsum(n * (n - 1) * self.zc[n] * u ** (n - 2) for n in range(2, len(self.zc)))
        g = (z * mp.conj(z)).real - 1
        dg = 2 * (mp.conj(z) * dz).real
        d2g = 2 * ((dz * mp.conj(dz)).real + (mp.conj(z) * d2z).real)
        return g, dg, d2g

    def state(self, u: Num) -> list[Num]:
        """Augmented scaled state at u."""
        return [_horner([cn[i] for cn in self.coeffs], u) for i in range(4)]


# --------------------------------------------------------------------------------------
# root finding
# --------------------------------------------------------------------------------------


def _bracket_root(f: Callable[[Num], tuple[Num, Num]], lo: Num, hi: Num, increasing: bool) -> Num:
    """Root of f in [lo, hi] by safeguarded Newton / bisection, to full precision.

    ``f(u)`` returns ``(value, derivative)``.  Requires ``f(lo) <= 0 <= f(hi)`` if
    ``increasing`` else ``f(lo) >= 0 >= f(hi)``.  Bisection keeps the bracket, so the
    result is guaranteed to lie in [lo, hi] even at a (near-)double root (grazing).
    """
    sgn = 1 if increasing else -1
    tol = mp.ldexp(mp.one, -mp.prec + 4) * max(mp.one, abs(hi))
    x = (lo + hi) / 2
    for _ in range(4 * mp.prec + 100):
        fx, dfx = f(x)
        fx = sgn * fx
        dfx = sgn * dfx
        if fx == 0:
            return x
        if fx < 0:
            lo = x
        else:
            hi = x
        if hi - lo <= tol:
            return x
        newton = x - fx / dfx if dfx > 0 else None
        if newton is not None and lo < newton < hi and abs(newton - x) < (hi - lo):
            if abs(newton - x) <= tol:
                return newton
            x = newton
        else:
            x = (lo + hi) / 2
    return x


# --------------------------------------------------------------------------------------
# 1. exact flight
# --------------------------------------------------------------------------------------


def mp_flight(
    par: Params,
    z0: Any,
    v0: Any,
    psi0: Any,
    Omega: Any,
    F_ext: Any,
    a: Any,
    t: Any,
    dps: int = 50,
) -> tuple[Num, Num]:
    """Exact free flight of (1) over time ``t >= 0`` s (the wall is ignored).

    Inputs in SI, inertial frame: position ``z0`` (m), velocity ``v0`` (m/s), spin
    angle ``psi0`` (rad), speed ``Omega`` (rad/s), external force ``F_ext`` (N,
    gravity ``-i m g`` is added here), AMB state ``a`` (-).  Returns ``(z, v)`` at
    time ``t`` as mpc, computed with ``mpmath.expm`` of the augmented 4x4 matrix at
    ``dps + GUARD_DIGITS`` digits.
    """
    if t < 0:
        raise ValueError(f"t must be >= 0, got {t}")
    with mp.workdps(dps + GUARD_DIGITS):
        flow = _Flow(par, Omega, F_ext, a, v0)
        X0 = flow.state(z0, v0, psi0)
        X = flow.apply(flow.expm(_mpf(t) * flow.ws), X0)
        return flow.si(X)


# --------------------------------------------------------------------------------------
# 2. first impact (event location including grazing)
# --------------------------------------------------------------------------------------


def _first_crossing(poly: _IntervalPoly) -> Num | None:
    """First u ∈ (0, 1] where g crosses 0 upward from g < 0, or None.

    Splits [0, 1] into monotone pieces at the (at most one, by assumption) interior
    extremum of g, located as the root of dg/du; a grazing maximum that pokes above
    0 between two samples is thereby found.  A piece counts only if g < 0 at its
    start, so a start on the wall moving inward is never reported.
    """
    g0, dg0, _ = poly.g(mp.zero)
    g1, dg1, _ = poly.g(mp.one)
    knots = [(mp.zero, g0)]
    if (dg0 > 0 > dg1) or (dg0 < 0 < dg1):
        um = _bracket_root(lambda u: poly.g(u)[1:], mp.zero, mp.one, increasing=dg0 < 0)
        knots.append((um, poly.g(um)[0]))
    knots.append((mp.one, g1))
    for (p, gp), (q, gq) in itertools.pairwise(knots):
        if gp < 0 <= gq:
            return _bracket_root(lambda u: poly.g(u)[:2], p, q, increasing=True)
    return None


def _search(flow: _Flow, X0: list[Num], tau_max: Num) -> tuple[Num, list[Num]] | None:
    """First upward crossing of |z̃| = 1 in (0, tau_max] (scaled time), or None.

    Returns ``(τ, X(τ))``.  Sample interval ``<= 1/SAMPLES_PER_RAD`` in scaled time,
    i.e. ``<= 1/(40 ω_max)`` in SI.
    """
    if flow.trivial or tau_max <= 0:
        return None
    n_int = max(1, int(mp.ceil(tau_max * SAMPLES_PER_RAD)))
    dtau = tau_max / n_int
    E = flow.expm(dtau)
    X = list(X0)
    ga, dga = _g_dg(X)
    for j in range(n_int):
        Xb = flow.apply(E, X)
        gb, dgb = _g_dg(Xb)
        if _may_cross(ga, dga, gb, dgb):
            poly = _IntervalPoly(flow.taylor(X, dtau))
            u = _first_crossing(poly)
            if u is not None:
                return (j + u) * dtau, poly.state(u)
        X, ga, dga = Xb, gb, dgb
    return None


def _g_dg(X: list[Num]) -> tuple[Num, Num]:
    """Scaled g = |z̃|² - 1 and dg/dτ = 2 Re(conj(z̃) ṽ) of an augmented state."""
    return (X[0] * mp.conj(X[0])).real - 1, 2 * (mp.conj(X[0]) * X[1]).real


def _may_cross(ga: Num, dga: Num, gb: Num, dgb: Num) -> bool:
    """Whether an interval with these end values can hold an upward crossing of 0.

    Under the one-extremum assumption, an interval with g(b) < 0 can only hold a
    crossing if it has an interior maximum (dg: + to -), or if it starts on/over the
    wall (g(a) >= 0) with an interior minimum.  Otherwise it is skipped without
    building its Taylor polynomial.
    """
    if gb >= 0:
        return True
    if dga > 0 > dgb:
        return True
    return ga >= 0 and dga < 0 < dgb


def _check_start(flow: _Flow, X0: list[Num]) -> None:
    """Reject starts outside the disk or on the wall moving outward."""
    g0 = (X0[0] * mp.conj(X0[0])).real - 1
    dg0 = 2 * (mp.conj(X0[0]) * X0[1]).real
    on_wall_tol = mp.mpf(10) ** -12
    if g0 > on_wall_tol:
        raise ValueError(f"start lies outside the clearance: |z0|/c_r - 1 = {g0 / 2}")
    if g0 >= 0 and dg0 > 0:
        raise ValueError("start lies on the wall moving outward (impact at t = 0)")


def mp_first_impact(
    par: Params,
    z0: Any,
    v0: Any,
    psi0: Any,
    Omega: Any,
    F_ext: Any,
    a: Any,
    t_max: Any,
    dps: int = 50,
) -> tuple[Num, Num, Num] | None:
    """First time in (0, t_max] at which ``|z| = c_r`` is reached from inside.

    Returns ``None`` or ``(t, z, v_minus)`` (s, m, m/s; inertial frame; ``t`` counted
    from the call's start).  The located ``z`` lies on the circle to ~``10^-dps``
    relative.

    Method: samples at ``Δt = t_max / ceil(40 ω_max t_max) <= 1/(40 ω_max)`` with
    ``ω_max = max(|Ω|, a c/m + sqrt(a k/m), sqrt(|F_c|/(m c_r)), |Ω| sqrt(e_c/c_r),
    |v0|/c_r)``; inside each interval ``z`` is an exact (truncated below 2^-prec)
    Taylor polynomial of the flow.  Upward crossings of ``g = |z|² - c_r²`` are
    found from sign changes of ``g``; local maxima of ``g`` (grazing excursions
    entirely between two samples) from sign changes of ``g' = 2 Re(conj(z) z')``,
    the maximum being located to full precision and ``g`` evaluated there.

    **Assumption:** ``g`` has at most one extremum inside each sample interval.
    With the sampling above this holds unless the motion contains a component
    faster than ``ω_max`` (which the linear flow (1) cannot generate).

    A start on the wall (``|z0| = c_r``) moving inward or tangentially is allowed
    (this is the state just after an impact); the starting point itself is never
    reported.  ``ValueError`` if ``|z0| > c_r`` or the start is on the wall moving
    outward.
    """
    with mp.workdps(dps + GUARD_DIGITS):
        flow = _Flow(par, Omega, F_ext, a, v0)
        X0 = flow.state(z0, v0, psi0)
        _check_start(flow, X0)
        hit = _search(flow, X0, _mpf(t_max) * flow.ws)
        if hit is None:
            return None
        tau, X = hit
        z, v = flow.si(X)
        return tau / flow.ws, z, v


# --------------------------------------------------------------------------------------
# 3. impact reset law
# --------------------------------------------------------------------------------------


def _sign(x: Num) -> int:
    """Sign of a real number (0 at 0)."""
    return (x > 0) - (x < 0)


def mp_reset(par: Params, z: Any, v_minus: Any, Omega: Any, dps: int = 50) -> dict[str, Any]:
    """Impact reset law (2) with the Coulomb stick cap (SI, inertial frame).

    ``z'⁺ = z'⁻ - (1 + d) ṙ⁻ n - i n Δv_t`` with ``n = z/|z|``, ``ṙ⁻ = Re(conj(n) z'⁻)``
    and the tangential velocity drop ``Δv_t = μ (1 + d) ṙ⁻ s``, ``s = sign(v_rel⁻)``,
    ``v_rel = R Ω + c_r θ'``, ``θ' = Im(conj(n) z')/|z|``.

    Stick cap: if the uncapped drop would leave ``s v_rel⁺ < 0`` (friction impulse
    reversing the slip), ``Δv_t`` is reduced so that ``v_rel⁺ = 0`` exactly.

    Returns dict: ``v_plus`` (m/s), ``rdot`` (ṙ⁻, m/s), ``P_n = m (1 + d) ṙ⁻`` (N s,
    normal impulse magnitude; the impulse on the rotor is ``-P_n n``), ``P_t = m Δv_t``
    (N s, signed; the impulse on the rotor is ``-P_t i n``, so ``P_t > 0`` brakes a
    positive slip and the friction torque impulse on the spin is ``-R P_t``),
    ``stick`` (True when the cap fired, or when ``v_rel⁻ = 0`` so that ``v_rel⁺ = 0``),
    ``v_rel_minus``, ``v_rel_plus`` (m/s).
    """
    with mp.workdps(dps + GUARD_DIGITS):
        p = _params(par)
        zc, vm = _mpc(z), _mpc(v_minus)
        r = abs(zc)
        n = zc / r
        rdot = (mp.conj(n) * vm).real
        vt = (mp.conj(n) * vm).imag  # = r θ'
        scale = p["c_r"] / r  # c_r θ' = scale * vt
        v_rel_m = p["R"] * _mpf(Omega) + scale * vt
        s = _sign(v_rel_m)
        dvt = p["mu"] * (1 + p["d"]) * rdot * s
        v_rel_p = v_rel_m - scale * dvt
        stick = s == 0
        if s != 0 and s * v_rel_p <= 0:
            dvt = v_rel_m / scale
            v_rel_p = mp.zero
            stick = True
        v_plus = vm - (1 + p["d"]) * rdot * n - mp.mpc(0, 1) * n * dvt
        return {
            "v_plus": v_plus,
            "rdot": rdot,
            "P_n": p["m"] * (1 + p["d"]) * rdot,
            "P_t": p["m"] * dvt,
            "stick": stick,
            "v_rel_minus": v_rel_m,
            "v_rel_plus": v_rel_p,
        }


# --------------------------------------------------------------------------------------
# 4. impact sequence (free flight + impacts only)
# --------------------------------------------------------------------------------------


def _pushes_outward(flow: _Flow, X: list[Num]) -> bool:
    """True if, at ṙ = 0 on the wall, the free-flight acceleration points outward."""
    acc = mp.fsum(flow.M[1, j] * X[j] for j in range(4))
    return ((X[1] * mp.conj(X[1])).real + (mp.conj(X[0]) * acc).real) > 0


def mp_impact_sequence(
    par: Params,
    z0: Any,
    v0: Any,
    psi0: Any,
    Omega: Any,
    F_ext: Any,
    a: Any,
    t_end: Any,
    max_impacts: int = 1000,
    dps: int = 50,
    v_stop: Any = 0,
) -> dict[str, Any]:
    """Free flight plus impacts over [0, t_end] s (no sustained-contact phase).

    Returns dict ``impacts`` (list of dicts ``t, z, v_minus, v_plus, rdot, P_n, P_t,
    stick``; ``t`` from the call's start), and the final ``z, v, t`` and ``stopped``:

    * ``"t_end"``: no further impact before ``t_end``; state at ``t_end``;
    * ``"max_impacts"``: ``max_impacts`` impacts were applied; post-reset state at
      the last one;
    * ``"v_stop"``: an impact had ``ṙ⁻ < v_stop`` (chattering cut-off, m/s); this
      impact is listed (with its would-be reset) but the returned state is the
      pre-impact one ``(z, v_minus)`` at its time, ready for a contact phase;
    * ``"contact"``: ``ṙ⁺ = 0`` (``d = 0``) and the free-flight acceleration pushes
      outward, so flight cannot continue.

    After a reset the search restarts at the impact point, which is on the wall
    moving inward; only crossings from ``g < 0`` count, so the same impact is never
    found twice.  The flight map is re-built after each impact (its rate scale
    depends on the post-impact speed).
    """
    with mp.workdps(dps + GUARD_DIGITS):
        t_end = _mpf(t_end)
        v_stop = _mpf(v_stop)
        Om = _mpf(Omega)
        z, v, t = _mpc(z0), _mpc(v0), mp.zero
        psi = _mpf(psi0)
        impacts: list[dict[str, Any]] = []
        while True:
            flow = _Flow(par, Om, F_ext, a, v)
            X = flow.state(z, v, psi + Om * t)
            if not impacts:
                _check_start(flow, X)
            hit = _search(flow, X, (t_end - t) * flow.ws)
            if hit is None:
                X = flow.apply(flow.expm((t_end - t) * flow.ws), X)
                z, v = flow.si(X)
                return _seq_result(impacts, z, v, t_end, "t_end")
            tau, Xh = hit
            t = t + tau / flow.ws
            z, vm = flow.si(Xh)
            res = mp_reset(par, z, vm, Om, dps=dps)
            impacts.append({"t": t, "z": z, "v_minus": vm, **_impact_fields(res)})
            if res["rdot"] < v_stop:
                return _seq_result(impacts, z, vm, t, "v_stop")
            v = res["v_plus"]
            if len(impacts) >= max_impacts:
                return _seq_result(impacts, z, v, t, "max_impacts")
            if par["d"] == 0 and _pushes_outward(flow, flow.state(z, v, psi + Om * t)):
                return _seq_result(impacts, z, v, t, "contact")


def _impact_fields(res: dict[str, Any]) -> dict[str, Any]:
    """Subset of a reset result stored per impact."""
    return {key: res[key] for key in ("v_plus", "rdot", "P_n", "P_t", "stick")}


def _seq_result(
    impacts: list[dict[str, Any]], z: Num, v: Num, t: Num, stopped: str
) -> dict[str, Any]:
    """Assemble the result dict of :func:`mp_impact_sequence`."""
    return {"impacts": impacts, "z": z, "v": v, "t": t, "stopped": stopped}


# --------------------------------------------------------------------------------------
# 5. sustained contact: sliding (Taylor AD integrator) and rolling (closed form)
# --------------------------------------------------------------------------------------


class _ContactModel:
    """Sliding-contact ODE (3) in SI units with ψ = ψ0 + Ω t.

    ``e^{-iθ} F = (P + Q0 e^{iΩt}) e^{-iθ} - a k c_r - i a c c_r θ'`` with the constant
    force ``P = a F_bias + F_ext - i m g`` and ``Q0 = m e_c Ω² e^{i(ψ0 + φ)}``;
    ``N = Re(e^{-iθ}F) + m c_r θ'²``, ``m c_r θ'' = Im(e^{-iθ}F) - μ s N``.
    """

    def __init__(self, par: Params, psi0: Any, Omega: Any, F_ext: Any, a: Any) -> None:
        p = _params(par)
        self.p = p
        self.Omega = _mpf(Omega)
        self.a = _mpf(a)
        self.P = _const_force(p, F_ext, self.a)
        self.Q0 = p["m"] * p["e_c"] * self.Omega**2 * mp.expj(_mpf(psi0) + p["phi"])

    def rate_scale(self, dtheta: Num) -> Num:
        """Natural rate of the contact motion, rad/s (for step-size tolerances)."""
        p = self.p
        m, c_r = p["m"], p["c_r"]
        force = abs(self.P) + abs(self.Q0) + self.a * p["k"] * c_r
        rates = [
            abs(self.Omega),
            abs(dtheta),
            mp.sqrt(force / (m * c_r)),
            self.a * p["c"] / m,
            p["R"] * abs(self.Omega) / c_r,
        ]
        return max(max(rates), mp.mpf(10) ** -30)

    def v_rel(self, dtheta: Num) -> Num:
        """Slip velocity R Ω + c_r θ', m/s."""
        return self.p["R"] * self.Omega + self.p["c_r"] * dtheta

    def forces(self, t: Num, theta: Num, dtheta: Num) -> tuple[Num, Num]:
        """(Re, Im) of e^{-iθ} F at time t (N)."""
        p = self.p
        G = (self.P + self.Q0 * mp.expj(self.Omega * t)) * mp.expj(-theta)
        re = G.real - self.a * p["k"] * p["c_r"]
        im = G.imag - self.a * p["c"] * p["c_r"] * dtheta
        return re, im

    def normal_force(self, t: Num, theta: Num, dtheta: Num) -> Num:
        """N = Re(e^{-iθ}F) + m c_r θ'², N (positive = pressing on the wall)."""
        return self.forces(t, theta, dtheta)[0] + self.p["m"] * self.p["c_r"] * dtheta**2

    def series(
        self, t0: Num, theta0: Num, dtheta0: Num, s: int, order: int
    ) -> tuple[list[Num], list[Num], list[Num]]:
        """Taylor coefficients (in local time σ = t - t0) of θ, θ' and N up to ``order``.

        Automatic differentiation: B = e^{-iθ} obeys B' = -i θ' B, D = e^{i(Ωt-θ)}
        obeys D' = i(Ω - θ') D; products by Cauchy convolution.
        """
        p = self.p
        m, c_r, mu = p["m"], p["c_r"], p["mu"]
        a, Om = self.a, self.Omega
        j_ = mp.mpc(0, 1)
        th = [_mpf(theta0)]
        om = [_mpf(dtheta0)]
        B = [mp.expj(-th[0])]
        D = [mp.expj(Om * t0 - th[0])]
        N: list[Num] = []
        for k in range(order + 1):
            if k > 0:
                B.append(-j_ / k * mp.fsum(i * th[i] * B[k - i] for i in range(1, k + 1)))
                dphi = [Om - th[1]] + [-th[i] for i in range(2, k + 1)]
                D.append(j_ / k * mp.fsum(i * dphi[i - 1] * D[k - i] for i in range(1, k + 1)))
            G = self.P * B[k] + self.Q0 * D[k]
            sq = mp.fsum(om[i] * om[k - i] for i in range(k + 1))
            Nk = G.real + m * c_r * sq - (a * p["k"] * c_r if k == 0 else 0)
            Tk = G.imag - a * p["c"] * c_r * om[k] - mu * s * Nk
            N.append(Nk)
            th.append(om[k] / (k + 1))
            om.append(Tk / (m * c_r * (k + 1)))
        return th[: order + 1], om[: order + 1], N


def _step_size(th: list[Num], om: list[Num], w_ref: Num, tol: Num) -> Num:
    """Taylor step h with the last two terms of θ and θ'/w_ref below tol (rad)."""
    n = len(th) - 1
    h = mp.inf
    for coeffs, scale in ((th, mp.one), (om, 1 / w_ref)):
        for j in (n - 1, n):
            cj = abs(coeffs[j]) * scale
            if cj > 0:
                h = min(h, (tol / cj) ** (mp.one / j))
    return h * mp.mpf("0.7")


def _first_event(
    coeffs: list[Num], h: Num, start_sign: int, offset: Num = 0, n_probe: int = 16
) -> Num | None:
    """First σ ∈ (0, h] where Σ c_k σ^k + offset leaves sign ``start_sign``, or None.

    Probes the polynomial at ``n_probe`` points, then refines the first sign change
    with safeguarded Newton/bisection.
    """

    def f(x: Num) -> tuple[Num, Num]:
        return _horner(coeffs, x) + offset, _dhorner(coeffs, x)

    prev = mp.zero
    for i in range(1, n_probe + 1):
        x = h * i / n_probe
        if start_sign * f(x)[0] <= 0:
            return _bracket_root(f, prev, x, increasing=start_sign < 0)
        prev = x
    return None


def mp_sliding(
    par: Params,
    theta0: Any,
    dtheta0: Any,
    psi0: Any,
    Omega: Any,
    F_ext: Any,
    a: Any,
    t_end: Any,
    dps: int = 40,
) -> dict[str, Any]:
    """High-precision integration of the sliding-contact ODE (3) from t = 0 to t_end.

    State: contact angle ``θ`` (rad, inertial, ``z = c_r e^{iθ}``), whirl rate ``θ'``
    (rad/s); spin angle ``ψ = ψ0 + Ω t``.  Sliding friction ``F_t = μ s N`` with the
    slip sign ``s = sign(R Ω + c_r θ')`` fixed at its initial value (``ValueError``
    if ``v_rel = 0`` initially: that is rolling, see :func:`mp_rolling_normal_force`).

    Integrator: Taylor series by automatic differentiation, degree ~ dps + 10,
    adaptive step with the last two terms below ``10^-(dps+GUARD)``.

    Stops at the first of: ``t_end``; lift-off (N reaches 0 while decreasing; also
    at t = 0 if ``N(0) < 0``); slip reversal ``v_rel = 0`` (stick/rolling onset).
    Returns dict ``theta, dtheta, t, lift_off (bool), N_end`` (N at the returned
    time, N), ``event`` in {"t_end", "lift_off", "v_rel_zero"}, and the impulses over
    [0, t]: ``I_n`` (the integral of N, N s) and ``I_c`` (of the contact force on the rotor,
    ``-(N + i μ s N) e^{iθ}``, complex, N s, inertial), from the integrated Taylor series.
    """
    with mp.workdps(dps + GUARD_DIGITS):
        model = _ContactModel(par, psi0, Omega, F_ext, a)
        th, om, t = _mpf(theta0), _mpf(dtheta0), mp.zero
        t_end = _mpf(t_end)
        s = _sign(model.v_rel(om))
        if s == 0:
            raise ValueError("v_rel = 0 at the start: rolling, not sliding")
        N0 = model.normal_force(t, th, om)
        if N0 < 0:
            return _slide_result(th, om, t, N0, "lift_off", (mp.zero, mp.zero))
        order = dps + GUARD_DIGITS
        tol = mp.mpf(10) ** -(dps + GUARD_DIGITS)
        vr_off = model.p["R"] * model.Omega / model.p["c_r"]
        imp = (mp.zero, mp.mpc(0))
        while True:
            ths, oms, Ns = model.series(t, th, om, s, order)
            h = _step_size(ths, oms, model.rate_scale(om), tol)
            last = h >= t_end - t
            h = t_end - t if last else h
            ev_n = _first_event(Ns, h, 1)
            ev_v = _first_event(oms, h, s, offset=vr_off)
            event, sig = _earliest(ev_n, ev_v, h)
            imp = _add_impulses(imp, model, ths, Ns, s, sig)
            th, om = _horner(ths, sig), _horner(oms, sig)
            if event != "t_end":
                return _slide_result(th, om, t + sig, _horner(Ns, sig), event, imp)
            t = t_end if last else t + h
            if last:
                N_end = model.normal_force(t, th, om)
                return _slide_result(th, om, t, N_end, "t_end", imp)


def _add_impulses(
    imp: tuple[Num, Num], model: _ContactModel, ths: list[Num], Ns: list[Num], s: int,
    sig: Num,
) -> tuple[Num, Num]:
    """(I_n, I_c) plus the integrals over [0, sig] of a step's series of N and of the
    contact force -(1 + i μ s) N e^{iθ}, with e^{iθ} = Σ E_k σ^k by E' = i θ' E."""
    j_ = mp.mpc(0, 1)
    E = [mp.expj(ths[0])]
    for k in range(1, len(ths)):
        E.append(j_ / k * mp.fsum(i * ths[i] * E[k - i] for i in range(1, k + 1)))
    fc = [mp.fsum(Ns[i] * E[k - i] for i in range(k + 1)) for k in range(len(Ns))]
    lead = -(1 + j_ * model.p["mu"] * s)
    I_n = _horner([mp.zero] + [c / (k + 1) for k, c in enumerate(Ns)], sig)
    I_c = lead * _horner([mp.mpc(0)] + [c / (k + 1) for k, c in enumerate(fc)], sig)
    return imp[0] + I_n, imp[1] + I_c


def _earliest(ev_n: Num | None, ev_v: Num | None, h: Num) -> tuple[str, Num]:
    """Pick the earliest event in a step: ('lift_off' | 'v_rel_zero' | 't_end', σ)."""
    cands = [("t_end", h)]
    if ev_n is not None:
        cands.append(("lift_off", ev_n))
    if ev_v is not None:
        cands.append(("v_rel_zero", ev_v))
    name, sig = min(cands, key=lambda c: c[1])
    if name == "t_end":
        return name, h
    return name, sig


def _slide_result(
    th: Num, om: Num, t: Num, N: Num, event: str, imp: tuple[Num, Num]
) -> dict[str, Any]:
    """Assemble the result dict of :func:`mp_sliding`."""
    return {
        "theta": th,
        "dtheta": om,
        "t": t,
        "lift_off": event == "lift_off",
        "N_end": N,
        "event": event,
        "I_n": imp[0],
        "I_c": imp[1],
    }


def mp_rolling_normal_force(
    par: Params,
    theta0: Any,
    psi0: Any,
    Omega: Any,
    F_ext: Any,
    a: Any,
    t: Any,
    dps: int = 50,
) -> dict[str, Num]:
    """Closed-form rolling motion (v_rel = 0) and its contact forces at time t (s).

    ``θ' = -R Ω/c_r`` (constant), ``θ = θ0 + θ' t``, ``ψ = ψ0 + Ω t``.
    Returns dict ``theta`` (rad), ``dtheta`` (rad/s), ``N = Re(e^{-iθ}F) + m c_r θ'²``
    (N, normal force, >= 0 while in contact) and ``F_t = Im(e^{-iθ}F)`` (N, the
    static friction force, tangential contact force on the rotor ``-F_t i e^{iθ}``);
    rolling is consistent while ``|F_t| <= μ N``.
    """
    with mp.workdps(dps + GUARD_DIGITS):
        model = _ContactModel(par, psi0, Omega, F_ext, a)
        p = model.p
        om = -p["R"] * model.Omega / p["c_r"]
        t = _mpf(t)
        th = _mpf(theta0) + om * t
        re, im = model.forces(t, th, om)
        return {"theta": th, "dtheta": om, "N": re + p["m"] * p["c_r"] * om**2, "F_t": im}
