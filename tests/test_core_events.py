"""Rigorous impact location: grazing excursions of 1e-10 c_r, accuracy, invariants, work."""

from __future__ import annotations

import cmath
import math
import random

import pytest
from rotortd import RotorParams, TouchdownCore, work_cap
from rotortd.contact.search import (
    CREEP,
    CREEP_RUN,
    EPS,
    HORIZON,
    ContactLocator,
    Work,
    flight_is_clear,
    g3_exact,
    g3_slack,
    safe_step,
)
from rotortd.segments.flight import FlightModel

from tests.reference.mp_reference import mp_first_impact

W0 = 184.2
BASE = RotorParams()


def _par(p: RotorParams) -> dict:
    return {f: getattr(p, f) for f in p.__dataclass_fields__}


def _offset_whirl(excess: float) -> tuple[RotorParams, complex, complex, float]:
    """A steady whirl z = Z0 + Z1 e^{i psi} whose largest radius is c_r (1 + excess).

    A constant force shifts the orbit off-centre by Z0; the start is the point nearest the
    centre, so both ends of a one-period step lie well inside.
    """
    p = BASE.replace(c=0.3 * BASE.m * W0)
    fm = FlightModel(p, W0, 0j, 1.0)
    Z1 = fm.F1 / complex(fm.kappa - W0**2, fm.beta * W0)  # at psi = 0
    Z0_mag = p.c_r * (1.0 + excess) - abs(Z1)
    F = Z0_mag * p.m * fm.kappa * cmath.exp(1j * cmath.phase(Z1))  # Z0 along Z1(psi=0)
    psi0 = math.pi  # start opposite: |z| = |Z1| - |Z0|
    E0 = cmath.exp(1j * psi0)
    z0 = F / (p.m * fm.kappa) + Z1 * E0
    v0 = 1j * W0 * Z1 * E0
    return p, F, z0, v0


@pytest.mark.parametrize("excess", [1e-10, -1e-10])
def test_grazing_within_one_long_step(excess: float) -> None:
    p, F, z0, v0 = _offset_whirl(excess)
    core = TouchdownCore(p, z0=z0, v0=v0, psi0=math.pi)
    period = 2 * math.pi / W0
    rep = core.step(3 * period, W0, F)
    if excess > 0:
        assert len(rep.impacts) >= 1, "an excursion of 1e-10 c_r beyond the wall was missed"
        imp = rep.impacts[0]
        assert imp.t == pytest.approx(0.5 * period, rel=1e-4)  # near the far point
        assert abs(imp.z) == pytest.approx(p.c_r, rel=4 * EPS)
    else:
        assert rep.impacts == [], "a miss by 1e-10 c_r produced an impact"
    assert abs(core.z) <= p.c_r * (1 + 1e-12)


def test_grazing_time_matches_high_precision_reference() -> None:
    p, F, z0, v0 = _offset_whirl(1e-8)
    fm = FlightModel(p, W0, F, 1.0)
    hit = ContactLocator(fm, z0, v0, cmath.exp(1j * math.pi)).find(0.05, False, Work())
    assert hit is not None and hit.kind == "impact"
    ref = mp_first_impact(_par(p), z0, v0, math.pi, W0, F, 1.0, 0.05, dps=40)
    t_ref, _, v_ref = ref
    assert abs(hit.v - complex(v_ref)) <= 1e-9 * abs(hit.v)
    rdot = (hit.z.conjugate() * hit.v).real / abs(hit.z)
    # time within a small multiple of eps (c_r/rdot + t)
    bound = 8 * EPS * (p.c_r / rdot + hit.s)
    assert abs(hit.s - float(t_ref)) <= bound, (hit.s - float(t_ref), bound)
    # near grazing the impact speed grows like sqrt(excess): rdot ~ sqrt(2 g'' excess c_r^2)
    assert rdot < 1e-3 * p.c_r * W0


