"""The spin-as-a-state contact segments (``rotortd.segments.spin_contact.SpinContact``,
docs/model.md §8) against the 40-digit Taylor integration ``tests.reference.spin_mp.mp_contact``
(its own coding of the equations; no shared code).

Segments over 1e-4 to 1e-3 s that stay in their mode (rolling in dry whirl with the bearing
off and on, with and without a drive torque; sliding pressed by F_ext = -5000j N forward and
backward, with the bearing on, in dry whirl backward), and located events (slip reaching zero
forward and backward, a lift-off). Required: the position c_r theta within 1e-12 c_r, psi within
1e-12 rad, theta' and Omega within 1e-12 of their scales (max(|theta'|, R |Omega|/c_r) and
max(|Omega|, c_r |theta'|/R)), the impulses int N, int F_t, int F_c within 1e-12 of
S = max(|int N|, |N_end| t), the dissipation within 1e-12 of mu S (R |Omega| + c_r |theta'|),
and an event's time within 1e-12 of the segment's duration. The core's tolerance is 1e-13
per step; ``python -m tests.test_spin_contact_mp`` prints the measured errors.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import mpmath
import pytest
from rotortd.contact.wall import SegmentEnd
from rotortd.params import RotorParams
from rotortd.segments.spin_contact import HeldInputs, SpinContact

from tests.reference.spin_mp import mp_contact

CHAPTER: dict[str, Any] = {
    "m": 50.0, "c": 1400.0, "k": 9.8e5, "e_c": 0.3e-3, "phi": 0.21, "c_r": 0.7e-3, "R": 0.04,
    "mu": 0.15, "d": 0.95, "g": 9.81, "levitate": True,
}
J = 0.04  # 1/2 m R^2
R, CR = CHAPTER["R"], CHAPTER["c_r"]
TOL = 1e-12
BOTTOM = -math.pi / 2
W_WHIP = 58.7  # the dry-whirl rolling speed of the drop (docs/model.md §8)

# name: (s, theta, theta', psi, Omega, t, a, F_ext, T_drive, event)
CASES: dict[str, tuple[Any, ...]] = {
    "rolling_dry_whirl": (0, BOTTOM, -R * W_WHIP / CR, 0.0, W_WHIP, 1e-3, 0.0, 0j, 0.0, None),
    "rolling_bearing_on_drive": (0, BOTTOM, -R * W_WHIP / CR, 0.3, W_WHIP, 1e-3, 1.0, 0j, 5.0,
                                 None),
    "sliding_pressed_drive": (1, BOTTOM, 10.0, 0.0, 184.2, 1e-3, 0.0, -5000j, 20.0, None),
    "sliding_pressed_bearing_on": (1, BOTTOM, 10.0, 0.0, 184.2, 1e-3, 1.0, -5000j, 0.0, None),
    "sliding_backward_pressed": (-1, BOTTOM, -300.0, 0.7, 0.5, 1e-3, 0.0, -5000j, -3.0, None),
    "sliding_backward_dry_whirl": (-1, BOTTOM, -R * 184.2 / CR - 2000.0, 0.0, 184.2, 2e-5, 0.0,
                                  0j, 0.0, None),
    # events: rem is longer than the segment
    "slip_zero_pressed": (1, BOTTOM, 0.0, 0.0, 1.0, 3e-3, 0.0, -5000j, 0.0, "slip_zero"),
    "slip_zero_dry_whirl": (-1, BOTTOM, -R * 184.2 / CR - 2000.0, 0.0, 184.2, 1e-4, 0.0, 0j, 0.0,
                           "slip_zero"),
    "lift_off_at_top": (1, math.pi / 2, 110.0, 0.0, 184.2, 3e-3, 0.0, 0j, 0.0, "lift_off"),
}
SEGMENTS = [k for k, c in CASES.items() if c[-1] is None]
EVENTS = [k for k, c in CASES.items() if c[-1] is not None]


def core_segment(name: str) -> SegmentEnd:
    s, th, dth, psi, Om, t, a, F_ext, T_drive, _ = CASES[name]
    held = HeldInputs(RotorParams(**CHAPTER), J, a, F_ext, T_drive)
    return SpinContact(held, s, th, dth, psi, Om).run(t, 10**9)


@functools.cache
def mp_segment(name: str, dps: int = 40, per_rad: int = 8) -> dict[str, Any]:
    s, th, dth, psi, Om, t, a, F_ext, T_drive, event = CASES[name]
    return mp_contact(CHAPTER, J, s, th, dth, psi, Om, t, a=a, F_ext=F_ext, T_drive=T_drive,
                      event=event, dps=dps, per_rad=per_rad)


def scales(ref: dict[str, Any]) -> dict[str, float]:
    """The scale of each compared quantity at the reference's end (see the module doc)."""
    dth, om = abs(float(ref["dtheta"])), abs(float(ref["Omega"]))
    S = max(abs(float(ref["P_n"])), abs(float(ref["N"])) * float(ref["t"]))
    return {"theta": 1.0, "psi": 1.0, "dtheta": max(dth, R * om / CR),
            "Omega": max(om, CR * dth / R), "P_n": S, "P_t": S, "P_c": S,
            "E_diss": CHAPTER["mu"] * S * (R * om + CR * dth), "duration": float(ref["t"])}


