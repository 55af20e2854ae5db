"""Dry whirl by its energy integral (``rotortd.segments.rolling_spin_fast``, the declared
accelerator of ``SpinContact`` for rolling with a c = 0;
docs/notes/dry-whirl-quadrature.md).

1. Against the extrapolation integrator it replaces (``SpinContact`` with ``accelerate``
   False) at random rolling states: speeds 60 to 3000 rad/s of both signs, gravity on and
   off, F_ext up to 2000 N, T_drive up to 20 N m, the bearing off or on with its damper off
   (c = 0: spring and bias), J from 0.2 to 3 m R^2, segments of 1e-6 to 1e-3 s; both modes
   (direct, Fourier-Levin). Required: theta within 1e-13 (1 + its turn) rad, psi within
   1e-13 (1 + its turn), Omega within 1e-13 |Omega|, the impulses within 1e-13 of
   S = max(|int N|, peak N t); the integrator's own error is 1e-13 per step.
2. Against the 40-digit Taylor integration ``tests.reference.spin_mp.mp_contact`` (no shared
   code) over one 1e-4 s step of dry whirl (the chapter's rotor, gravity, bearing off) at
   60, 200, 600 and 2000 rad/s: the same quantities within 1e-13 of the same scales.
3. The method declines (None: the integrator then takes the segment and locates the event)
   when its bounds cannot exclude lift-off or slip start, and its work does not depend on
   the speed.
"""

from __future__ import annotations

import functools
import math
import random
from typing import Any

import pytest
from rotortd.contact.wall import SegmentEnd
from rotortd.params import RotorParams
from rotortd.segments.rolling_spin_fast import DryWhirl
from rotortd.segments.spin_contact import HeldInputs, SpinContact

from tests.reference.spin_mp import mp_contact

CHAPTER: dict[str, Any] = {
    "m": 50.0, "c": 1400.0, "k": 9.8e5, "e_c": 0.3e-3, "phi": 0.21, "c_r": 0.7e-3, "R": 0.04,
    "mu": 0.15, "d": 0.95, "g": 9.81, "levitate": True,
}
J = 0.04  # 1/2 m R^2
TOL = 1e-13
SPEEDS = (60.0, 200.0, 600.0, 2000.0)
TH0, PSI0, H = -1.3, 0.4, 1e-4


def _errors(new: SegmentEnd, theta0: float, psi0: float, W0: float, theta: Any, psi: Any,
            Omega: Any, I_n: Any, I_t: Any, I_c: Any, mc: float) -> dict[str, float]:
    """|new - other| over the scales of the module docstring (other: floats or mpmath)."""
    tal = new.tally
    S = max(abs(float(I_n)), tal.peak * new.duration) * mc
    return {"theta": float(abs(new.theta - theta)) / (1.0 + abs(new.theta - theta0)),
            "psi": float(abs(new.psi - psi)) / (1.0 + abs(new.psi - psi0)),
            "Omega": float(abs(new.Omega - Omega)) / abs(W0),
            "P_n": float(abs(mc * tal.I_n - I_n)) / S, "P_t": float(abs(mc * tal.I_t - I_t)) / S,
            "P_c": float(abs(mc * tal.I_c - I_c)) / S}


def _random_case(rng: random.Random) -> tuple[HeldInputs, float, float, float, float, bool]:
    W = math.copysign(math.exp(rng.uniform(math.log(60.0), math.log(3000.0))),
                      rng.choice((1.0, -1.0)))
    a = rng.choice((0.0, 1.0))
    p = RotorParams(g=rng.choice((0.0, 9.81)), c=0.0 if a else 1400.0,
                    levitate=rng.choice((True, False)))
    F = (complex(rng.uniform(-2e3, 2e3), rng.uniform(-2e3, 2e3)) if rng.random() < 0.5
         else 0j)
    T = rng.uniform(-20.0, 20.0) if rng.random() < 0.5 else 0.0
    h = HeldInputs(p, p.m * p.R ** 2 * rng.uniform(0.2, 3.0), a, F, T)
    rem = math.exp(rng.uniform(math.log(1e-6), math.log(1e-3)))
    levin = rng.random() < 0.5 and abs(W) * rem * p.R / p.c_r > 4.0  # where both modes apply
    return h, W, rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0), rem, levin


def errors_against_the_integrator(h: HeldInputs, th: float, psi: float, W: float,
                                  new: SegmentEnd) -> dict[str, float]:
    """``_errors`` of a segment ``new`` of rolling from (th, psi, W) against the
    extrapolation integrator (``SpinContact`` with ``accelerate`` False) over its duration;
    neither may end at an event."""
    seg = SpinContact(h, 0.0, th, 0.0, psi, W)
    seg.accelerate = False
    old = seg.run(new.duration, 10 ** 9)
    assert old.orbit is None  # (the integrator took it: the orbit's ends carry their orbit)
    assert old.event is None and new.event is None
    mc = h.p.m * h.p.c_r
    tal = old.tally
    return _errors(new, th, psi, W, old.theta, old.psi, old.Omega, mc * tal.I_n,
                   mc * tal.I_t, mc * tal.I_c, mc)