@pytest.mark.parametrize("seed", range(6))
def test_impact_times_match_reference(seed: int) -> None:
    """Random flights from inside at the chapter's parameters: first impact vs mpmath."""
    import random

    rng = random.Random(seed)
    p = BASE.replace(c=rng.uniform(0.05, 0.3) * BASE.m * W0)
    z0 = p.c_r * rng.uniform(0, 0.9) * cmath.exp(1j * rng.uniform(-3, 3))
    v0 = p.c_r * W0 * rng.uniform(0, 1.5) * cmath.exp(1j * rng.uniform(-3, 3))
    psi0 = rng.uniform(-3, 3)
    fm = FlightModel(p, W0, 0j, 1.0)
    hit = ContactLocator(fm, z0, v0, cmath.exp(1j * psi0)).find(0.1, False, Work())
    ref = mp_first_impact(_par(p), z0, v0, psi0, W0, 0j, 1.0, 0.1, dps=30)
    if ref is None:
        assert hit is None
        return
    assert hit is not None
    rdot = (hit.z.conjugate() * hit.v).real / abs(hit.z)
    assert abs(hit.s - float(ref[0])) <= 8 * EPS * (p.c_r / rdot + hit.s)
    assert abs(hit.z - complex(ref[1])) <= 8 * EPS * p.c_r + 8 * EPS * abs(hit.v) * hit.s


def test_step_invariants_and_work_cap_over_random_scene() -> None:
    p = BASE.replace(c=0.1 * BASE.m * W0)
    core = TouchdownCore(p, z0=0.5 * p.c_r, v0=0.8j * p.c_r * W0)
    for i in range(2000):
        h = 1e-4 * (1 + (i % 7))
        rep = core.step(h, W0)
        assert rep.status == 0
        assert abs(core.z) <= p.c_r * (1 + 1e-12)
        assert rep.work <= work_cap(p, h, W0, 0j, 1.0)
        for imp in rep.impacts:
            assert abs(abs(imp.z) - p.c_r) <= 4 * EPS * p.c_r
    assert core.n_impacts > 10


def test_free_whirl_skips_the_search() -> None:
    """A scene that provably never reaches the wall does one propagation per step."""
    p = BASE.replace(c=0.3 * BASE.m * W0)
    core = TouchdownCore.on_steady_whirl(p, W0)
    works = [core.step(1e-3, W0).work for _ in range(100)]
    assert works[0] <= 2 and max(works[1:]) == 1


def _random_flight(rng: random.Random) -> tuple[FlightModel, complex, complex, complex, float]:
    """A random free flight inside the clearance: damping, imbalance, gravity, a constant
    force, spin speed and direction, position, velocity and step length (log-uniform)."""
    p = BASE.replace(c=rng.uniform(0.0, 1.0) * 2.0 * math.sqrt(BASE.m * BASE.k),
                     e_c=BASE.e_c * 10 ** rng.uniform(-3.0, 0.5), g=rng.choice([0.0, 9.81]))
    W = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(1.0, 3.3)
    F = cmath.rect(p.m * 9.81 * rng.uniform(0.0, 3.0), rng.uniform(-math.pi, math.pi))
    fm = FlightModel(p, W, F, rng.choice([1.0, 1.0, 0.3]))
    z0 = cmath.rect(p.c_r * rng.uniform(0.0, 0.999999), rng.uniform(-math.pi, math.pi))
    v0 = cmath.rect(p.c_r * abs(W) * rng.uniform(0.0, 2.0), rng.uniform(-math.pi, math.pi))
    E0 = cmath.exp(1j * rng.uniform(-math.pi, math.pi))
    return fm, z0, v0, E0, 10 ** rng.uniform(-6.0, -1.0)


