"""High-precision (mpmath) checks for the rotor with the spin as a state (spin-SPEC, MODEL §6).

Independent of ``fmu_src/rotortd`` and of :mod:`tests.reference.spin_reference` (no shared
code). SI units, inertial frame, complex positions.

* :func:`mp_flight`: one free flight with the bearing on (Omega varies through the reaction term
  ``e_c Im(conj(F_amb + F_ext) E)``), integrated by an automatic-differentiation Taylor-series
  method of order ``order`` (default ``dps + 10``) with a step ``h <= 1/(4 w)``, ``w`` the largest
  rate of the problem (``|Omega|``, ``sqrt(k/m)``, ``c/m``); the truncation term of each step is
  ``~ 4^-order``, far below ``10^-dps``. Returns ``(z, v, psi, Omega)`` at ``t``.
* :func:`mp_impact`: the SPEC's impact law (restitution, Coulomb with the slip after the impact,
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
    """(P_n, P_t, rdot+, v_rel+, stick, dT) at restitution d_eff (SPEC steps 1-4)."""
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
    """The SPEC impact law in mpmath (``cap`` as in the float reference: "largest" for the
    largest admissible d_eff in [0, d], "spec" for the SPEC's literal bisection recipe).
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
