"""Fuzzing the core: random parameters, initial states, inputs and step sizes (slow group).

Examples: 10,000 by default (``ROTORTD_FUZZ_EXAMPLES`` overrides), with a fixed seed and
no example database, so every run replays the same stream.

Every example must finish every step with status OK, no NaN, |z| <= c_r (1 + 1e-12) and
the work counter within its documented bound (the constant WORK_MAX, docs/model.md 7). To
keep the run affordable, a step covers at most MAX_RADIANS of the scene's fastest rate.
"""

from __future__ import annotations

import cmath
import math
import os

import pytest
from hypothesis import HealthCheck, Phase, assume, given, seed, settings
from hypothesis import strategies as st
from rotortd import WORK_MAX, RotorParams, ScaledParams, TouchdownCore, work_cap

pytestmark = pytest.mark.slow
MAX_RADIANS = 40.0


def _logu(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


@st.composite
def scenes(draw: st.DrawFn) -> tuple:
    W_ref = draw(_logu(1.0, 1e5))
    sp = ScaledParams(
        gamma=draw(st.one_of(st.just(0.0), _logu(1e-6, 10.0))),
        omega=draw(st.one_of(st.just(0.0), st.floats(0.0, 3.0))),
        rho=draw(st.one_of(st.just(0.0), _logu(1e-6, 100.0))),
        phi=draw(st.floats(-math.pi, math.pi)),
        mu=draw(st.floats(0.0, 2.0)),
        d=draw(
            st.one_of(st.sampled_from([0.0, 1e-6, 0.5, 0.95, 0.999999, 1.0]), st.floats(0.0, 1.0))
        ),
        R_over_cr=draw(_logu(1.0, 1e3)),
    )
    c_r = draw(st.sampled_from([1e-9, 1e-6, 0.7e-3, 1.0]))
    p = RotorParams.from_scaled(
        sp,
        W_ref,
        m=draw(_logu(0.1, 1e3)),
        c_r=c_r,
        g=draw(st.sampled_from([0.0, 9.81])),
        levitate=draw(st.booleans()),
    )
    r0 = draw(st.one_of(st.just(0.0), st.just(1.0), st.floats(0.0, 1.0)))
    U0 = r0 * cmath.exp(1j * draw(st.floats(-math.pi, math.pi)))
    dU0 = draw(st.floats(0.0, 3.0)) * cmath.exp(1j * draw(st.floats(-math.pi, math.pi)))
    steps = draw(
        st.lists(
            st.tuples(
                _logu(1e-9, 10.0),
                st.sampled_from([1.0, -1.0, 0.0, 0.37]),
                st.sampled_from([0.0, 1.0, 0.5]),
                st.floats(0.0, 2.0),
            ),
            min_size=1,
            max_size=4,
        )
    )
    return p, W_ref, U0, dU0, steps


def _radians(p: RotorParams, h: float, W: float, F: complex, amb: float, speed: float
             ) -> float:
    """Radians of the scene's fastest rate in a step of h s, as the former rate-based work
    cap computed them (to the same rounding, so that the filter, and with it the stream of
    examples, is the one the suite has always run): |Omega|, R|Omega|/c_r, sqrt(k/m), c/m,
    sqrt(F/(m c_r)) for the largest force F, and speed/c_r."""
    force = abs(F) + p.m * p.g + amb * p.m * p.g * p.levitate + p.m * p.e_c * W**2
    w_inputs = max(abs(W), p.R * abs(W) / p.c_r, math.sqrt(amb * p.k / p.m), amb * p.c / p.m,
                   math.sqrt(force / (p.m * p.c_r)))
    w_speed = speed / p.c_r
    x = h * (w_inputs if w_inputs > w_speed else w_speed)
    cap = int(20_000 + 100_000 * (x if x < 1e12 else 1e12))
    return (cap - 20_000) / 100_000


def _friction_rounding(core: TouchdownCore, p: RotorParams, W: float, speed: float,
                       h: float) -> float:
    """The friction work (J) that a normal force inside its rounding band can do in a step
    of h s: a contact is kept while N is above minus that band (``WallForces.gn_tol``:
    64 eps of the scale of the forces at the wall, here times m c_r in N), and sliding
    friction mu N then has N's sign. Its dissipation is zero to mu times the band times the
    slip speed (R |Omega| + c_r |theta'|) times h, which |P_n| (itself about zero there)
    does not measure when the other forces are large."""
    band = 64.0 * 2.220446049250313e-16 * p.m * p.c_r * core.wall_forces.force_scale(
        speed / p.c_r)
    return p.mu * band * (p.R * abs(W) + speed) * h


@seed(20261121)  # the same examples on every machine and path: CI explores what we verify
@settings(
    max_examples=int(os.environ.get("ROTORTD_FUZZ_EXAMPLES", "10000")),
    deadline=None,
    database=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],  # no shrinking: report fast
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(scenes())
def test_random_scenes_finish_within_the_work_cap(scene: tuple) -> None:
    p, W_ref, U0, dU0, steps = scene
    if abs(U0) >= 1.0:  # on the wall: moving inward or tangentially
        dU0 = complex(min(0.0, (dU0 * U0.conjugate()).real), (dU0 * U0.conjugate()).imag)
        dU0 *= U0
    core = TouchdownCore.from_scaled(p, W_ref, U0=U0, dU0=dU0)
    for h, w_scale, amb, f_scale in steps:
        W = w_scale * W_ref
        F = f_scale * p.m * p.c_r * W_ref**2 * cmath.exp(1.3j)
        assume(_radians(p, h, W, F, amb, abs(core.v)) <= MAX_RADIANS)
        speed0 = abs(core.v)
        rep = core.step(h, W, F, amb)
        assert rep.status == 0, rep.message
        assert rep.work <= rep.work_cap == work_cap() == WORK_MAX
        values = (
            core.z.real,
            core.z.imag,
            core.v.real,
            core.v.imag,
            rep.F_n,
            rep.T_f,
            rep.E_diss,
            rep.F_contact.real,
            rep.F_contact.imag,
            rep.F_n_peak,
        )
        assert all(math.isfinite(x) for x in values)
        assert abs(core.z) <= p.c_r * (1 + 1e-12)
        assert rep.E_diss >= -1e-12 * (1 + abs(rep.P_n) * p.c_r * max(abs(W), 1.0)) - (
            _friction_rounding(core, p, W, max(speed0, abs(core.v)), h))