def _composed_find(loc: ContactLocator, h: float, on_wall: bool, work: Work):
    """ContactLocator.find written through the helpers its inline loop copies (accel,
    g3_exact, g3_slack, safe_step, state): the oracle of the bit-identity test below."""
    s, (z, v, E), fm = 0.0, (loc.z0, loc.v0, loc.E0), loc.fm
    c3_modes, creeps = math.inf, 0
    for _ in range(400):
        acc = fm.accel(z, v, E)
        zc = z.conjugate()
        g = (z * zc).real - loc.c2
        g1 = 2.0 * (zc * v).real
        g2 = 2.0 * (v * v.conjugate()).real + 2.0 * (zc * acc).real
        if g >= -loc.tol_g or (on_wall and s == 0.0):
            bands = loc.bands(v)
            hit = loc._at_wall(s, z, v, E, g, g1, g2, bands, work, first=(s == 0.0))
            if hit is not None:
                return hit
            g, g1 = 0.0, min(g1, 0.0)
            if g1 >= -bands[0] and g2 >= -bands[1] and s < h:
                s = min(h, s + loc.grace_step(z, v, E))
                z, v, E = loc.state(s, work)
                continue
        remaining = h - s
        if remaining <= 0.0:
            return None
        tau = min(remaining, loc.horizon)
        c3 = min(g3_exact(fm, z, v, acc, E) + g3_slack(fm, v, tau), c3_modes)
        u = safe_step(g, g1, g2, c3, tau, work)
        if u is not None and u < CREEP * tau and g1 <= 0.0:
            creeps += 1
            if creeps == CREEP_RUN:
                c3_modes = loc._creep_bound(s, work)
                if c3 > c3_modes:
                    um = safe_step(g, g1, g2, c3_modes, tau, work)
                    u = um if um is None or um > u else u
        if u is None:
            if tau >= remaining:
                return None
            u = tau
        if u <= 0.0:
            return ("touch", s, z, v, E)
        s = s + u if u < remaining else h
        z, v, E = loc.state(s, work)
    return ("clear", s, z, v, E)


def _as_tuple(hit) -> tuple | None:
    return hit if hit is None or isinstance(hit, tuple) else (hit.kind, hit.s, hit.z, hit.v,
                                                                 hit.E)


def test_inline_search_loop_is_bit_identical_to_its_helpers() -> None:
    """find evaluates points, bounds and the quick test inline (the core's hottest loop).
    On 1500 random flights, from inside and from the wall, with modes and without (k = 0),
    it returns the same contact, bit for bit, with the same work count as the loop
    composed of the helpers, so the helpers' tests (the bound above the exact flight, the
    quick test) speak for the inline copy. Contacts of every kind must occur."""
    rng = random.Random(20261123)
    kinds: dict[str, int] = {}
    for j in range(1500):
        fm, z0, v0, E0, h = _random_flight(rng)
        if j % 5 == 0:  # no stiffness: no modes, points by the divided-difference map
            fm = FlightModel(fm.params.replace(k=0.0), fm.Omega, fm.F_ext, fm.amb)
        on_wall = j % 3 == 0
        if on_wall:
            z0 = fm.c_r * z0 / abs(z0) if z0 else complex(fm.c_r)
        h = 10 * h
        w1, w2 = Work(), Work()
        got = _as_tuple(ContactLocator(fm, z0, v0, E0).find(h, on_wall, w1))
        want = _as_tuple(_composed_find(ContactLocator(fm, z0, v0, E0), h, on_wall, w2))
        assert got == want, (j, got, want)
        assert (w1.evals, w1.iters) == (w2.evals, w2.iters), j
        kind = "none" if got is None else got[0]
        kinds[kind] = kinds.get(kind, 0) + 1
    assert kinds.get("impact", 0) > 100 and kinds.get("none", 0) > 100, kinds


