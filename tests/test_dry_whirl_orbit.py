"""Dry whirl on its orbit (``rotortd.segments.dry_whirl_orbit``, the declared accelerator of
``SpinContact`` for rolling with a c = 0 and T_drive = 0; docs/notes/dry-whirl-quadrature.md
§8).

1. Against the 40-digit Taylor integration ``tests.reference.spin_mp.mp_contact`` (no shared
   code) over one 1e-4 s step of dry whirl of the chapter's rotor at 60 to 2000 rad/s, as
   ``tests/test_dry_whirl_fast.py`` measures the panels: within 1e-13 of its scales.
2. Against the extrapolation integrator (``SpinContact`` with ``accelerate`` False) at
   random rolling states with T_drive = 0 (those of ``tests/test_dry_whirl_fast.py``:
   speeds 60 to 3000 rad/s of both signs, gravity on and off, F_ext up to 2000 N, the
   bearing off or on with its damper off, J from 0.2 to 3 m R^2, steps of 1e-6 to 1e-3 s),
   each step continuing the previous one's orbit; the orbit's grid samples
   (``DryWhirl.beta_row``) against the one definition of the forces (``DryWhirl._forces``).
3. The orbit carries over steps and states: the energy stays the same float, a state
   written mid-orbit and restored continues bit for bit, a state written before the orbit
   was recorded (no ``orbit_energy``) loads, and the work of a step does not depend on the
   speed.
4. It declines where it must: a drive torque, a lift-off not excluded, series that do not
   converge (a slow rotor).
"""

from __future__ import annotations

import cmath
import json
import math
import random
from dataclasses import replace

import pytest
from rotortd import SpinCore
from rotortd.contact.search import SEGMENT_WORK
from rotortd.params import RotorParams
from rotortd.segments import dry_whirl_orbit as orbit_mod
from rotortd.segments.rolling_spin_fast import DryWhirl
from rotortd.segments.spin_contact import HeldInputs, SpinContact

from tests.test_dry_whirl_fast import (
    CHAPTER,
    PSI0,
    SPEEDS,
    TH0,
    TOL,
    H,
    J,
    _errors,
    _held,
    _reference,
    errors_against_the_integrator,
)
from tests.test_dry_whirl_fast import _random_case as _random_fast_case


def _advance(h: HeldInputs, th: float, psi: float, W: float, rem: float,
             prev: orbit_mod.Orbit | None = None):
    return orbit_mod.advance(prev, h, th, psi, W, rem, 10 ** 9, math.inf)


@pytest.mark.parametrize("W", SPEEDS)
def test_one_step_matches_the_40_digit_reference(W: float) -> None:
    new, orb = _advance(_held(), TH0, PSI0, W, H)
    assert new is not None and orb is not None and new.orbit is orb
    assert new.duration == H and new.event is None
    ref = _reference(W)
    mc = CHAPTER["m"] * CHAPTER["c_r"]
    err = _errors(new, TH0, PSI0, W, ref["theta"], ref["psi"], ref["Omega"], ref["P_n"],
                  ref["P_t"], ref["P_c"], mc)
    assert all(v <= TOL for v in err.values()), err


def _random_case(rng: random.Random) -> tuple[HeldInputs, float, float, float, float]:
    """``test_dry_whirl_fast``'s random rolling state with its drive torque taken off."""
    h, W, th, psi, rem, _ = _random_fast_case(rng)
    return HeldInputs(h.p, h.J, h.a, h.F_ext, 0.0), W, th, psi, rem


def test_agrees_with_the_integrator_over_steps_on_one_orbit() -> None:
    """Three steps per case, each continuing the orbit, each against the integrator from the
    same start state."""
    rng = random.Random(11)
    taken, worst = 0, dict.fromkeys(("theta", "psi", "Omega", "P_n", "P_t", "P_c"), 0.0)
    for _ in range(60):
        h, W, th, psi, rem = _random_case(rng)
        prev = None
        for _ in range(3):
            new, prev = _advance(h, th, psi, W, rem, prev)
            if new is None:
                break
            taken += 1
            assert new.duration == rem
            err = errors_against_the_integrator(h, th, psi, W, new)
            for k, v in err.items():
                worst[k] = max(worst[k], v)
            th, psi, W = new.theta, new.psi, new.Omega
    assert taken >= 150, taken
    assert all(v <= TOL for v in worst.values()), worst