def value(end: SegmentEnd, key: str) -> Any:
    """The end's value of a compared quantity (the impulses from its tally, per unit m c_r)."""
    mc, tal = CHAPTER["m"] * CR, end.tally
    si = {"duration": end.duration, "P_n": mc * tal.I_n, "P_t": mc * tal.I_t,
          "P_c": mc * tal.I_c, "E_diss": mc * CR * tal.I_e}
    return si[key] if key in si else getattr(end, key)


def errors(end: SegmentEnd, ref: dict[str, Any]) -> dict[str, float]:
    """|core - reference| / scale per quantity."""
    sc = scales(ref)
    out = {}
    for key, scale in sc.items():
        val = value(end, key)
        out[key] = float(abs(val - ref["t" if key == "duration" else key])) / scale
    return out


def test_reference_converges() -> None:
    """mp_contact at 40 digits (order 50, 8 steps per radian) and 50 digits (order 60, 12
    steps per radian) agree to 1e-30 of the scales: rolling, sliding, an event."""
    for name in ("rolling_bearing_on_drive", "sliding_pressed_drive", "slip_zero_pressed"):
        ref, fine = mp_segment(name), mp_segment(name, 50, 12)
        sc = scales(fine)
        for key, scale in sc.items():
            k = "t" if key == "duration" else key
            assert abs(ref[k] - fine[k]) <= 1e-30 * scale, (name, key)


def _kinematics(th: Any, dth: Any, psi: Any, Om: Any) -> tuple[Any, Any, Any]:
    """(z, z_G, z_G') on the circle (mpmath)."""
    n = mpmath.expj(th)
    E = mpmath.expj(psi + CHAPTER["phi"])
    z = CR * n
    return z, z + CHAPTER["e_c"] * E, 1j * CR * dth * n + 1j * CHAPTER["e_c"] * Om * E


@pytest.mark.parametrize("name", [k for k, c in CASES.items() if c[6] == 0.0])
def test_reference_balances(name: str) -> None:
    """The reference's own physics, bearing off: the energy balance (kinetic + gravity +
    the potential of the held F_ext, minus the drive's work T_drive dpsi, plus the friction
    dissipation: zero; rolling dissipates nothing) and the momentum balance
    m dz_G' = (F_ext - i m g) t + int F_c, each to 1e-30 of its terms."""
    s, th, dth, psi, Om, _, _, F_ext, T_drive, _ = CASES[name]
    ref = mp_segment(name)
    with mpmath.workdps(50):
        m, g, T_drive = (mpmath.mpf(x) for x in (CHAPTER["m"], CHAPTER["g"], T_drive))
        F_ext = mpmath.mpc(F_ext)
        if s == 0:
            dth = -mpmath.mpf(R) * Om / CR
        z0, zg0, vg0 = _kinematics(*(mpmath.mpf(x) for x in (th, dth, psi, Om)))
        z1, zg1, vg1 = _kinematics(ref["theta"], ref["dtheta"], ref["psi"], ref["Omega"])
        terms = [m * abs(vg1) ** 2 / 2, -m * abs(vg0) ** 2 / 2,
                 J * ref["Omega"] ** 2 / 2, -J * mpmath.mpf(Om) ** 2 / 2,
                 m * g * mpmath.im(zg1 - zg0), -mpmath.re(mpmath.conj(F_ext) * (z1 - z0)),
                 -T_drive * (ref["psi"] - psi), ref["E_diss"]]
        assert abs(mpmath.fsum(terms)) <= 1e-30 * mpmath.fsum(abs(x) for x in terms)
        mom = [m * (vg1 - vg0), -(F_ext - 1j * m * g) * ref["t"], -ref["P_c"]]
        assert abs(mpmath.fsum(mom)) <= 1e-30 * mpmath.fsum(abs(x) for x in mom)
        if s == 0:
            assert ref["E_diss"] == 0


