"""Regenerate the validation scenes and their high-precision references (models/scenes/).

    python tests/reference/make_references.py [--only NAME ...] [--jobs N] [--dps 40]

For every scene of :data:`SCENES` this writes, in the FMI cross-check layout:

* ``<Scene>_par.json``  FMU start values (SI) + description + reference notes;
* ``<Scene>_ref.opt``   StartTime, StopTime, StepSize (reference output grid), RelTol;
* ``<Scene>_in.csv``    input signal (only where an input varies: amb_on for the drop);
* ``<Scene>_ref.csv``   time + outputs (x, y, vx, vy, r_rel, u_re, u_im, du_re, du_im, mode,
  n_impacts) on the reference grid, from mpmath (``--dps`` digits, default 40);
* ``<Scene>_impacts.csv``  every impact from mpmath: t, x, y, vx-, vy-, vx+, vy+, rdot (SI);
* ``<Scene>_direct.csv`` / ``<Scene>_direct_impacts.csv``: the same from the independent
  scipy DOP853 integrator (tests/reference/direct.py, rtol 1e-13) -- a second reference;
* ``<Scene>_sens.json`` amplification of a 1e-12 (scaled) perturbation of the initial state,
  per impact, per grid point and at the end, measured with the float64 core
  (``rotortd.TouchdownCore``): the basis of the tolerances (tests/validation_lib.py).

The mpmath reference (tests/reference/mp_reference.py, independent of the product code):

* free flight + impacts: ``mp_impact_sequence`` (one impact per call, exact ``expm`` flight,
  full-precision event location including grazing), reset law with the stick cap;
* **low-speed rule** (chattering): at each impact the reference evaluates the product's rule
  (1) itself, in mpmath: with the outward normal acceleration ``A`` of the contact-free forces
  at the wall (after the reset), the impact is made plastic and sustained contact begins when
  the rebound height ``(d rdot-)^2/(2A) <= ETA_HEIGHT c_r`` (ETA_HEIGHT = 1e-14). This is the
  documented chattering cut-off ``v_stop = sqrt(2 A ETA_HEIGHT c_r)/d`` (about 1e-7 c_r Omega at
  the chapter's values). It is the same *model* as the product's (docs/model.md §6), so the
  reference solves the regularised model to 40 digits; the cut-off's own modelling error
  (O(h_b) in position) is not part of the comparison. Rule (2) (d close to 1, cascades of more
  than 1000 impacts) is not modelled: a scene that would reach it raises.
* sliding: ``mp_sliding`` (Taylor AD integrator, restarted at each grid point); rolling: the
  closed form ``mp_rolling_normal_force`` with the friction cone and N >= 0 checked at 16
  points per grid interval. Slip reversal and lift-off from rolling are not modelled (raise).

Run time (2 cores, ``--jobs 2``): about 2.5 minutes for all scenes (measured 141 s; chattering
scenes dominate: a few hundred mp impacts each). A regeneration script, not part of CI.
"""

from __future__ import annotations

import argparse
import cmath
import itertools
import json
import math
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from mpmath import mp

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tests.reference import mp_reference as M  # noqa: E402
from tests.reference.direct import direct_simulate  # noqa: E402

SCENE_DIR = ROOT / "models" / "scenes"
OMEGA = 184.2
"""Spin speed (rad/s), the FMU input's start value, held constant in every scene."""
ETA_HEIGHT = 1e-14
"""Low-speed rule (1) threshold on the rebound height, in c_r (docs/model.md §6)."""
CUTOFF_NEAR = 2.0
"""Impacts with rdot- <= CUTOFF_NEAR v_stop have their cut-off speed recorded in the
reference (``cutoffs`` in <Scene>_par.json): the validation needs it to tell whether the
FMU's own speed error at that impact reaches across the cut-off (tests/validation_lib.py)."""
PERTURBATION = 1e-12
"""Scaled perturbation of the initial state for the sensitivity (c_r, c_r Omega)."""
REF_STEP = 1e-3
"""Reference output grid (s)."""
PAR_KEYS = ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")
OUT_COLS = ("x", "y", "vx", "vy", "r_rel", "u_re", "u_im", "du_re", "du_im", "mode", "n_impacts")