def test_agrees_with_the_integrator_at_random_states() -> None:
    rng = random.Random(7)
    taken, worst = 0, dict.fromkeys(("theta", "psi", "Omega", "P_n", "P_t", "P_c"), 0.0)
    for _ in range(80):
        h, W, th, psi, rem, levin = _random_case(rng)
        new = DryWhirl(h, th, psi, W).advance(rem, 10 ** 9, levin=levin or None)
        if new is None:
            continue
        taken += 1
        assert new.duration == rem or new.duration < rem  # the panel may end first
        err = errors_against_the_integrator(h, th, psi, W, new)
        for k, v in err.items():
            worst[k] = max(worst[k], v)
    assert taken >= 70, taken
    assert all(v <= TOL for v in worst.values()), worst


@functools.cache
def _reference(W: float) -> dict[str, Any]:
    return mp_contact(CHAPTER, J, 0, TH0, 0.0, PSI0, W, H, a=0.0)


def _held() -> HeldInputs:
    return HeldInputs(RotorParams(**CHAPTER), J, 0.0, 0j, 0.0)


@pytest.mark.parametrize("levin", [None, True])
@pytest.mark.parametrize("W", SPEEDS)
def test_one_step_matches_the_40_digit_reference(W: float, levin: bool | None) -> None:
    new = DryWhirl(_held(), TH0, PSI0, W).advance(H, 10 ** 9, levin=levin)
    assert new is not None and new.duration == H and new.event is None
    ref = _reference(W)
    assert ref["event"] is None and ref["N"] > 0
    mc = CHAPTER["m"] * CHAPTER["c_r"]
    err = _errors(new, TH0, PSI0, W, ref["theta"], ref["psi"], ref["Omega"], ref["P_n"],
                  ref["P_t"], ref["P_c"], mc)
    assert all(v <= TOL for v in err.values()), err


def test_declines_where_an_event_is_not_excluded() -> None:
    """Slow rolling pressed outward by less than the force that pulls it off: F_ext inward
    (toward the centre) of nearly the centripetal force leaves the lift-off bound unproved."""
    p = RotorParams(**CHAPTER)
    W = 60.0
    cen = p.m * p.c_r * (p.R / p.c_r * W) ** 2  # m c_r theta'^2 (N)
    n = complex(math.cos(TH0), math.sin(TH0))
    h = HeldInputs(p, J, 0.0, -0.99 * cen * n, 0.0)
    assert DryWhirl(h, TH0, PSI0, W).advance(H, 10 ** 9) is None
    assert DryWhirl(_held(), TH0, PSI0, W).advance(H, 10 ** 9) is not None


def test_work_does_not_grow_with_the_speed() -> None:
    """The Fourier-Levin panel's work does not grow with the speed; beyond L_MAX rad of psi
    per call the panel ends first (the step loop takes another)."""
    works = []
    for W in (700.0, 2000.0, 6000.0, 1e5):
        end = DryWhirl(_held(), TH0, PSI0, W).advance(H, 10 ** 9)
        assert end is not None
        works.append(end.work)
        assert end.duration == H or (end.duration < H and abs(end.psi - PSI0) > 0.99)
    assert works == sorted(works, reverse=True), works


if __name__ == "__main__":
    for W in SPEEDS:
        for lv in (None, True):
            e = DryWhirl(_held(), TH0, PSI0, W).advance(H, 10 ** 9, levin=lv)
            assert e is not None
            r = _reference(W)
            mc_ = CHAPTER["m"] * CHAPTER["c_r"]
            er = _errors(e, TH0, PSI0, W, r["theta"], r["psi"], r["Omega"], r["P_n"],
                         r["P_t"], r["P_c"], mc_)
            print(f"W={W:6.0f} {'levin ' if lv else 'auto  '}"
                  + " ".join(f"{k}={v:.1e}" for k, v in er.items()))


def test_a_strong_drive_torque_takes_the_middle_tier_of_direct_nodes() -> None:
    """100 N m held at 60 rad/s: from this state the 10 Chebyshev nodes miss the impulse's
    tolerance (theta turns 0.4 rad over the panel); the 14 meet it, and the step matches the
    40-digit reference (P_DIRECT_FEW's tiers in turn, not 10 then P_DIRECT)."""
    th, psi, W, T = -1.8, -2.1, 60.0, 100.0
    w = DryWhirl(HeldInputs(RotorParams(**CHAPTER), J, 0.0, 0j, T), th, psi, W)
    new = w.advance(H, 10 ** 9)
    assert new is not None and new.duration == H and new.event is None
    assert w.samples == 10 + 14
    ref = mp_contact(CHAPTER, J, 0, th, 0.0, psi, W, H, a=0.0, T_drive=T)
    assert ref["event"] is None
    mc = CHAPTER["m"] * CHAPTER["c_r"]
    err = _errors(new, th, psi, W, ref["theta"], ref["psi"], ref["Omega"], ref["P_n"],
                  ref["P_t"], ref["P_c"], mc)
    assert all(v <= TOL for v in err.values()), err