@pytest.mark.parametrize("name", SEGMENTS)
def test_segment_matches_mp(name: str) -> None:
    end, ref = core_segment(name), mp_segment(name)
    assert end.event is None and ref["event"] is None
    assert ref["N"] > 0  # still pressed at the end (the core watches N throughout)
    err = errors(end, ref)
    bad = {k: v for k, v in err.items() if not v <= TOL}
    assert not bad, f"{name}: {bad}"


@pytest.mark.parametrize("name", EVENTS)
def test_event_matches_mp(name: str) -> None:
    end, ref = core_segment(name), mp_segment(name)
    assert ref["event"] == CASES[name][-1]
    assert end.event == ref["event"]
    assert float(ref["t"]) < CASES[name][5]
    err = errors(end, ref)
    bad = {k: v for k, v in err.items() if not v <= TOL}
    assert not bad, f"{name}: {bad}"



# A slip start inside one integrator step (docs/model.md §8): rolling in dry whirl with the
# bearing on and a drive torque, |F_t|/N rises to a shallow peak (0.009896 by the step's
# Hermite midpoint) inside the accepted step 0.00063950 + 7.49e-5 s, at whose ends it is
# below 0.009875 (and below that before). With mu = 0.00988 between the two, mu N - |F_t|
# dips below 0 and back within that step (about 0.22 rad of beta wide): only the midpoint
# check sees it. The step grid does not depend on mu here (rolling ignores mu, and the
# quadratures' force scale is m c_r w^2 > (1 + mu) N), so the scene is that grid's.
DIP = {**CHAPTER, "mu": 0.00988}
DIP_CASE = (0, BOTTOM, 0.0, 0.6, W_WHIP, 3e-3, 1.0, 0j, 50.0)  # as CASES, t = 3 ms


def test_slip_start_within_one_step_is_found_at_its_time() -> None:
    """docs/model.md §8: the event functions are checked at every step's end and at its
    midpoint, so a sign change is missed only if it starts and ends within half a step. A
    slip start whose dip lies inside one step, around its midpoint, is the segment's end,
    at the 20-digit reference's first zero of mu N - |F_t| (to 1e-12 of the duration, as
    test_event_matches_mp), and the state there agrees as there."""
    s, th, dth, psi, Om, t, a, F_ext, T_drive = DIP_CASE
    held = HeldInputs(RotorParams(**DIP), J, a, F_ext, T_drive)
    end = SpinContact(held, s, th, dth, psi, Om).run(t, 10**9)
    ref = mp_contact(DIP, J, s, th, dth, psi, Om, t, a=a, F_ext=F_ext, T_drive=T_drive,
                     event="slip_start", dps=20, per_rad=16)
    assert ref["event"] == "slip_start" and float(ref["t"]) < 1e-3
    assert end.event == "slip_start", (end.event, end.duration, float(ref["t"]))
    assert abs(end.duration - ref["t"]) <= TOL * ref["t"], (end.duration, float(ref["t"]))
    for key in ("theta", "psi", "Omega"):
        assert abs(getattr(end, key) - ref[key]) <= TOL * max(1.0, abs(ref[key])), key

if __name__ == "__main__":
    for nm in CASES:
        e = errors(core_segment(nm), mp_segment(nm))
        print(f"{nm:28s} t={mpmath.nstr(mp_segment(nm)['t'], 6):>8s} "
              + " ".join(f"{k}={v:.1e}" for k, v in e.items()))