def test_grid_samples_are_the_forces_of_the_one_definition() -> None:
    """``beta_row`` (the hot loop of the orbit's and the Levin panel's grids) gives F, D and
    |N| of ``DryWhirl._forces`` at random states, to rounding."""
    rng = random.Random(3)
    worst = 0.0
    for _ in range(200):
        h, W, th, psi, _, _ = _random_fast_case(rng)
        w = DryWhirl(h, th, psi, W)
        betas = [rng.uniform(-math.pi, math.pi) for _ in range(5)]
        grid = w.beta_grid([math.cos(b) for b in betas], [math.sin(b) for b in betas])
        a = psi + h.p.phi
        cE, sE = math.cos(a), math.sin(a)
        dv = rng.uniform(-1e-3, 1e-3) * w.K0
        fs, ds, ns = w.beta_row(grid, cE, sE, w.K0 - 2.0 * dv)
        for b, F, D, N in zip(betas, fs, ds, ns):
            ct, st = math.cos(a - b), math.sin(a - b)
            F1, N1, Ft1, _ = w._forces(ct, st, cE, sE, dv)
            scale = abs(N1) + abs(Ft1)
            worst = max(worst, abs(F - F1) / F1, abs(D - complex(N1, Ft1) * F1) / (scale * F1),
                        abs(N - abs(N1)) / scale)
    assert worst <= 1e-13, worst


def _rolling_core(W: float, params: dict[str, float] | None = None, **kw: float) -> SpinCore:
    """The chapter's rotor (gravity, J = m R^2/2; ``params`` in place of CHAPTER) rolling at
    the bottom of the clearance."""
    p = RotorParams(**(CHAPTER if params is None else params))
    core = SpinCore(p, J, Omega0=W)
    th, dth = -math.pi / 2, -p.R * W / p.c_r
    n = cmath.exp(1j * th)
    core.set_state(replace(core.state, mode=2, theta=th, dtheta=dth, slip=0.0,
                           z=p.c_r * n, v=1j * p.c_r * dth * n, **kw))
    return core


def test_the_orbit_carries_over_steps_and_states() -> None:
    core = _rolling_core(2000.0)
    energies = set()
    for _ in range(20):
        core.step(H, amb_on=0.0)
        energies.add(core.state.orbit_energy)
    assert core.mode == 2 and len(energies) == 1 and not math.isnan(energies.pop())
    assert core._orbit.map is not None and core._orbit.map.ok and core._orbit.map.h == H
    doc = json.loads(json.dumps(core.get_state()))
    assert doc["contact"]["orbit_energy"] is not None and doc["contact"]["orbit_step"] == H
    run = [core.step(H, amb_on=0.0).work for _ in range(10)]
    again = _rolling_core(1.0)
    again.set_state(doc)
    rerun = [again.step(H, amb_on=0.0).work for _ in range(10)]
    assert again.get_state() == core.get_state() and rerun == run
    del doc["contact"]["orbit_energy"]  # a version 3 document written before the orbit
    older = _rolling_core(1.0)
    older.set_state(doc)
    assert math.isnan(older.state.orbit_energy)
    older.step(H, amb_on=0.0)
    assert older.mode == 2 and not math.isnan(older.state.orbit_energy)


