"""High-precision (mpmath) checks for the rotor with the spin as a state (docs/model.md §8).

Independent of ``fmu_src/rotortd`` and of :mod:`tests.reference.spin_reference` (no shared
code). SI units, inertial frame, complex positions.

* :func:`mp_flight`: one free flight with the bearing on (Omega varies through the reaction term
  ``e_c Im(conj(F_amb + F_ext) E)``), integrated by an automatic-differentiation Taylor-series
  method of order ``order`` (default ``dps + 10``) with a step ``h <= 1/(4 w)``, ``w`` the largest
  rate of the problem (``|Omega|``, ``sqrt(k/m)``, ``c/m``); the truncation term of each step is
  ``~ 4^-order``, far below ``10^-dps``. Returns ``(z, v, psi, Omega)`` at ``t``.
* :func:`mp_contact`: one sustained-contact segment (sliding with slip sign s, or rolling) from
  docs/model.md §8, with the impulses int N, int F_t, int F_c and the friction dissipation
  int mu N |v_rel|, optionally stopped at the first zero of v_rel (slip zero), N (lift-off)
  or mu N - |F_t| (slip start, rolling):
  Taylor series by automatic differentiation (exponentials, products and the 2x2 / 3x3 solve
  as series recurrences), order dps + 10, steps of at most 1/(8 w); 40 and 50 digits (12 steps
  per radian) agree to 1e-50 (``tests/test_spin_contact_mp.py``).
* :func:`mp_impact`: the model's impact law (restitution, Coulomb with the slip after the impact,
  stick, energetic cap with its closed forms and the 60-halving bisection) in mpmath.

Free-flight equations::

    E = exp(i (psi + phi)),  F = a (F_bias - c v - k z) + F_ext
    J Omega' = T_drive + e_c Im(conj(F) E)
    m z''    = F - i m g + m e_c (Omega^2 - i Omega') E,   psi' = Omega
"""

from __future__ import annotations

from typing import Any

import mpmath
from mpmath import mp

Num = Any  # mpmath mpf / mpc


def _taylor_step(par: dict[str, Num], z: Num, v: Num, psi: Num, om: Num, h: Num, order: int
                 ) -> tuple[Num, Num, Num, Num]:
    """One Taylor step of length h [s] from (z, v, psi, Omega); coefficients by recurrences."""
    m, c, k, e_c, phi, g, J = (par[x] for x in ("m", "c", "k", "e_c", "phi", "g", "J"))
    a, F_ext, T_drive, F_bias = par["a"], par["F_ext"], par["T_drive"], par["F_bias"]
    zs, vs, ps, os_ = [z], [v], [psi], [om]
    Es: list[Num] = [mpmath.expj(psi + phi)]
    Fs: list[Num] = []
    Ds: list[Num] = []  # Omega'
    Gs: list[Num] = []  # Omega^2 - i Omega'
    for kk in range(order):
        if kk > 0:  # E' = i psi' E  =>  E_k = (i/k) sum_{j=1..k} j psi_j E_{k-j}
            Es.append(1j * mpmath.fsum(j * ps[j] * Es[kk - j] for j in range(1, kk + 1)) / kk)
        Fs.append(a * ((F_bias if kk == 0 else 0) - c * vs[kk] - k * zs[kk])
                  + (F_ext if kk == 0 else 0))
        cfe = mpmath.fsum(mpmath.conj(Fs[j]) * Es[kk - j] for j in range(kk + 1))
        Ds.append(((T_drive if kk == 0 else 0) + e_c * mpmath.im(cfe)) / J)
        om2 = mpmath.fsum(os_[j] * os_[kk - j] for j in range(kk + 1))
        Gs.append(om2 - 1j * Ds[kk])
        ge = mpmath.fsum(Gs[j] * Es[kk - j] for j in range(kk + 1))
        acc = (Fs[kk] - (1j * m * g if kk == 0 else 0)) / m + e_c * ge
        zs.append(vs[kk] / (kk + 1))
        vs.append(acc / (kk + 1))
        ps.append(os_[kk] / (kk + 1))
        os_.append(Ds[kk] / (kk + 1))

    def horner(cs: list[Num]) -> Num:
        r = cs[-1]
        for cc in reversed(cs[:-1]):
            r = r * h + cc
        return r

    return horner(zs), horner(vs), horner(ps), horner(os_)