# ------------------------------------------------------------------------------ scenes


@dataclass
class Scene:
    """One validation scene: SI parameters, initial state, experiment, input schedule.

    ``par``: dict with PAR_KEYS (+ levitate); ``z0`` (m), ``v0`` (m/s), ``psi0`` (rad) at t=0;
    ``stop`` (s); ``amb_off``: time (s) at which amb_on steps 1 -> 0, or None.
    """

    name: str
    description: str
    par: dict[str, Any]
    z0: complex
    v0: complex
    stop: float
    psi0: float = 0.0
    amb_off: float | None = None
    notes: list[str] = field(default_factory=list)

    def segments(self) -> list[tuple[float, float]]:
        """(t_end s, amb_on) of the input segments."""
        if self.amb_off is None:
            return [(self.stop, 1.0)]
        return [(self.amb_off, 1.0), (self.stop, 0.0)]

    def start_values(self) -> dict[str, Any]:
        """FMU start values (SI) for this scene."""
        sv = {k: float(self.par[k]) for k in PAR_KEYS}
        sv.update(x0=self.z0.real, y0=self.z0.imag, vx0=self.v0.real, vy0=self.v0.imag,
                  psi0=self.psi0)
        return sv


def _scaled_si(gamma: float, **over: float) -> dict[str, Any]:
    """SI parameter dict of the chapter set at ``gamma`` (Omega = 184.2 rad/s), overrides."""
    from rotortd_tools import cycles as C

    p = C.si_params(C.chapter_params(gamma=gamma))
    par = {k: float(getattr(p, k)) for k in PAR_KEYS}
    par["levitate"] = True
    par.update(over)
    return par


def _from_scaled(par: dict[str, Any], U: complex, dU: complex, psi: float = 0.0
                 ) -> tuple[complex, complex]:
    """SI (z, v) of the scaled co-rotating (U, U') at spin angle psi (rad):
    z = c_r U e^{i psi}, v = c_r Omega (U' + i U) e^{i psi}."""
    c_r, E = par["c_r"], cmath.exp(1j * psi)
    return c_r * U * E, c_r * OMEGA * (dU + 1j * U) * E


def _on_cycle(gamma: float, branch: str, frac: float = 0.5
              ) -> tuple[complex, complex, float, Any]:
    """SI state (z, v, psi) a fraction ``frac`` of the period after the cycle's impact.

    The cycle (cycles.find_period_one_cycle) starts on the wall at psi = 0; the three solvers
    all accept an interior start, so the state is advanced by ``frac T`` with the mpmath
    flight and rounded; the spin angle there is psi = Omega frac T (the scene's psi0).
    """
    from rotortd_tools import cycles as C

    cyc = C.find_period_one_cycle(gamma, branch=branch)
    par = _scaled_si(gamma)
    t = frac * cyc.T_si
    z, v = M.mp_flight(par, cyc.z0, cyc.v0, 0.0, OMEGA, 0j, 1.0, t, dps=40)
    return complex(z), complex(v), OMEGA * t, cyc


def _grazing_start(par: dict[str, Any], U_eq: complex, beta: float, excess: float,
                   horizon: float) -> complex:
    """Offset amplitude A so that U0 = U* + A e^{i beta}, U0' = 0 first reaches
    max |U| = 1 + excess (scaled co-rotating) within ``horizon`` (scaled time)."""
    from rotortd_tools import cycles as C
    from scipy.optimize import brentq, minimize_scalar

    flow = C.ScaledFlow(C.chapter_params(gamma=par["c"] / (par["m"] * OMEGA)))
    ts = np.linspace(0.0, horizon, 4001)

    def peak(A: float) -> float:
        w0 = np.array([U_eq + A * cmath.exp(1j * beta), 0.0], dtype=complex)
        r = np.abs(flow.states(w0, ts)[:, 0])
        k = int(np.argmax(r))
        lo, hi = ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)]
        res = minimize_scalar(lambda t: -abs(flow.state(w0, t)[0]), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-12})
        return -res.fun - (1.0 + excess)

    return U_eq + brentq(peak, 0.01, 0.3, xtol=1e-15) * cmath.exp(1j * beta)