def test_flight_proved_clear_never_reaches_the_wall() -> None:
    """flight_is_clear (a step with no search) proves only what is true: on 3000 random
    flights, every step it proves free is free in the search too, and at 400 points of the
    exact flight map (independent of the cubic bound). Both verdicts must occur."""
    rng = random.Random(20261121)
    proved = refused = 0
    for _ in range(3000):
        fm, z0, v0, E0, h = _random_flight(rng)
        if not flight_is_clear(fm, z0, v0, E0, h):
            refused += 1
            continue
        proved += 1
        assert ContactLocator(fm, z0, v0, E0).find(h, False, Work()) is None
        r_max = max(abs(fm.propagate(z0, v0, E0, h * k / 400)[0]) for k in range(1, 401))
        assert r_max < fm.c_r, f"proved free, yet |z| reaches {r_max / fm.c_r!r} c_r"
    assert proved > 300 and refused > 300, (proved, refused)


def _bound_violation(fm: FlightModel, z0: complex, v0: complex, E0: complex, tau: float,
                     slack: float) -> float:
    """Largest g(u) - p(u) (in c_r^2) over 200 points of [0, tau] while the exact flight
    stays inside, p the search's bound g + g' u + g'' u^2/2 + (g''' + slack) u^3/6."""
    c2 = fm.c_r * fm.c_r
    acc = fm.accel(z0, v0, E0)
    g0 = abs(z0) ** 2 - c2
    g1 = 2.0 * (z0.conjugate() * v0).real
    g2 = 2.0 * abs(v0) ** 2 + 2.0 * (z0.conjugate() * acc).real
    c3 = g3_exact(fm, z0, v0, acc, E0) + slack
    worst = -math.inf
    for k in range(1, 201):
        u = tau * k / 200
        z = fm.propagate(z0, v0, E0, u)[0]
        if abs(z) > fm.c_r:
            break
        p = g0 + u * (g1 + u * (0.5 * g2 + u * c3 / 6.0))
        worst = max(worst, (abs(z) ** 2 - c2 - p) / c2)
    return worst


def test_search_bound_lies_above_the_exact_flight() -> None:
    """The search's bound (exact g''' plus g3_slack: the quartic remainder over tau and the
    rounding of g''') lies above g = |z|^2 - c_r^2 of the exact flight map on 600 random
    flights, over the longest interval one bound covers. Without the slack, the bare cubic
    Taylor polynomial falls below the flight on many of them: the slack is what makes the
    bound a bound, and this test would notice its loss."""
    rng = random.Random(20261122)
    bare_below = 0
    for _ in range(600):
        fm, z0, v0, E0, _h = _random_flight(rng)
        w = max(fm.rate, abs(v0) / fm.c_r)
        tau = HORIZON / w
        slack = g3_slack(fm, v0, tau)
        assert _bound_violation(fm, z0, v0, E0, tau, slack) <= 64 * EPS
        bare_below += _bound_violation(fm, z0, v0, E0, tau, 0.0) > 64 * EPS
    assert bare_below > 30, bare_below


@pytest.mark.parametrize("excess", [1e-10, 1e-14])
def test_flight_reaching_the_wall_is_never_proved_clear(excess: float) -> None:
    """The orbit of test_grazing_within_one_long_step, reaching c_r (1 + excess) half a
    period in: a step over it is never proved free, however slight the excursion."""
    p, F, z0, v0 = _offset_whirl(excess)
    fm = FlightModel(p, W0, F, 1.0)
    period = 2 * math.pi / W0
    for h in (0.5 * period, period, 3 * period):
        assert not flight_is_clear(fm, z0, v0, cmath.exp(1j * math.pi), h)


