"""Dry whirl with a held drive torque on the level table (``rotortd.segments.dry_whirl_driven``,
docs/notes/dry-whirl-quadrature.md §10).

1. One step against the 40-digit Taylor integration ``tests.reference.spin_mp.mp_contact``
   (no shared code): the chapter's rotor with gravity, bearing off, T_drive = 1 and 30 N m,
   1e-4 s at 2000 rad/s (the slow group adds -5 N m, 6000 rad/s and a 1e-3 s step at
   600 rad/s): theta, psi, Omega and the impulses within TOL = 1e-13 of the scales of
   tests/test_dry_whirl_fast.py (measured: 1e-15 and below).
2. Against the extrapolation integrator at random rolling states where the table applies
   (700 to 6000 rad/s of both signs, gravity on and off, F_ext up to 2000 N, T_drive up to
   30 N m either way, J from 0.2 to 3 m R^2, steps of 1e-4 to 3e-4 s): within TOL.
3. The core keeps the table across steps, does not write it to the state, and a restored
   state continues bit for bit (the table is a function of the held inputs and the band of
   the level); it declines where it must: the steps the direct panel takes, the bearing's
   spring on, a level whose expansion would not converge, a work limit below its build.
"""

from __future__ import annotations

import functools
import json
import math
import random
from typing import Any

import mpmath as mp
import pytest
from rotortd.params import RotorParams
from rotortd.segments import dry_whirl_driven as driven
from rotortd.segments.dry_whirl_driven import LevelTable
from rotortd.segments.spin_contact import HeldInputs, SpinContact

from tests.reference.spin_mp import mp_contact
from tests.test_dry_whirl_fast import (
    CHAPTER,
    PSI0,
    TH0,
    TOL,
    H,
    J,
    _errors,
    errors_against_the_integrator,
)
from tests.test_dry_whirl_orbit import _rolling_core


def _driven(T: float) -> HeldInputs:
    return HeldInputs(RotorParams(**CHAPTER), J, 0.0, 0j, T)


def _advance(h: HeldInputs, th: float, psi: float, W: float, rem: float,
             prev: LevelTable | None = None, limit: int = 10 ** 9) -> tuple[Any, Any]:
    return driven.advance(prev, h, th, psi, W, rem, limit, math.inf)


@functools.cache
def _reference(W: float, T: float, rem: float) -> dict[str, Any]:
    return mp_contact(CHAPTER, J, 0, TH0, 0.0, PSI0, W, rem, a=0.0, T_drive=T)


def _against_reference(W: float, T: float, rem: float) -> dict[str, float]:
    new, tab = _advance(_driven(T), TH0, PSI0, W, rem)
    assert new is not None and isinstance(tab, LevelTable) and new.orbit is tab
    assert new.duration == rem and new.event is None
    ref = _reference(W, T, rem)
    assert ref["event"] is None
    mc = CHAPTER["m"] * CHAPTER["c_r"]
    return _errors(new, TH0, PSI0, W, ref["theta"], ref["psi"], ref["Omega"], ref["P_n"],
                   ref["P_t"], ref["P_c"], mc)


@pytest.mark.parametrize("T", [1.0, 30.0])
def test_one_step_matches_the_40_digit_reference(T: float) -> None:
    err = _against_reference(2000.0, T, H)
    assert all(v <= TOL for v in err.values()), err


@pytest.mark.slow
@pytest.mark.parametrize(("W", "T", "rem"), [(2000.0, -5.0, H), (6000.0, 30.0, H),
                                            (600.0, 30.0, 1e-3)])
def test_more_steps_match_the_40_digit_reference(W: float, T: float, rem: float) -> None:
    err = _against_reference(W, T, rem)
    assert all(v <= TOL for v in err.values()), err


def _random_case(rng: random.Random) -> tuple[HeldInputs, float, float, float, float]:
    W = math.copysign(math.exp(rng.uniform(math.log(700.0), math.log(6000.0))),
                      rng.choice((1.0, -1.0)))
    p = RotorParams(g=rng.choice((0.0, 9.81)), levitate=rng.choice((True, False)))
    F = (complex(rng.uniform(-2e3, 2e3), rng.uniform(-2e3, 2e3)) if rng.random() < 0.5
         else 0j)
    h = HeldInputs(p, p.m * p.R ** 2 * rng.uniform(0.2, 3.0), 0.0, F,
                   rng.uniform(-30.0, 30.0))
    rem = math.exp(rng.uniform(math.log(1e-4), math.log(3e-4)))
    return h, W, rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0), rem


def test_agrees_with_the_integrator_at_random_states() -> None:
    rng = random.Random(26)
    taken, worst = 0, dict.fromkeys(("theta", "psi", "Omega", "P_n", "P_t", "P_c"), 0.0)
    for _ in range(80):
        h, W, th, psi, rem = _random_case(rng)
        new, _ = _advance(h, th, psi, W, rem)
        if new is None:
            continue
        taken += 1
        assert new.duration == rem
        for k, v in errors_against_the_integrator(h, th, psi, W, new).items():
            worst[k] = max(worst[k], v)
    assert taken >= 70, taken
    assert all(v <= TOL for v in worst.values()), worst