def build_scenes() -> list[Scene]:
    """All validation scenes (initial states from the chapter tools where needed)."""
    from rotortd_tools import cycles as C

    scenes: list[Scene] = []
    p03 = _scaled_si(0.3)
    U03 = C.regular_equilibrium(C.chapter_params(gamma=0.3))
    z, v = _from_scaled(p03, U03 + 0.05, 0j)
    scenes.append(Scene("Fig52a_equilibrium", "Fig. 5-2a: gamma = 0.3, start 0.05 c_r off the "
                        "admissible whirl U*, no contact", p03, z, v, 0.1))
    z, v = _from_scaled(p03, 0.75 * U03, 0j)
    scenes.append(Scene("Transient_to_whirl", "gamma = 0.3, start at 0.75 U* co-rotating with "
                        "the whirl: a transient settling to the regular equilibrium", p03, z, v,
                        0.3))
    Ug = _grazing_start(p03, U03, math.pi, 1e-8, 40.0)
    z, v = _from_scaled(p03, Ug, 0j)
    scenes.append(Scene("Near_grazing", "gamma = 0.3, transient tuned so that its first maximum "
                        "of |U| is 1 + 1e-8: a near-grazing impact (rdot- ~ 1e-4 c_r Omega)",
                        p03, z, v, 0.1))
    z, v, psi, cyc = _on_cycle(0.1, "long-large")
    p01 = _scaled_si(0.1)
    scenes.append(Scene("Cycle_g0100", f"gamma = 0.1 on the stable long-large period-T cycle "
                        f"(T = {cyc.T:.6f}/Omega, multipliers {_mults(cyc)}), started T/2 after "
                        "its impact", p01, z, v, 0.1, psi0=psi))
    U1, dU1 = _to_scaled(p01["c_r"], z, v, psi)
    z1, v1 = _from_scaled(p01, U1 + 0.05, dU1, psi)
    scenes.append(Scene("Converge_to_cycle", "gamma = 0.1, start 0.05 c_r (co-rotating, real "
                        "direction) off the stable long-large cycle: impacts converging to the "
                        "period-T cycle", p01, z1, v1, 0.2, psi0=psi))
    z, v, psi, cyc = _on_cycle(0.065, "long-large")
    scenes.append(Scene("Cycle_g0065", f"Fig. 5-2b: gamma = 0.065 on the (unstable) long-large "
                        f"cycle near grazing (T = {cyc.T:.6f}/Omega, multipliers {_mults(cyc)}), "
                        "started T/2 after its impact", _scaled_si(0.065), z, v, 0.1, psi0=psi))
    scenes.append(Scene("Chatter_to_rub", "gamma = 0.3 from rest at the centre: impacts, "
                        "chattering, accumulation, sliding onto the forward rub", p03, 0j, 0j,
                        0.25))
    p065 = _scaled_si(0.065)
    scenes.append(Scene("Dry_whirl_rolling", "gamma = 0.065, synthetic backward-whirl start at "
                        "0.99 c_r with v = 0.1 c_r Omega (radial) - 0.9 R Omega i: friction "
                        "(stick cap) drives v_rel to 0, the rotor rolls", p065,
                        0.99 * p065["c_r"] + 0j,
                        complex(0.1 * p065["c_r"] * OMEGA, -0.9 * p065["R"] * OMEGA), 0.02))
    pc = _scaled_si(C.chapter_params().gamma, d=1.0, mu=0.0)
    scenes.append(Scene("Elastic_frictionless", "chapter set (gamma = 0.152), d = 1, mu = 0, "
                        "from rest at the centre", pc, 0j, 0j, 0.1))
    z, v, psi, _ = _on_cycle(0.1, "long-large")
    scenes.append(Scene("High_friction", "gamma = 0.1, mu = 1 started on the mu = 0.15 cycle: "
                        "chattering, sliding, dry whirl into rolling", _scaled_si(0.1, mu=1.0), z,
                        v, 0.05, psi0=psi))
    pd = _scaled_si(C.chapter_params().gamma, g=9.81)
    scenes.append(Scene("AMB_drop", "chapter set, horizontal rotor (g = 9.81, bias force on), at "
                        "rest at the centre; amb_on 1 -> 0 at 0.01 s: drop onto the bearing", pd,
                        0j, 0j, 0.1, amb_off=0.01))
    return scenes