def test_long_step_keeps_impact_times_to_the_clock() -> None:
    """One 10 s step over 640 impacts reports each impact at the time 100 steps of 0.1 s
    do, to 4 ulp of 10 s, and ends in the same state to 1e-12 c_r: the step-local time is
    summed with its rounding kept. (Summed plainly, one rounding per impact drifted by
    44 ulp, and the end state by 1.1e-11 c_r.)"""
    from rotortd_tools.cycles import OMEGA, find_period_one_cycle

    cyc = find_period_one_cycle(0.1)
    z0, v0, W = 0.999 * cyc.z0, cyc.v0, OMEGA
    one = TouchdownCore(cyc.params, z0=z0, v0=v0)
    long_times = [imp.t for imp in one.step(10.0, W).impacts]
    many = TouchdownCore(cyc.params, z0=z0, v0=v0)
    short_times = [imp.t for _ in range(100) for imp in many.step(0.1, W).impacts]
    assert len(long_times) == len(short_times) > 600
    drift = max(abs(a - b) for a, b in zip(long_times, short_times))
    assert drift <= 4 * math.ulp(10.0), drift
    assert abs(one.z - many.z) <= 1e-12 * cyc.params.c_r


def test_bound_polynomials_match_their_nested_forms() -> None:
    """FlightModel.g3_poly and g4_poly are G3 = 6 V A + 2 c_r Jm and G4 = 6 A^2 + 8 V Jm +
    2 c_r L expanded in V, to rounding, on random flights (any damping, spin, forces)."""
    rng = random.Random(7)
    for _ in range(300):
        fm, _z, v, _E, tau = _random_flight(rng)
        V = abs(v) + fm.K * tau
        A = fm.beta * V + fm.K
        Jm = fm.beta * A + fm.kappa * V + fm.J
        L = fm.beta * Jm + fm.kappa * A + fm.L_rot
        G3, G4 = 6.0 * V * A + 2.0 * fm.c_r * Jm, 6.0 * A * A + 8.0 * V * Jm + 2.0 * fm.c_r * L
        s0, s1, s2 = fm.g3_poly
        q0, q1, q2 = fm.g4_poly
        assert min(fm.g3_poly + fm.g4_poly) >= 0.0
        assert abs(s0 + V * (s1 + V * s2) - G3) <= 16 * EPS * G3
        assert abs(q0 + V * (q1 + V * q2) - G4) <= 16 * EPS * G4


def test_bracket_left_is_the_one_root_finder_inlined() -> None:
    """The contact search's innermost loop (search._bracket_left) is the core's one root
    finder (segments.roots.illinois) inlined: on random increasing cubics, on and off the
    wall, both give the same left end, bit for bit."""
    from rotortd.contact.search import BRACKET_RTOL, Work, _bracket_left
    from rotortd.segments.roots import illinois

    rng = random.Random(23)
    checked = 0
    for _ in range(3000):
        g0 = None if rng.random() < 0.3 else -rng.uniform(1e-3, 1.0)
        g1, g2, g3 = (rng.uniform(0.0, 2.0), rng.uniform(-1.0, 2.0), rng.uniform(-1.0, 1.0))
        lo, hi = 0.0, rng.uniform(0.01, 3.0)

        def f(u: float, g0: float | None = g0, g1: float = g1, g2: float = g2,
              g3: float = g3) -> float:
            q = g1 + u * (0.5 * g2 + u * g3 / 6.0)
            return q if g0 is None else g0 + u * q

        if not f(lo) < 0.0 <= f(hi):
            continue
        checked += 1
        left = _bracket_left((g0, g1, g2, g3), lo, hi, Work())
        ref, _, _ = illinois(lambda u: (-f(u), None), lo, -f(lo), hi, -f(hi), None,
                             lambda a, b, _: b - a <= BRACKET_RTOL * b, 100)
        assert left == ref, (g0, g1, g2, g3, hi)
    assert checked > 1000