def mp_flight(params: dict[str, Any], J: float, Omega0: float, z0: complex, v0: complex,
              psi0: float, t: float, a: float = 1.0, F_ext: complex = 0j, T_drive: float = 0.0,
              dps: int = 40, order: int | None = None) -> tuple[Num, Num, Num, Num]:
    """Free flight (no wall) from t = 0 to t [s]; returns (z [m], v [m/s], psi [rad],
    Omega [rad/s]) as mpmath numbers to ~dps digits. Inputs are exact binary floats.

    ``params``: dict m c k e_c phi c_r R mu d g levitate; ``J`` [kg m^2]; held ``a``,
    ``F_ext`` [N] (gravity excluded), ``T_drive`` [N m].
    """
    with mp.workdps(dps + 10):
        par: dict[str, Num] = {x: mpmath.mpf(params[x]) for x in ("m", "c", "k", "e_c", "phi")}
        par["g"] = mpmath.mpf(params.get("g", 0.0))
        par["J"] = mpmath.mpf(J)
        par["a"] = mpmath.mpf(a)
        par["F_ext"] = mpmath.mpc(F_ext)
        par["T_drive"] = mpmath.mpf(T_drive)
        par["F_bias"] = 1j * par["m"] * par["g"] if params.get("levitate", False) else mpmath.mpc(0)
        z, v = mpmath.mpc(z0), mpmath.mpc(v0)
        psi, om = mpmath.mpf(psi0), mpmath.mpf(Omega0)
        T = mpmath.mpf(t)
        w = max(abs(om), mpmath.sqrt(par["k"] / par["m"]), par["c"] / par["m"], mpmath.mpf(1))
        n_steps = int(mpmath.ceil(T * 4 * w * 1.25)) or 1
        h = T / n_steps
        nord = order if order is not None else dps + 10
        for _ in range(n_steps):
            z, v, psi, om = _taylor_step(par, z, v, psi, om, h, nord)
        return +z, +v, +psi, +om


def _sgn(x: Num) -> int:
    return 1 if x > 0 else (-1 if x < 0 else 0)


def _law_at(w: tuple[Num, Num, Num], mu: Num, d_eff: Num, rd: Num, s: Num
            ) -> tuple[Num, Num, Num, Num, bool, Num]:
    """(P_n, P_t, rdot+, v_rel+, stick, dT) at restitution d_eff (the impact law's steps 1-4)."""
    wnn, wnt, wtt = w
    D = (1 + d_eff) * rd
    det = wnn * wtt - wnt * wnt
    pn = (wtt * D - wnt * s) / det
    pt = (wnn * s - wnt * D) / det
    rdp = -d_eff * rd
    if pn >= 0 and abs(pt) <= mu * pn:
        vrp, stick = mpmath.mpf(0), True
    else:
        sig = 1 if pt >= 0 else -1
        pn = D / (wnn + mu * sig * wnt)
        pt = mu * sig * pn
        vrp = s - (wnt * pn + wtt * pt)
        stick = False
    dT = -(pn * (rd + rdp) + pt * (s + vrp)) / 2
    return pn, pt, rdp, vrp, stick, dT