def _mults(cyc: Any) -> str:
    """Multipliers of a cycle as short text."""
    return ", ".join(f"{m.real:.4f}" if abs(m.imag) < 1e-12 else f"{m:.4f}"
                     for m in cyc.multipliers)


def _to_scaled(c_r: float, z: complex, v: complex, psi: float = 0.0
               ) -> tuple[complex, complex]:
    """Scaled co-rotating (U, U') of SI (z, v) at spin angle psi (rad)."""
    E = cmath.exp(-1j * psi)
    U = z * E / c_r
    return U, v * E / (c_r * OMEGA) - 1j * U


# ------------------------------------------------------------------------------ mp reference


@dataclass
class MpState:
    """Reference state (mpmath, SI, inertial): time, position, velocity, mode, contact angle."""

    t: Any
    z: Any
    v: Any
    mode: int = 0
    theta: Any = 0
    dtheta: Any = 0
    n_imp: int = 0


@dataclass
class MpRun:
    """mp reference of one scene: impacts, grid samples, contact events, end state."""

    impacts: list[dict[str, Any]] = field(default_factory=list)
    samples: list[MpState] = field(default_factory=list)
    events: list[tuple[float, str]] = field(default_factory=list)


def _psi(sc: Scene, t: Any) -> Any:
    """Spin angle (rad) at time t (s)."""
    return mp.mpf(sc.psi0) + mp.mpf(OMEGA) * t


def _outward_accel(sc: Scene, a: float, t: Any, z: Any, v: Any) -> Any:
    """A = N_free/m (m/s^2) at the wall point z with velocity v (tangential part used)."""
    par = _mp_par(sc)
    model = M._ContactModel(par, _psi(sc, t), OMEGA, 0j, a)
    n = z / abs(z)
    dtheta = (mp.conj(n) * v).imag / abs(z)
    return model.normal_force(0, mp.arg(z), dtheta) / par["m"]


def _mp_par(sc: Scene) -> dict[str, Any]:
    """Parameter dict for mp_reference."""
    return {**{k: sc.par[k] for k in PAR_KEYS}, "levitate": sc.par.get("levitate", True)}


def _low_speed_cutoff(sc: Scene, a: float, t: Any, imp: dict[str, Any]) -> Any:
    """Rule (1) of the low-speed rule, evaluated in mpmath (see the module docstring): the
    cut-off speed v_stop = sqrt(2 A ETA_HEIGHT c_r)/d (m/s) at this impact, at or below which
    it is plastic (inf for d = 0: no rebound); None where A <= 0 (no contact possible)."""
    A = _outward_accel(sc, a, t, imp["z"], imp["v_plus"])
    if A <= 0:
        return None
    d = mp.mpf(sc.par["d"])
    if d == 0:
        return mp.inf
    if d >= mp.mpf("0.99") and imp["rdot"] < mp.mpf(1e-3) * sc.par["c_r"] * OMEGA:
        raise NotImplementedError("low-speed rule (2) regime (d close to 1) not modelled")
    return mp.sqrt(2 * A * ETA_HEIGHT * mp.mpf(sc.par["c_r"])) / d


