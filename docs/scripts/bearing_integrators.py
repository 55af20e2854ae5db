"""Why the drop onto the real bearing costs what it costs (issue 24, item 5): the contact
segment's integrator measured against the alternatives, in one run.

The drop of issue 24 (docs/bearing.md; the chapter's rotor with gravity from its levitated
whirl at 184.2 rad/s, all three options on, k_c = 1e9 N/m) over its first ``--t-end``
seconds at 1e-4 s steps of the core, with ``segments/bearing_contact.py``'s integrator

- as shipped: Gragg-Bulirsch-Stoer at RTOL 1e-13 per step, at least ``k_min`` = 4 columns;
- with k_min = 5 and 6 (higher order, longer steps);
- at RTOL 1e-10 and 1e-8 (what a looser accuracy would buy);
- replaced by the linearly implicit midpoint rule of Bader & Deuflhard, extrapolated on
  the sequence 2, 6, 10, 14, 22, 34, 50, with the exact Jacobian of the stiff part (the
  kinematic rows and the compliant law's rank-one share a g^T: the derivative of the
  accelerations with respect to N times the gradient of N; checked here against a central
  difference of the right-hand side), with the step capped at a radian of the contact's
  natural frequency as shipped, and uncapped (2e-4 s).

Printed per variant: CPU seconds per simulated second, accepted extrapolated steps,
right-hand sides (adaptive steps; event and peak re-integrations), the state component
whose error bounds the step most often, and Omega at the end against the shipped run.
The implementation of the implicit rule lives here only: it did not pay (docs/bearing.md,
"Cost"). Writes docs/bearing_integrators.json.

    python docs/scripts/bearing_integrators.py [--t-end 0.1]
"""

from __future__ import annotations

import argparse
import cmath
import collections
import dataclasses
import json
import math
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rotortd.bodies.race import BearingParams
from rotortd.params import RotorParams
from rotortd.segments import bearing_contact as bc
from rotortd.segments import gbs
from rotortd.step.simulator import TouchdownCore

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "docs" / "bearing_integrators.json"
W0, H = 184.2, 1e-4
SEQUENCE_LI = (2, 6, 10, 14, 22, 34, 50)
NAMES = ["x", "y", "x'", "y'", "psi", "Omega", "x_b", "y_b", "x_b'", "y_b'", "omega_b",
         "int N", "int F_t", "int F_c x", "int F_c y", "E_fric", "E_damp", "E_drag",
         "E_support", "int F_s x", "int F_s y"]
Vector = list[float]