def mp_impact(m: float, J: float, e_c: float, R: float, mu: float, d: float, beta: float,
              rdot_minus: float, v_rel_minus: float, n: complex = 1 + 0j, v_minus: complex = 0j,
              Omega_minus: float = 0.0, dps: int = 40, cap: str = "largest") -> dict[str, Any]:
    """The impact law of docs/model.md §8 in mpmath (``cap`` as in the float reference:
    "largest" for the
    largest admissible d_eff in [0, d], "spec" for the model's literal bisection recipe).
    Returns a dict with P_n, P_t [N s], v_plus [m/s], Omega_plus [rad/s], stick (bool), d_eff,
    E_diss [J] (= -dT), rdot_plus, v_rel_plus [m/s].

    ``beta`` [rad] = psi + phi - theta; ``n`` unit normal; ``v_minus`` (geometric centre's z')
    and ``Omega_minus`` the state before (only used for v_plus, Omega_plus): the mass centre's
    velocity changes by -(P_n + i P_t) n / m, so z' changes by that minus i e_c E dOmega,
    E = n e^{i beta}. Inputs are exact binary floats.
    """
    with mp.workdps(dps + 10):
        M, JJ, ec, RR = (mpmath.mpf(x) for x in (m, J, e_c, R))
        MU, DD, b = mpmath.mpf(mu), mpmath.mpf(d), mpmath.mpf(beta)
        rd, s = mpmath.mpf(rdot_minus), mpmath.mpf(v_rel_minus)
        B = ec * mpmath.sin(b)
        A = RR - ec * mpmath.cos(b)
        w = (1 / M + B * B / JJ, A * B / JJ, 1 / M + A * A / JJ)
        res = _law_at(w, MU, DD, rd, s)
        d_eff = DD
        if res[5] > 0 and rd > 0:
            wnn, wnt, wtt = w
            if res[4]:
                det = wnn * wtt - wnt * wnt
                knn, knt, ktt = wtt / det, -wnt / det, wnn / det
                quad = knn * rd * rd + 2 * knt * rd * s + ktt * s * s
                de = mpmath.sqrt(max(quad, 0) / (knn * rd * rd))
                kind: tuple[bool, int] = (True, 0)
            else:
                sig = _sgn(res[1])
                cc = (wnt + MU * sig * wtt) / (wnn + MU * sig * wnt)
                de = (rd * (1 - MU * sig * cc) + 2 * MU * sig * s) / (rd * (1 + MU * sig * cc))
                kind = (False, sig)
            de = min(max(de, mpmath.mpf(0)), DD)
            trial = _law_at(w, MU, de, rd, s)
            same = trial[4] == kind[0] and (trial[4] or _sgn(trial[1]) == kind[1])
            if same or (trial[5] <= 0 and cap == "spec"):
                d_eff, res = de, trial
            else:
                lo, hi = (de, DD) if trial[5] <= 0 else (mpmath.mpf(0), de)
                for _ in range(60):
                    mid = (lo + hi) / 2
                    if _law_at(w, MU, mid, rd, s)[5] <= 0:
                        lo = mid
                    else:
                        hi = mid
                d_eff, res = lo, _law_at(w, MU, lo, rd, s)
        pn, pt, rdp, vrp, stick, dT = res
        nn = mpmath.mpc(n)
        d_om = -(B * pn + A * pt) / JJ
        E = nn * mpmath.expj(b)
        v_plus = mpmath.mpc(v_minus) - (pn + 1j * pt) * nn / M - 1j * ec * E * d_om
        om_plus = mpmath.mpf(Omega_minus) + d_om
        return {"P_n": +pn, "P_t": +pt, "v_plus": +v_plus, "Omega_plus": +om_plus,
                "stick": stick, "d_eff": +d_eff, "E_diss": -dT, "rdot_plus": +rdp,
                "v_rel_plus": +vrp}