def _free_to(sc: Scene, run: MpRun, st: MpState, a: float, t_stop: Any, dps: int) -> MpState:
    """Free flight + impacts from st to t_stop, or to the start of sustained contact."""
    par = _mp_par(sc)
    while st.t < t_stop:
        res = M.mp_impact_sequence(par, st.z, st.v, _psi(sc, st.t), OMEGA, 0j, a,
                                   t_stop - st.t, max_impacts=1, dps=dps)
        if res["stopped"] == "t_end":
            return MpState(t_stop, res["z"], res["v"], 0, n_imp=st.n_imp)
        imp = dict(res["impacts"][0])
        t_imp = st.t + imp["t"]
        imp["t"] = t_imp
        v_stop = _low_speed_cutoff(sc, a, t_imp, imp)
        imp["v_stop"] = v_stop
        if v_stop is not None and imp["rdot"] <= v_stop:
            plastic = M.mp_reset({**par, "d": 0.0}, imp["z"], imp["v_minus"], OMEGA, dps=dps)
            imp["v_plus"] = plastic["v_plus"]
            imp["plastic"] = True
            run.impacts.append(imp)
            return _enter_contact(sc, run, MpState(t_imp, imp["z"], imp["v_plus"], 0,
                                                   n_imp=st.n_imp + 1), a)
        imp["plastic"] = False
        run.impacts.append(imp)
        st = MpState(t_imp, imp["z"], imp["v_plus"], 0, n_imp=st.n_imp + 1)
    return st


def _enter_contact(sc: Scene, run: MpRun, st: MpState, a: float) -> MpState:
    """Sustained contact from an on-wall state: sliding, or rolling if v_rel = 0."""
    n = st.z / abs(st.z)
    st.theta = mp.arg(st.z)
    st.dtheta = (mp.conj(n) * st.v).imag / mp.mpf(sc.par["c_r"])
    vrel = sc.par["R"] * OMEGA + sc.par["c_r"] * st.dtheta
    st.mode = 1 if vrel != 0 else 2
    run.events.append((float(st.t), "sliding" if st.mode == 1 else "rolling"))
    return st


def _contact_state(sc: Scene, st: MpState) -> MpState:
    """Set z, v from theta, theta' (on the circle)."""
    e = mp.expj(st.theta)
    st.z = sc.par["c_r"] * e
    st.v = mp.mpc(0, 1) * sc.par["c_r"] * st.dtheta * e
    return st


def _slide_to(sc: Scene, run: MpRun, st: MpState, a: float, t_stop: Any, dps: int) -> MpState:
    """Sliding (mp_sliding) from st to t_stop or to its first event."""
    res = M.mp_sliding(_mp_par(sc), st.theta, st.dtheta, _psi(sc, st.t), OMEGA, 0j, a,
                       t_stop - st.t, dps=dps)
    new = MpState(st.t + res["t"], 0, 0, 1, res["theta"], res["dtheta"], st.n_imp)
    _contact_state(sc, new)
    if res["event"] == "lift_off":
        run.events.append((float(new.t), "lift_off"))
        new.mode = 0
    elif res["event"] == "v_rel_zero":
        roll = M.mp_rolling_normal_force(_mp_par(sc), new.theta, _psi(sc, new.t), OMEGA, 0j,
                                         a, 0, dps=dps)
        if abs(roll["F_t"]) > sc.par["mu"] * roll["N"]:
            raise NotImplementedError("slip reversal is not modelled by the reference")
        new.mode = 2
        new.dtheta = roll["dtheta"]
        _contact_state(sc, new)
        run.events.append((float(new.t), "rolling"))
    return new


def _roll_to(sc: Scene, st: MpState, a: float, t_stop: Any, dps: int) -> MpState:
    """Rolling (closed form) from st to t_stop; the cone and N >= 0 are checked at 16 points."""
    par = _mp_par(sc)
    dt = t_stop - st.t
    for j in range(1, 17):
        r = M.mp_rolling_normal_force(par, st.theta, _psi(sc, st.t), OMEGA, 0j, a, dt * j / 16,
                                      dps=dps)
        if r["N"] < 0 or abs(r["F_t"]) > sc.par["mu"] * r["N"]:
            raise NotImplementedError("rolling leaves the friction cone: not modelled")
    new = MpState(t_stop, 0, 0, 2, r["theta"], r["dtheta"], st.n_imp)
    return _contact_state(sc, new)