def drop_core() -> TouchdownCore:
    """Issue 24's drop (docs/bearing.md): all options on, k_c = 1e9 N/m, p_c = 1."""
    p = RotorParams(g=9.81, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    bearing = BearingParams(race_turns=True, J_b=2e-4, T_b0=0.02, c_bw=1e-5, omega_b0=0.0,
                            support_compliant=True, m_b=2.0, k_b=5e7, c_b=2e3,
                            contact_compliant=True, k_c=1e9, p_c=1.0)
    return TouchdownCore(p, J=0.04, z0=Z1, v0=1j * W0 * Z1, Omega0=W0, bearing=bearing)


def stiff_jacobian(model: bc.BearingModel, y: Vector) -> tuple[float, ...] | None:
    """The compliant law's share of the Jacobian of y' at y as a g^T (flat: a over x', y',
    Omega, x_b', y_b', omega_b; g over x, y, x_b, y_b, then x', y', x_b', y_b'), from the
    module docstring of segments/bearing_contact.py; None where N does not depend on y."""
    if not model.law.compliant or model.cs.clamped:
        return None
    x, yy, vx, vy, psi, _, xb, yb, vxb, vyb = y[:10]
    Dx, Dy = x - xb, yy - yb
    r = math.hypot(Dx, Dy)
    delta = r - model.c_r
    if not delta > 0.0:
        return None
    nx, ny = Dx / r, Dy / r
    ux, uy = vx - vxb, vy - vyb
    dd = nx * ux + ny * uy
    cE, sE = math.cos(psi + model.phi), math.sin(psi + model.phi)
    e_c, iJ, im, i_mb = model.e_c, model.iJ, model.im, model.i_mb
    B = e_c * (nx * sE - ny * cE)
    A = model.R - e_c * (nx * cE + ny * sE)
    q = model.mus if model.cs.s != 0.0 else -A * B * iJ / (im + A * A * iJ + i_mb + model.w_b)
    Px, Py = nx - q * ny, ny + q * nx
    dOm = -(B + A * q) * iJ
    a = (-Px * im + e_c * dOm * sE, -Py * im - e_c * dOm * cE, dOm, Px * i_mb, Py * i_mb,
         model.law.R_b * q * model.iJb)
    N_el = model.law.K * delta ** model.law.p
    N_d = model.law.p * N_el / delta * (1.0 + model.cs.chi * dd)
    N_v = N_el * model.cs.chi
    gx = N_d * nx + N_v * (ux - nx * dd) / r
    gy = N_d * ny + N_v * (uy - ny * dd) / r
    return (*a, gx, gy, -gx, -gy, N_v * nx, N_v * ny, -N_v * nx, -N_v * ny)


def dense_jacobian(J: tuple[float, ...]) -> list[list[float]]:
    """The 11 x 11 matrix of stiff_jacobian's J with the kinematic rows x' = v."""
    M = [[0.0] * 11 for _ in range(11)]
    for i, ai in zip((2, 3, 5, 8, 9, 10), J[:6]):
        for j, gj in zip((0, 1, 6, 7, 2, 3, 8, 9), J[6:]):
            M[i][j] = ai * gj
    for p, v in ((0, 2), (1, 3), (6, 8), (7, 9)):
        M[p][v] = 1.0
    return M


def solver(J: tuple[float, ...]) -> Callable[[float], Callable[[Vector], Vector]]:
    """h -> x = (I - h M)^{-1} b (in place) for M = dense_jacobian(J): the velocities by
    Sherman-Morrison, then the positions (x_p = b_p + h x_v)."""
    a2, a3, a5, a8, a9, a10, g0, g1, g6, g7, v2, v3, v8, v9 = J

    def for_h(h: float) -> Callable[[Vector], Vector]:
        G2, G3, G8, G9 = h * g0 + v2, h * g1 + v3, h * g6 + v8, h * g7 + v9
        den = 1.0 - h * (G2 * a2 + G3 * a3 + G8 * a8 + G9 * a9)

        def solve(b: Vector) -> Vector:
            sp = h * (g0 * b[0] + g1 * b[1] + g6 * b[6] + g7 * b[7])
            c2, c3, c8, c9 = b[2] + a2 * sp, b[3] + a3 * sp, b[8] + a8 * sp, b[9] + a9 * sp
            t = h * (G2 * c2 + G3 * c3 + G8 * c8 + G9 * c9) / den
            b[2], b[3], b[8], b[9] = c2 + a2 * t, c3 + a3 * t, c8 + a8 * t, c9 + a9 * t
            b[5] += a5 * (sp + t)
            b[10] += a10 * (sp + t)
            for p, v in ((0, 2), (1, 3), (6, 8), (7, 9)):
                b[p] += h * b[v]
            return b
        return solve
    return for_h


def li_midpoint(rhs: Callable[[float, Vector], Vector], solve_h: Callable[..., Any],
                u0: float, y0: Vector, f0: Vector, H_: float, n: int) -> Vector:
    """Bader & Deuflhard's linearly implicit midpoint rule with n substeps and smoothing."""
    h = H_ / n
    solve = solve_h(h)
    d = solve([h * b for b in f0])
    y = [a + b for a, b in zip(y0, d)]
    for i in range(1, n):
        x = solve([h * b - c for b, c in zip(rhs(u0 + i * h, y), d)])
        d = [c + 2.0 * b for b, c in zip(x, d)]
        y = [a + b for a, b in zip(y, d)]
    x = solve([h * b - c for b, c in zip(rhs(u0 + H_, y), d)])
    return [a + b for a, b in zip(y, x)]


RATIOS_LI = [[(SEQUENCE_LI[j] / SEQUENCE_LI[j - c]) ** 2 - 1.0 for c in range(1, j + 1)]
             for j in range(len(SEQUENCE_LI))]


def li_extrapolated_step(sweep: Callable[..., Vector], u0: float, y0: Vector, f0: Vector,
                         H_: float, scale: Vector, k_min: int = 3,
                         k_fixed: int | None = None) -> tuple[Vector, float, int, int]:
    """gbs.extrapolated_step (its contract) on SEQUENCE_LI: Aitken-Neville in h^2."""
    table: list[Vector] = []
    err, nfev = math.inf, 0
    for j in range(k_fixed or len(SEQUENCE_LI)):
        extr = [sweep(u0, y0, f0, H_, SEQUENCE_LI[j])]
        nfev += SEQUENCE_LI[j]
        for r, b in zip(RATIOS_LI[j], table):
            extr.append([x + (x - w) / r for x, w in zip(extr[-1], b)])
        if j >= 1:
            err = gbs._error_ratio(extr[j], extr[j - 1], scale)
            if k_fixed is None and j + 1 >= k_min and err <= 1.0:
                return extr[j], err, j + 1, nfev
        table = extr
    return table[-1], err, len(table), nfev


def jacobian_check(core_steps: int = 300) -> float:
    """Largest difference between the stiff Jacobian a g^T and a central difference of the
    contact force's share of the right-hand side (the model's minus the clamped model's,
    N = F_t = 0) in the rows of x', y', x_b', y_b' and the columns N depends on, relative to
    the column's largest entry, at the ends of sliding segments of the drop that end
    without an event. What a g^T leaves out is N times the derivative of a (the normal's
    turning), of the relative order of delta/c_r."""
    worst, seen = 0.0, 0
    real_run = bc.BearingContact.run

    def run(self: bc.BearingContact, rem: float, limit: int = bc.WORK_MAX) -> Any:
        nonlocal worst, seen
        end = real_run(self, rem, limit)
        J = stiff_jacobian(self.model, end.y)
        if J is not None and end.event is None and self.model.cs.s != 0.0 and seen < 20:
            seen += 1
            y = list(end.y) + [0.0] * bc.NQ
            M = dense_jacobian(J)
            free = bc.BearingModel(self.model.h, self.model.law,
                                   dataclasses.replace(self.model.cs, clamped=True))
            for j in (0, 1, 2, 3, 6, 7, 8, 9):  # the columns N depends on
                e = 1e-7 * max(abs(y[j]), 1e-6)
                yp, ym = list(y), list(y)
                yp[j] += e
                ym[j] -= e
                col = [(a - b - c + d) / (2 * e) for a, b, c, d in zip(
                    self.model.rhs(0.0, yp), self.model.rhs(0.0, ym), free.rhs(0.0, yp),
                    free.rhs(0.0, ym))][:11]
                size = max(abs(c) for c in col)
                worst = max(worst, max(abs(col[i] - M[i][j]) for i in (2, 3, 8, 9)) / size)
        return end

    bc.BearingContact.run = run  # type: ignore[method-assign]
    try:
        core = drop_core()
        for _ in range(core_steps):
            core.step(H, None, 0j, 0.0, T_drive=0.0)
    finally:
        bc.BearingContact.run = real_run  # type: ignore[method-assign]
    return worst


@contextmanager
def variant(k_min: int = 4, rtol: float = bc.RTOL, implicit: bool = False,
            h_max: float | None = None) -> Iterator[collections.Counter[str]]:
    """The contact segment's integrator changed for the duration (bc's module names patched);
    yields the counter of steps, right-hand sides and limiting components."""
    stats: collections.Counter[str] = collections.Counter()
    real_ext, real_err, real_rtol = gbs.extrapolated_step, gbs._error_ratio, bc.RTOL
    real_init = bc.BearingContact.__init__

    def ext(sweep: Any, u0: float, y0: Vector, f0: Vector, H_: float, scale: Vector,
            **kw: Any) -> Any:
        if "k_min" in kw:
            kw["k_min"] = k_min
        if implicit and (J := stiff_jacobian(model[0], y0)) is not None:
            rhs, solve_h = model[0].rhs, solver(J)
            sweep = lambda u, y, f, HH, n: li_midpoint(rhs, solve_h, u, y, f, HH, n)  # noqa: E731
            out = li_extrapolated_step(sweep, u0, y0, f0, H_, scale, **kw)
        else:
            out = real_ext(sweep, u0, y0, f0, H_, scale, **kw)
        kind = "fixed" if kw.get("k_fixed") else "adaptive"
        stats[f"{kind}_rhs"] += out[3]
        stats[f"{kind}_steps"] += kind == "fixed" or out[1] <= 1.0
        return out

    def err(a: Vector, b: Vector, scale: Vector) -> float:
        e = real_err(a, b, scale)
        if len(scale) == bc.NY + bc.NQ:
            stats["limit " + NAMES[max(range(len(scale)),
                                       key=lambda i: abs(a[i] - b[i]) / scale[i])]] += 1
        return e

    model: list[bc.BearingModel] = []

    def init(self: bc.BearingContact, *args: Any, **kw: Any) -> None:
        real_init(self, *args, **kw)
        model[:] = [self.model]
        if h_max is not None:
            self.h_max = h_max

    bc.RTOL = rtol
    bc.BearingContact.__init__ = init  # type: ignore[method-assign]
    gbs.extrapolated_step, gbs._error_ratio = ext, err  # type: ignore[assignment]
    try:
        yield stats
    finally:
        bc.RTOL = real_rtol
        bc.BearingContact.__init__ = real_init  # type: ignore[method-assign]
        gbs.extrapolated_step, gbs._error_ratio = real_ext, real_err


VARIANTS: dict[str, dict[str, Any]] = {
    "shipped: GBS, k_min 4, RTOL 1e-13": {},
    "GBS, k_min 5": {"k_min": 5},
    "GBS, k_min 6": {"k_min": 6},
    "GBS, RTOL 1e-10": {"rtol": 1e-10},
    "GBS, RTOL 1e-8": {"rtol": 1e-8},
    "linearly implicit midpoint, k_min 5": {"implicit": True, "k_min": 5},
    "linearly implicit midpoint, k_min 6": {"implicit": True, "k_min": 6},
    "linearly implicit midpoint, k_min 5, step uncapped": {"implicit": True, "k_min": 5,
                                                          "h_max": 2e-4},
    "linearly implicit midpoint, k_min 6, step uncapped": {"implicit": True, "k_min": 6,
                                                          "h_max": 2e-4},
}


def measure(t_end: float, **kw: Any) -> dict[str, Any]:
    """One variant over the drop's first t_end s."""
    with variant(**kw) as stats:
        core = drop_core()
        t0 = time.process_time()
        for _ in range(round(t_end / H)):
            core.step(H, None, 0j, 0.0, T_drive=0.0)
        cpu = time.process_time() - t0
    limits = {k[6:]: v for k, v in stats.items() if k.startswith("limit ")}
    return {"cpu_per_simulated_s": cpu / t_end, "accepted_steps": stats["adaptive_steps"],
            "rhs_adaptive": stats["adaptive_rhs"], "rhs_located": stats["fixed_rhs"],
            "located_reintegrations": stats["fixed_steps"],
            "limiting": dict(sorted(limits.items(), key=lambda kv: -kv[1])[:4]),
            "Omega_end": core.Omega}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--t-end", type=float, default=0.1)
    args = ap.parse_args()
    jac = jacobian_check()
    print(f"stiff Jacobian against a central difference: {jac:.1e} relative (sliding)")
    out: dict[str, Any] = {"t_end": args.t_end, "jacobian_check": jac, "variants": {}}
    base = None
    for name, kw in VARIANTS.items():
        r = measure(args.t_end, **kw)
        base = r["Omega_end"] if base is None else base
        r["Omega_end_minus_shipped"] = r["Omega_end"] - base
        out["variants"][name] = r
        top = ", ".join(f"{k} {v}" for k, v in r["limiting"].items())
        print(f"{name:52s} {r['cpu_per_simulated_s']:6.2f} s CPU/s  "
              f"{r['accepted_steps']:6d} steps  {r['rhs_adaptive']:7d} + "
              f"{r['rhs_located']:6d} rhs  dOmega {r['Omega_end_minus_shipped']:+.1e}  "
              f"limited by {top}", flush=True)
    OUT.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