# ------------------------------------------------------------------- sustained contact (§6)
# On the circle z = c_r n, n = e^{i theta}; E = e^{i(psi + phi)}; beta = psi + phi - theta;
# B = e_c sin(beta), A = R - e_c cos(beta). Known forces F_o = F_amb + F_ext - i m g
# + m e_c Omega^2 E, F_amb = a (F_bias - c z' - k z); their torque about the mass centre
# T_o = e_c Im(conj(F_amb + F_ext) E). The contact force on the rotor is -(N + i F_t) n:
#
#     normal:      -m c_r theta'^2 = Re(conj(n) F_o) - N + m e_c Omega' sin(beta)
#     tangential:  m c_r theta''   = Im(conj(n) F_o) - F_t - m e_c Omega' cos(beta)
#     spin:        J Omega'        = T_drive + T_o - B N - A F_t
#
# Sliding (slip sign s): F_t = mu s N, so with rn = Re(conj(n) F_o) + m c_r theta'^2,
# N = rn + m B Omega' and (J + m B (B + mu s A)) Omega' = T_drive + T_o - (B + mu s A) rn.
# Rolling (v_rel = R Omega + c_r theta' = 0): theta'' = -R Omega'/c_r, so
# F_t = Im(conj(n) F_o) + m A Omega' and (J + m (A^2 + B^2)) Omega' = T_drive + T_o - B rn
# - A Im(conj(n) F_o).
#
# Every quantity is a power series in the time from the step's start, built order by order
# (automatic differentiation): exponentials by w' = i u' w, products by Cauchy sums,
# quotients by the division recurrence.


def _conv(a: list[Num], b: list[Num], k: int) -> Num:
    """Coefficient k of the product of two series."""
    return mpmath.fsum(a[j] * b[k - j] for j in range(k + 1))


def _expi_next(w: list[Num], u: list[Num], k: int) -> Num:
    """Coefficient k >= 1 of w = exp(i u) from w[0..k-1] and u[1..k]."""
    return 1j * mpmath.fsum(j * u[j] * w[k - j] for j in range(1, k + 1)) / k