def mp_scene(sc: Scene, grid: list[Any], dps: int = 40) -> MpRun:
    """The mp reference of a scene: impacts and states at the grid times (s, mpf)."""
    run = MpRun()
    with mp.workdps(dps + M.GUARD_DIGITS):
        st = MpState(mp.zero, mp.mpc(sc.z0), mp.mpc(sc.v0))
        run.samples.append(st)
        seg_ends = [(mp.mpf(repr(t)), a) for t, a in sc.segments()]
        for tk in grid[1:]:
            while st.t < tk:
                t_seg, a = next((te, a) for te, a in seg_ends if te > st.t)
                t_stop = min(tk, t_seg)
                st = _advance(sc, run, st, a, t_stop, dps)
            run.samples.append(st)
    return run


def _advance(sc: Scene, run: MpRun, st: MpState, a: float, t_stop: Any, dps: int) -> MpState:
    """One advance in the current mode (free / sliding / rolling) towards t_stop."""
    if st.mode == 0:
        return _free_to(sc, run, st, a, t_stop, dps)
    if st.mode == 1:
        return _slide_to(sc, run, st, a, t_stop, dps)
    return _roll_to(sc, st, a, t_stop, dps)


# ------------------------------------------------------------------------------ core runs


def core_run(sc: Scene, z0: complex, v0: complex, grid: np.ndarray) -> dict[str, Any]:
    """Float64 core (rotortd.TouchdownCore) stepped to each grid time: impacts, samples."""
    from rotortd import RotorParams, TouchdownCore

    p = RotorParams(**{k: float(sc.par[k]) for k in PAR_KEYS},
                    levitate=bool(sc.par.get("levitate", True)))
    core = TouchdownCore(p, z0=z0, v0=v0, psi0=sc.psi0, t0=0.0)
    impacts, zs, vs = [], [z0], [v0]
    for t0, t1 in itertools.pairwise(grid):
        a = 0.0 if sc.amb_off is not None and t0 >= sc.amb_off - 1e-12 else 1.0
        rep = core.step(float(t1 - t0), OMEGA, 0j, a)
        if rep.status != 0:
            raise RuntimeError(f"core step failed: {rep.message}")
        impacts += [(i.t, i.z, i.v_minus, i.v_plus) for i in rep.impacts]
        zs.append(core.z)
        vs.append(core.v)
    return {"impacts": impacts, "z": np.array(zs), "v": np.array(vs)}


def _scaled_diff(sc: Scene, a: dict[str, Any], b: dict[str, Any]) -> dict[str, Any]:
    """Scaled differences of two core runs: per impact (t, z, v-, v+), per sample, end."""
    c_r, vs = sc.par["c_r"], sc.par["c_r"] * OMEGA
    n = min(len(a["impacts"]), len(b["impacts"]))
    dt = [abs(a["impacts"][i][0] - b["impacts"][i][0]) * OMEGA for i in range(n)]
    dz = [abs(a["impacts"][i][1] - b["impacts"][i][1]) / c_r for i in range(n)]
    dvm = [abs(a["impacts"][i][2] - b["impacts"][i][2]) / vs for i in range(n)]
    dvp = [abs(a["impacts"][i][3] - b["impacts"][i][3]) / vs for i in range(n)]
    ds = np.maximum(np.abs(a["z"] - b["z"]) / c_r, np.abs(a["v"] - b["v"]) / vs)
    return {"n": (len(a["impacts"]), len(b["impacts"])), "t": dt, "z": dz, "vm": dvm,
            "vp": dvp, "s": ds.tolist()}