def test_illinois_takes_the_secant_of_f_minus_the_level() -> None:
    """The root finder locates the crossing of a positive level as fast as that of zero:
    on random smooth decreasing functions whose ends are both positive (the held sliding's
    event functions cross their rounding band, level 64 eps), the secant of f - level
    converges superlinearly: 6 to 14 evaluations to a bracket of 2e-16 relative. The secant
    of f itself left the bracket and bisected: 15 to 100 (the limit) on the same functions."""
    from rotortd.segments.roots import illinois

    rng = random.Random(26)
    level = 64.0 * 2.220446049250313e-16
    for _ in range(200):
        a0, a1, a2 = rng.uniform(0.5, 2.0), rng.uniform(0.1, 1.0), rng.uniform(-0.3, 0.3)
        x0 = rng.uniform(0.1, 0.9)

        def f(x: float, a0: float = a0, a1: float = a1, a2: float = a2,
              x0: float = x0) -> float:
            d = x0 - x
            return level + d * (a0 + d * (a1 + d * a2))

        calls: list[float] = []

        def at(x: float, f=f, calls: list[float] = calls) -> tuple[float, None]:
            calls.append(x)
            return f(x), None

        _, b, _ = illinois(at, 0.0, f(0.0), 1.0, f(1.0), None,
                           lambda a, b, g: b - a <= 2e-16 * b or g == 0.0, 100, level)
        assert abs(b - x0) <= 1e-14 and len(calls) <= 16, (x0, len(calls))


def test_the_modes_bound_the_third_derivative_of_the_gap() -> None:
    """Modes.g3_bound(s) bounds |g'''| of g = |z|^2 - c_r^2 at every later point of the
    flight: on those of 1000 random flights whose modes are well conditioned (385), at 20
    points each, against g3_exact from the state there (largest ratio 0.97). On some it is
    below the Taylor bound's slack alone; where the search creeps it is far below (the next
    test)."""
    rng = random.Random(20261127)
    checked = tighter = 0
    for _ in range(1000):
        fm, z0, v0, E0, h = _random_flight(rng)
        md = fm.modes(z0, v0, E0)
        if md is None:
            continue
        s0 = rng.uniform(0.0, h)
        bound = md.g3_bound(s0)
        for _ in range(20):
            t = s0 + rng.uniform(0.0, 10.0 * h)
            z, v, rot = md.at(t)
            E = E0 * rot
            g3 = g3_exact(fm, z, v, fm.accel(z, v, E), E)
            assert abs(g3) <= bound * (1.0 + 64.0 * EPS), (bound, g3)
            checked += 1
        tighter += bound < g3_slack(fm, v0, HORIZON * h)
    assert checked > 5000 and tighter > 0


def test_a_flight_that_osculates_the_circle_after_lift_off_leaves_it() -> None:
    """Rolling lifts off where the free orbit has the wall's curvature to 1e-13 (no
    damping, the AMB's natural frequency times c_r equal to the speed along the wall): the
    Taylor bound of g''', loose by 1e9 there, let the search advance 1.9e-18 s at a time,
    76 flights of 7.5e-16 s until the work bound (found by the core fuzz, session 14). With
    the modes' bound after CREEP_RUN creeping advances the step ends OK in a few thousand
    work units."""
    p = RotorParams(m=10.0 ** 0.25, c=0.0, k=15083208765.821896, e_c=0.0,
                    phi=0.9920951837729122, c_r=1.0, R=1.7782794100389228,
                    mu=1.9739675530705534, d=0.0, g=9.81, levitate=True)
    W = 65998.36396028813
    core = TouchdownCore.from_scaled(p, W, U0=-0.22834490772319652 + 0.19823107336750304j,
                                     dU0=1.5433967619949445 + 1.5712806067521043j)
    h = 0.00027989782550347345
    F = 0.9920951837729122 * p.m * p.c_r * W**2 * cmath.exp(1.3j)
    for Omega, F_ext, amb in ((0.0, 0j, 0.5), (W, F, 0.0)):
        assert core.step(h, Omega, F_ext, amb).status == 0
    assert core.mode == 2  # rolling
    rep = core.step(h, 0.0, 0j, 0.5)
    assert rep.status == 0, rep.message
    assert [k for _, k in rep.transitions] == ["lift_off"]
    assert rep.work < 20_000
    assert abs(core.z) <= p.c_r