def _contact_series(par: dict[str, Num], s: int, th0: Num, dth0: Num, psi0: Num, om0: Num,
                    order: int) -> dict[str, list[Num]]:
    """Taylor coefficients (orders 0..order) of theta, theta', psi, Omega and of the
    integrands N, F_t, F_c, mu N |v_rel| (orders 0..order-1) of one contact mode from the
    state (s = +-1 sliding, s = 0 rolling, where theta' = -R Omega/c_r)."""
    m, c, k, e_c, phi, g, J = (par[x] for x in ("m", "c", "k", "e_c", "phi", "g", "J"))
    c_r, R, mu = par["c_r"], par["R"], par["mu"]
    a, F_ext, T_drive, F_bias = par["a"], par["F_ext"], par["T_drive"], par["F_bias"]
    rolling = s == 0
    mus = mu * s
    th, ps, om = [th0], [psi0], [om0]
    dth = [-R * om0 / c_r if rolling else dth0]
    bet = [psi0 + phi - th0]
    n = [mpmath.expj(th0)]
    E = [mpmath.expj(psi0 + phi)]
    eb = [mpmath.expj(bet[0])]
    nc: list[Num] = []  # conj(n)
    v: list[Num] = []
    F: list[Num] = []  # F_amb + F_ext
    Fc_: list[Num] = []  # conj(F)
    om2: list[Num] = []
    Fo: list[Num] = []
    B: list[Num] = []
    A: list[Num] = []
    cb: list[Num] = []
    rn: list[Num] = []
    Fot: list[Num] = []
    kk_: list[Num] = []
    den: list[Num] = []
    dW: list[Num] = []
    N: list[Num] = []
    Ft: list[Num] = []
    Fc: list[Num] = []
    NF: list[Num] = []  # N + i F_t
    vrel: list[Num] = []
    diss: list[Num] = []
    for q in range(order):
        if q > 0:
            n.append(_expi_next(n, th, q))
            E.append(_expi_next(E, ps, q))
            eb.append(_expi_next(eb, bet, q))
        nc.append(mpmath.conj(n[q]))
        v.append(1j * c_r * _conv(dth, n, q))
        F.append(a * ((F_bias if q == 0 else 0) - c * v[q] - k * c_r * n[q])
                 + (F_ext if q == 0 else 0))
        Fc_.append(mpmath.conj(F[q]))
        om2.append(_conv(om, om, q))
        Fo.append(F[q] - (1j * m * g if q == 0 else 0) + m * e_c * _conv(om2, E, q))
        T = (T_drive if q == 0 else 0) + e_c * mpmath.im(_conv(Fc_, E, q))
        nFo = _conv(nc, Fo, q)
        rn.append(mpmath.re(nFo) + m * c_r * _conv(dth, dth, q))
        Fot.append(mpmath.im(nFo))
        B.append(e_c * mpmath.im(eb[q]))
        cb.append(mpmath.re(eb[q]))
        A.append((R if q == 0 else 0) - e_c * cb[q])
        if rolling:
            den.append((J if q == 0 else 0) + m * (_conv(A, A, q) + _conv(B, B, q)))
            num = T - _conv(B, rn, q) - _conv(A, Fot, q)
        else:
            kk_.append(B[q] + mus * A[q])
            den.append((J if q == 0 else 0) + m * _conv(B, kk_, q))
            num = T - _conv(kk_, rn, q)
        dW.append((num - mpmath.fsum(den[j] * dW[q - j] for j in range(1, q + 1))) / den[0])
        N.append(rn[q] + m * _conv(B, dW, q))
        if rolling:
            Ft.append(Fot[q] + m * _conv(A, dW, q))
            ddth = -R * dW[q] / c_r
        else:
            Ft.append(mus * N[q])
            ddth = (Fot[q] - Ft[q] - m * e_c * _conv(cb, dW, q)) / (m * c_r)
        NF.append(N[q] + 1j * Ft[q])
        Fc.append(-_conv(NF, n, q))
        vrel.append(R * om[q] + c_r * dth[q])
        diss.append(mus * _conv(N, vrel, q))  # mu N |v_rel| with s v_rel > 0 in the mode
        th.append(dth[q] / (q + 1))
        ps.append(om[q] / (q + 1))
        om.append(dW[q] / (q + 1))
        dth.append(-R * om[q + 1] / c_r if rolling else ddth / (q + 1))
        bet.append(ps[q + 1] - th[q + 1])
    return {"theta": th, "dtheta": dth, "psi": ps, "Omega": om, "N": N, "F_t": Ft,
            "F_c": Fc, "diss": diss, "v_rel": vrel}


def _poly(cs: list[Num], h: Num) -> Num:
    r = cs[-1]
    for cc in reversed(cs[:-1]):
        r = r * h + cc
    return r


def _poly_int(cs: list[Num], h: Num) -> Num:
    """int_0^h of the series."""
    return h * _poly([cc / (j + 1) for j, cc in enumerate(cs)], h)