def test_the_core_keeps_the_table_and_replays_from_a_state() -> None:
    core = _rolling_core(2000.0)
    tables = set()
    for _ in range(10):
        core.step(H, amb_on=0.0, T_drive=30.0)
        tables.add(id(core._orbit))
        assert isinstance(core._orbit, LevelTable)
    assert core.mode == 2 and len(tables) == 1  # (one band: 30 N m moves K by 1e-4 a step)
    doc = json.loads(json.dumps(core.get_state()))
    assert doc["contact"]["orbit_energy"] is None  # not an orbit: nothing of it is stored
    run = [core.step(H, amb_on=0.0, T_drive=30.0).work for _ in range(10)]
    again = _rolling_core(1.0)
    again.set_state(doc)
    rerun = [again.step(H, amb_on=0.0, T_drive=30.0).work for _ in range(10)]
    assert again.get_state() == core.get_state() and rerun == run


def test_a_torque_that_changes_every_step_keeps_its_table() -> None:
    """A speed controller sets T_drive every step: within a factor 2 (``torque_cap``) the
    table serves them all (D's part linear in T_drive held apart), each step as accurate
    as with its own table."""
    core = _rolling_core(2000.0)
    tables = set()
    for k in range(12):
        core.step(H, amb_on=0.0, T_drive=24.0 + 7.0 * math.sin(k))  # (17 to 31 N m)
        tables.add(id(core._orbit))
    assert core.mode == 2 and len(tables) == 1 and isinstance(core._orbit, LevelTable)
    tab, th, psi, W = core._orbit, core.state.theta, core.state.psi, core.state.Omega
    for T in (17.0, -31.0, 2.0 ** -3):
        h = _driven(T)
        new, again = _advance(h, th, psi, W, H, tab)
        assert new is not None and (again is tab) == (T != 2.0 ** -3)
        err = errors_against_the_integrator(h, th, psi, W, new)
        assert all(v <= TOL for v in err.values()), (T, err)


def test_consecutive_steps_agree_with_the_integrator() -> None:
    """Five steps on one table, each from the previous one's end, against the integrator
    from the same starts (the errors do not grow with the steps taken on a table)."""
    h = _driven(30.0)
    th, psi, W, tab = TH0, PSI0, 3000.0, None
    for _ in range(5):
        new, tab = _advance(h, th, psi, W, H, tab)
        assert new is not None
        err = errors_against_the_integrator(h, th, psi, W, new)
        assert all(v <= TOL for v in err.values()), err
        th, psi, W = new.theta, new.psi, new.Omega


def test_declines_where_it_must() -> None:
    assert _advance(_driven(1.0), TH0, PSI0, 60.0, H)[0] is None  # the direct panel's step
    seg = SpinContact(_driven(1.0), 0.0, TH0, 0.0, PSI0, 60.0)
    assert seg.run(H).orbit is None  # (the panels took it)
    sprung = HeldInputs(RotorParams(**{**CHAPTER, "c": 0.0}), J, 1.0, 0j, 1.0)
    end, tab = _advance(sprung, TH0, PSI0, 2000.0, H)
    assert end is None and not tab.ok  # a k != 0: int n dt is not in the table
    slow, tab = _advance(_driven(1.0), TH0, PSI0, 10.0, 0.1)
    assert slow is None and not tab.ok  # 2 V_b/K near 0.08, above EPS_MAX
    assert _advance(_driven(1.0), TH0, PSI0, 2000.0, H, limit=driven.TABLE_WORK - 1) == (
        None, None)
    for T in (1e308, -1e308, 5e-324):  # (the level's change too large; a subnormal torque)
        end, _ = _advance(_driven(T), TH0, PSI0, 2000.0, H)
        assert (end is None) == (abs(T) > 1.0)


@pytest.mark.parametrize("p0", [-0.5, 0.5])
def test_the_means_integral_over_a_step_is_the_closed_form(p0: float) -> None:
    """``_StepSums.excess``: int_0^u sum_k c_k (X^(p0-k) - 1) ds, X = 1 + delta s, against
    40 digits, for level changes x = delta u from subnormal to 1e-2 of either sign (within
    1e-15 of sum_k |c_k| u)."""
    mp.mp.dps = 40
    sums = driven._StepSums.__new__(driven._StepSums)
    sums.mean = [1.3, -0.2, 0.05, 0.01, 0.003]
    sums.a = [p0 - k + 1.0 for k in range(len(sums.mean))]
    sums.mean0 = sum(sums.mean)
    u = 0.1
    for x in (1e-320, 1e-12, 5e-9, 1.5e-8, 1e-5, 1e-3, 1e-2, -5e-9, -1e-3, -1e-2):
        sums.delta = x / u
        lx = mp.log1p(mp.mpf(x))  # (X^a - 1 = expm1(a log X): exact for subnormal x too)
        ref = sum(mp.mpf(c) * u * (mp.expm1(a * lx) / (mp.mpf(a) * mp.mpf(x)) - 1)
                  for c, a in zip(sums.mean, sums.a))
        scale = sum(abs(c) for c in sums.mean) * u
        assert float(abs(sums.excess(u) - ref)) <= 1e-15 * scale, x