def sensitivity(sc: Scene, grid: np.ndarray, n_ref: int) -> dict[str, Any]:
    """Amplification of a PERTURBATION (scaled) of the initial state, 8 directions.

    Directions: +-1e-12 c_r on x and y, +-1e-12 c_r Omega on vx and vy. Amplification of a
    quantity = max over directions of |difference| (scaled) / 1e-12. Impacts are matched by
    index; an impact beyond the shorter list (the count changed) gets ``None``, and so does
    every reference impact (``n_ref`` of them) beyond the float64 nominal run's own count.
    """
    c_r = sc.par["c_r"]
    nominal = core_run(sc, sc.z0, sc.v0, grid)
    dirs = [(c_r, 0j), (1j * c_r, 0j), (0j, c_r * OMEGA), (0j, 1j * c_r * OMEGA)]
    amp: dict[str, Any] = {}
    counts = [len(nominal["impacts"])]
    for sgn in (1.0, -1.0):
        for dz, dv in dirs:
            pert = core_run(sc, sc.z0 + sgn * PERTURBATION * dz, sc.v0 + sgn * PERTURBATION * dv,
                            grid)
            diff = _scaled_diff(sc, nominal, pert)
            counts.append(len(pert["impacts"]))
            for key in ("t", "z", "vm", "vp", "s"):
                amp[key] = _max_amp(amp.get(key), diff[key], len(nominal["impacts"])
                                    if key != "s" else len(grid))
    for key in ("t", "z", "vm", "vp"):
        amp[key] = (amp[key] + [None] * n_ref)[:n_ref]
    amp["counts"] = counts
    amp["end"] = amp["s"][-1]
    amp["max"] = max(x for key in ("t", "z", "vm", "vp", "s") for x in amp[key]
                     if x is not None) if counts else 0.0
    return amp


def _max_amp(acc: list[Any] | None, diff: list[float], n: int) -> list[Any]:
    """Running max of diff/PERTURBATION; entries missing from diff become None."""
    acc = acc if acc is not None else [0.0] * n
    out = []
    for i in range(n):
        if acc[i] is None or i >= len(diff):
            out.append(None)
        else:
            out.append(max(acc[i], diff[i] / PERTURBATION))
    return out


# ------------------------------------------------------------------------------ writing


def _fmt(x: Any) -> str:
    """Decimal text of an mp or float number (25 significant digits)."""
    if isinstance(x, float):
        return repr(float(x))
    return mp.nstr(mp.mpf(x), 25, min_fixed=-1, max_fixed=-1)


def _outputs(sc: Scene, st: MpState) -> list[Any]:
    """OUT_COLS values of a reference state (SI, scaled co-rotating as the FMU defines)."""
    c_r = sc.par["c_r"]
    E = mp.expj(-_psi(sc, st.t))
    U = st.z * E / c_r
    dU = st.v * E / (c_r * OMEGA) - mp.mpc(0, 1) * U
    return [st.z.real, st.z.imag, st.v.real, st.v.imag, abs(st.z) / c_r, U.real, U.imag,
            dU.real, dU.imag, st.mode, st.n_imp]


def write_csv(path: Path, header: list[str], rows: list[list[Any]]) -> None:
    """CSV with a quoted header and full-precision numbers."""
    with path.open("w", newline="") as fh:
        fh.write(",".join(f'"{h}"' for h in header) + "\n")
        for row in rows:
            fh.write(",".join(str(x) if isinstance(x, int) else _fmt(x) for x in row) + "\n")


IMPACT_COLS = ["t", "x", "y", "vx_minus", "vy_minus", "vx_plus", "vy_plus", "rdot"]


def _impact_rows(impacts: list[dict[str, Any]]) -> list[list[Any]]:
    """Rows of an impacts CSV."""
    return [[i["t"], i["z"].real, i["z"].imag, i["v_minus"].real, i["v_minus"].imag,
             i["v_plus"].real, i["v_plus"].imag, i["rdot"]] for i in impacts]


def _direct_files(sc: Scene, grid: np.ndarray) -> tuple[list[list[Any]], list[list[Any]], str]:
    """Direct-integration samples and impacts (floats)."""
    segs = [(t, OMEGA, 0j, a) for t, a in sc.segments()]
    res = direct_simulate(_mp_par(sc), sc.z0, sc.v0, sc.psi0, 0.0, segs, t_eval=grid)
    s = res.samples
    rows = [[float(t), float(z.real), float(z.imag), float(v.real), float(v.imag), int(m)]
            for t, z, v, m in zip(s["t"], s["z"], s["v"], s["mode"])]
    imps = [[i["t"], i["z"].real, i["z"].imag, i["v_minus"].real, i["v_minus"].imag,
             i["v_plus"].real, i["v_plus"].imag, i["rdot"]] for i in res.impacts]
    return rows, imps, res.status