def test_a_rolling_step_asks_the_orbit_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The core's rolling step asks the orbit first (``SpinSteps._spin_roll_step``); where
    it refuses, the step loop's segment takes its answer and does not ask again (a second
    ask would charge the orbit's build twice and could build its step map early); and a
    refused orbit leaves the step to the panels as if there were none, to the bit."""
    answers: list[bool] = []
    real = orbit_mod.advance

    def counted(*args: object) -> tuple[object, object]:
        out = real(*args)  # type: ignore[arg-type]
        answers.append(out[0] is not None)
        return out

    monkeypatch.setattr(orbit_mod, "advance", counted)
    core = _rolling_core(2000.0)
    for _ in range(4):
        core.step(H, amb_on=0.0)
    assert answers == [True] * 4
    answers.clear()
    core.step(H, amb_on=0.0, budget=SEGMENT_WORK + 10)  # below the orbit's cost
    assert answers == [False]
    wobbly = {**CHAPTER, "e_c": 2e-3}  # c2 > DELTA_MAX I0: the series would not converge
    runs = []
    for follow in (True, False):
        monkeypatch.setattr(SpinContact, "follow_orbit", follow)
        core = _rolling_core(2000.0, wobbly)
        answers.clear()
        runs.append([core.step(H, amb_on=0.0).work for _ in range(3)] + [core.get_state()])
        assert core.mode == 2
        assert answers == ([False] * 3 if follow else [])
    assert runs[0] == runs[1]


def test_work_does_not_depend_on_the_speed() -> None:
    works = set()
    for W in (60.0, 700.0, 2000.0, 6000.0, 2e4):
        end, _ = _advance(_held(), TH0, PSI0, W, H)
        assert end is not None and end.duration == H
        works.add(end.work)
    assert len(works) == 1, works


def test_declines_where_it_must() -> None:
    p = RotorParams(**CHAPTER)
    W = 60.0
    driven = HeldInputs(p, J, 0.0, 0j, 5.0)
    seg = SpinContact(driven, 0.0, TH0, 0.0, PSI0, W)
    assert seg.run(H).orbit is None  # T_drive != 0 at 60 rad/s: the direct panel (§10)
    cen = p.m * p.c_r * (p.R / p.c_r * W) ** 2
    n = complex(math.cos(TH0), math.sin(TH0))
    pulled = HeldInputs(p, J, 0.0, -0.99 * cen * n, 0.0)
    assert _advance(pulled, TH0, PSI0, W, H) == (None, None)
    assert _advance(_held(), TH0, PSI0, 8.0, H) == (None, None)  # eps near 0.14: no grid
    orb = _advance(_held(), TH0, PSI0, W, H)[1]
    assert orb is not None and orb.ok  # below the work a step needs: declined, the orbit kept
    assert orbit_mod.advance(orb, _held(), TH0, PSI0, W, H, 10, math.inf) == (None, orb)


def test_the_step_map_agrees_with_newton_within_its_share() -> None:
    """``StepMap`` (docs/notes/dry-whirl-quadrature.md §9), built by the second step of one
    length, against ``_solve``'s Newton from random starts on the orbit: u within its share
    of the tolerance (the smaller of TOL_PHASE in theta and TOL_IMPULSE of u), the periodic
    impulses within theirs of the mean impulse, plus rounding."""
    rng = random.Random(5)
    share = orbit_mod.MAP_SHARE
    checked = 0
    for _ in range(40):
        h, W, th, psi, rem = _random_case(rng)
        end, orb = _advance(h, th, psi, W, rem)
        if end is None:
            continue
        end, orb = _advance(h, end.theta, end.psi, end.Omega, rem, orb)
        m = orb.map
        assert end is not None and m is not None and m.h == rem
        if not m.ok:
            continue
        w = DryWhirl(h, end.theta, end.psi, end.Omega)
        for _ in range(5):
            beta, psi_s = rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi, math.pi)
            g = orbit_mod.on_orbit(orb, w, beta, psi_s)
            x, P, q = orbit_mod._solve(orb, g, g.theta0, psi_s, rem)
            xm, Pm, qm = m.at(beta, psi_s)
            u = rem / orb.f00 + x
            tol_u = share * min(1e-14 * (1 + w.rho * u) / w.rho, 1e-14 * u)
            assert abs(xm - x) <= 1.1 * tol_u + 4 * math.ulp(u), (xm, x, tol_u)
            tol_p = share * 1e-14 * abs(orb.d00) * u
            assert abs(Pm - P) <= 1.1 * tol_p + 1e-15 * abs(orb.d00) * u, (Pm, P, tol_p)
            if w.akcr:
                assert abs(qm - q) * w.akcr <= 1.1 * tol_p + 1e-15 * abs(orb.d00) * u
            checked += 1
    assert checked >= 100, checked


@pytest.mark.parametrize("W", SPEEDS)
def test_the_step_map_samples_are_rounded_relative_to_x(W: float) -> None:
    """The map of the benchmark scene's 1e-4 s step is taken at every speed, and the bound
    of its check harmonics of x (2 sum |c|) is at most 1e-15 of u (docs/notes/
    dry-whirl-quadrature.md §9: 1.5e-17 to 3.8e-16 of u measured; Newton run on u itself,
    its samples rounded relative to u, gave 3.6e-15 to 4e-15 of u). At 2000 rad/s, where
    the truncation is far below it, that bound is below one rounding of u (eps/2 = 1.1e-16
    of u): the samples are rounded relative to x, not to u (a residual rounded relative
    to h gives 3.8e-16 of u there)."""
    core = _rolling_core(W)
    for _ in range(3):
        core.step(H, amb_on=0.0)
    m = core._orbit.map
    assert m is not None and m.ok and m.h == H
    u = H / core._orbit.f00 + m.x00
    assert m.check_x <= (1.1e-16 if W == 2000.0 else 1e-15) * u, (m.check_x, u)