def _contact_par(params: dict[str, Any], J: float, a: float, F_ext: complex,
                 T_drive: float) -> dict[str, Num]:
    par: dict[str, Num] = {x: mpmath.mpf(params[x])
                           for x in ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu")}
    par["g"] = mpmath.mpf(params.get("g", 0.0))
    par["J"] = mpmath.mpf(J)
    par["a"] = mpmath.mpf(a)
    par["F_ext"] = mpmath.mpc(F_ext)
    par["T_drive"] = mpmath.mpf(T_drive)
    par["F_bias"] = 1j * par["m"] * par["g"] if params.get("levitate", False) else mpmath.mpc(0)
    return par


def mp_contact(params: dict[str, Any], J: float, s: int, theta0: float, dtheta0: float,
               psi0: float, Omega0: float, t: float, a: float = 0.0, F_ext: complex = 0j,
               T_drive: float = 0.0, event: str | None = None, dps: int = 40,
               order: int | None = None, per_rad: int = 8) -> dict[str, Num]:
    """One contact segment (docs/model.md §8) from t = 0 to t [s], or to the first zero of the
    event function (``event``: "slip_zero" for v_rel, sliding only; "lift_off" for N;
    "slip_start" for mu N - |F_t|, rolling only, F_t keeping its sign within a step) if
    that comes first (seen at the ends of its steps); sliding with slip sign s = +-1,
    rolling with s = 0 (theta' = -R Omega/c_r, ``dtheta0`` ignored). Taylor method of order
    ``order`` (default dps + 10) with equal steps of at most 1/(per_rad w), w the largest
    rate (|theta'|, |Omega|, |Omega - theta'|, sqrt(|N|/(m c_r)), sqrt(k/m), c/m, 1 /s). The
    event's zero is the root of its step's polynomial (mpmath.findroot, anderson, then
    Newton polish).

    Returns mpmath numbers: t (end time, s), theta, dtheta, psi, Omega, P_n = int N,
    P_t = int F_t (N s), P_c = int F_c (complex N s), E_diss = int mu N |v_rel| (J),
    N (at the end, N) and event (the name or None). Inputs are exact binary floats.
    """
    with mp.workdps(dps + 10):
        par = _contact_par(params, J, a, F_ext, T_drive)
        nord = order if order is not None else dps + 10
        th, dth, psi, om = (mpmath.mpf(x) for x in (theta0, dtheta0, psi0, Omega0))
        if s == 0:
            dth = -par["R"] * om / par["c_r"]
        ser0 = _contact_series(par, s, th, dth, psi, om, 2)
        w = max(abs(dth), abs(om), abs(om - dth), mpmath.sqrt(abs(ser0["N"][0])
                / (par["m"] * par["c_r"])), mpmath.sqrt(par["k"] / par["m"]),
                par["c"] / par["m"], mpmath.mpf(1))
        T = mpmath.mpf(t)
        n_steps = int(mpmath.ceil(T * per_rad * w)) or 1
        h = T / n_steps
        P_n = P_t = E_d = mpmath.mpf(0)
        P_c = mpmath.mpc(0)
        t_now = mpmath.mpf(0)
        hit = None
        for _ in range(n_steps):
            ser = _contact_series(par, s, th, dth, psi, om, nord)
            tau = h
            if event is not None:
                if event == "slip_start":  # mu N - |F_t| (rolling), F_t of one sign near it
                    sig = 1 if ser["F_t"][0] >= 0 else -1
                    f = [par["mu"] * a - sig * b for a, b in zip(ser["N"], ser["F_t"])]
                else:
                    f = ser["v_rel"] if event == "slip_zero" else ser["N"]
                sgn = (s if event == "slip_zero" else 1)
                if sgn * _poly(f, h) <= 0:
                    root = mpmath.findroot(lambda x, f=f: _poly(f, x), (0, h),
                                           solver="anderson")
                    df = [j * f[j] for j in range(1, len(f))]
                    for _ in range(3):
                        root -= _poly(f, root) / _poly(df, root)
                    tau, hit = root, event
            P_n += _poly_int(ser["N"], tau)
            P_t += _poly_int(ser["F_t"], tau)
            P_c += _poly_int(ser["F_c"], tau)
            E_d += _poly_int(ser["diss"], tau)
            th, dth, psi, om = (_poly(ser[x], tau) for x in ("theta", "dtheta", "psi", "Omega"))
            t_now += tau
            if hit is not None:
                break
        N_end = _contact_series(par, s, th, dth, psi, om, 1)["N"][0]
        return {"t": +t_now, "theta": +th, "dtheta": +dth, "psi": +psi, "Omega": +om,
                "P_n": +P_n, "P_t": +P_t, "P_c": +P_c, "E_diss": +E_d, "N": +N_end,
                "event": hit}