def make_scene(sc: Scene, dps: int = 40) -> dict[str, Any]:
    """Compute and write every file of one scene; returns timing and summary."""
    t0 = time.perf_counter()
    n = round(sc.stop / REF_STEP)
    grid = np.array([k * REF_STEP for k in range(n + 1)])
    with mp.workdps(dps + M.GUARD_DIGITS):
        mp_grid = [mp.mpf(k) * mp.mpf(repr(REF_STEP)) for k in range(n + 1)]
    run = mp_scene(sc, mp_grid, dps)
    t_mp = time.perf_counter() - t0
    out = SCENE_DIR
    write_csv(out / f"{sc.name}_ref.csv", ["time", *OUT_COLS],
              [[grid[k], *_outputs(sc, st)] for k, st in enumerate(run.samples)])
    write_csv(out / f"{sc.name}_impacts.csv", IMPACT_COLS, _impact_rows(run.impacts))
    d_rows, d_imps, d_status = _direct_files(sc, grid)
    write_csv(out / f"{sc.name}_direct.csv", ["time", "x", "y", "vx", "vy", "mode"], d_rows)
    write_csv(out / f"{sc.name}_direct_impacts.csv", IMPACT_COLS, d_imps)
    sens = sensitivity(sc, grid, len(run.impacts))
    (out / f"{sc.name}_sens.json").write_text(json.dumps(sens, indent=1))
    _write_meta(sc, run, dps, d_status, time.perf_counter() - t0, t_mp)
    return {"scene": sc.name, "impacts": len(run.impacts), "events": run.events,
            "seconds": time.perf_counter() - t0, "mp_seconds": t_mp, "amp_max": sens["max"],
            "counts": sens["counts"]}


def _write_meta(sc: Scene, run: MpRun, dps: int, d_status: str, secs: float, t_mp: float
                ) -> None:
    """<Scene>_par.json, <Scene>_ref.opt and (if inputs vary) <Scene>_in.csv."""
    plastic = [i for i, imp in enumerate(run.impacts) if imp.get("plastic")]
    cutoffs = [[i, float(imp["v_stop"])] for i, imp in enumerate(run.impacts)
               if imp.get("v_stop") is not None and mp.isfinite(imp["v_stop"])
               and imp["rdot"] <= CUTOFF_NEAR * imp["v_stop"]]
    meta = {"name": sc.name, "description": sc.description, "start_values": sc.start_values(),
            "Omega": OMEGA, "stop_time": sc.stop, "amb_off": sc.amb_off,
            "reference": {"dps": dps, "eta_height": ETA_HEIGHT, "n_impacts": len(run.impacts),
                          "plastic_impacts": plastic, "cutoffs": cutoffs,
                          "contact_events": run.events,
                          "direct_status": d_status, "seconds": round(secs, 1),
                          "mp_seconds": round(t_mp, 1)}}
    (SCENE_DIR / f"{sc.name}_par.json").write_text(json.dumps(meta, indent=1))
    (SCENE_DIR / f"{sc.name}_ref.opt").write_text(
        f"StartTime, 0.0\nStopTime, {sc.stop!r}\nStepSize, {REF_STEP!r}\nRelTol, 1e-40\n")
    if sc.amb_off is not None:
        (SCENE_DIR / f"{sc.name}_in.csv").write_text(
            f'"time","amb_on"\n0.0,1.0\n{sc.amb_off!r},1.0\n{sc.amb_off!r},0.0\n'
            f"{sc.stop!r},0.0\n")


def _job(args: tuple[str, int]) -> dict[str, Any]:
    """Worker: build the scene list (cheap) and make one scene."""
    name, dps = args
    sc = next(s for s in build_scenes() if s.name == name)
    return make_scene(sc, dps)


def main(argv: list[str] | None = None) -> None:
    """Command line entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--dps", type=int, default=40)
    args = ap.parse_args(argv)
    SCENE_DIR.mkdir(parents=True, exist_ok=True)
    names = [s.name for s in build_scenes() if not args.only or s.name in args.only]
    t0 = time.perf_counter()
    run: Callable[..., Any]
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        run = ex.map
        for res in run(_job, [(n, args.dps) for n in names]):
            print(json.dumps(res), flush=True)
    print(f"total {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    main()
