"""Scenes that fuzzing once broke, kept as quick regression tests.

Each ran into a state handed back and forth between two modes at one instant, or into
an arithmetic corner; each must now finish every step within its work cap.
"""

from __future__ import annotations

import cmath
import math

import pytest
from rotortd import RotorParams, TouchdownCore

CASES = {
    # N crosses 0 while sliding: free flight saw 'pressing', contact saw 'pulling'
    "lift-off tie at N = 0": (
        dict(m=0.2275765295959083, c=0.0, k=0.0, e_c=1.0000000000000232e-09,
             phi=-2.513698661651737, c_r=1e-09, R=1e-09, mu=1e-05, d=0.0, g=0.0,
             levitate=False),
        1.0000002744895709, 1 + 0j, 0j,
        [(0.0003292534624965832, 0.0, 0.0, 0.9443905167400992), (1.0, 1.0, 0.0, 0.1796875)],
    ),
    # sliding restarted at exactly zero slip re-found the trivial event forever
    "slip restart at v_rel = 0": (
        dict(m=1.0, c=0.0, k=0.0, e_c=2.0625403481418077e-09, phi=3.0490926067571964,
             c_r=1e-09, R=1.164531629654549e-09, mu=0.06149251206833829, d=0.0, g=0.0,
             levitate=True),
        9.965667595132976, 0j, 0.34473088621789405 + 0j,
        [(0.0017557449382459415, 0.0, 0.0, 0.08588486635618021),
         (0.9999997255105045, 0.37, 0.0, 4.25009999636114e-178),
         (1.0, -1.0, 0.0, 0.5), (3.037068934499845e-07, 1.0, 0.0, 0.0)],
    ),
    # the friction-cone edge: rolling <-> sliding at one instant
    "friction-cone edge": (
        dict(m=0.5167296306383199, c=0.0, k=0.0, e_c=9.854135872901524e-14,
             phi=1.5630597812840679e-21, c_r=1e-09, R=2.865243745654152e-09,
             mu=1.3521222343271362, d=0.0, g=0.0, levitate=True),
        4.549928114663448, 0j, 0.45142014239913425 - 0.1546026865902977j,
        [(1.0, 0.37, 0.0, 1.7402647114261542),
         (2.5963952828924218e-08, 1.0, 0.0, 1.4754989934842426),
         (0.026707615582180808, 1.0, 0.0, 0.0)],
    ),
    # stick at the slip surface: the bracket started inside the rounding band of v_rel
    "slip surface rounding band": (
        dict(m=1.0, c=0.0, k=0.0, e_c=1.19708503049573e-09, phi=0.0, c_r=1e-09, R=1e-09,
             mu=0.765625, d=0.0, g=0.0, levitate=False),
        1.0, 0j, -0.6219247142870152 + 0.32801587672552446j,
        [(1.0, 0.0, 0.0, 1.6875), (1.0, 1.0, 0.0, 1.25)],
    ),
    # a Coulomb-friction pendulum at the bottom: the extrapolation stayed at order 6 and
    # crawled with 1e-4 s steps until the segment's step cap
    "friction pendulum crawl": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=0.0007, R=0.007, mu=1.625, d=0.0,
             g=9.81, levitate=False),
        1.0, 0j, 0j, [(10**-0.5, 1.0, 0.0, 0.0), (10**-0.5, 1.0, 0.0, 0.0)],
    ),
    # frictionless contact at exactly zero slip: the slip event fired forever
    "frictionless zero slip": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=1e-09, R=1e-09, mu=0.0, d=0.0,
             g=0.0, levitate=False),
        1.0, 1 + 0j, 0j, [(1.0, -1.0, 0.0, 0.0)],
    ),
    # the same with negligible friction (mu = 2.4e-192): the slip cannot leave 0: it rolls
    "negligible friction zero slip": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=1e-09, R=1e-09,
             mu=2.4155040090266096e-192, d=0.0, g=0.0, levitate=False),
        1.0, 1 + 0j, 0j, [(1.0, -1.0, 0.0, 0.0)],
    ),
    # ... and with a force of 1e-47 N: rolling left the cone at once, sliding could not
    # leave zero slip, and the two alternated at t = 0
    "negligible friction and force": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=1e-09, R=1e-09,
             mu=2.4155040090266096e-192, d=0.0, g=0.0, levitate=False),
        1.0, 1 + 0j, 0j, [(1.0, -1.0, 0.0, 1.175494351e-38)],
    ),
    # a denormal force: half the cubic's third coefficient underflowed to exactly 0
    "denormal cubic coefficient": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=1e-06, R=1e-06, mu=0.0, d=0.0,
             g=0.0, levitate=False),
        1.0, 0j, 2 + 0j, [(1.0, 1.0, 0.0, 2.2250738585e-313)],
    ),
    # an oversized first sliding step overflowed: NaN error estimate taken as acceptance
    "overflowing trial step": (
        dict(m=1.1501811128474624, c=0.0006008940895357105, k=0.0, e_c=0.0, phi=0.0,
             c_r=1e-09, R=8.204696109024991e-09, mu=1.0039146309357434, d=0.8984375, g=0.0,
             levitate=False),
        2.4142303421860594, 0j, 2.420150349722683 + 0.9130187576874073j,
        [(1.0, 1.0, 0.0, 0.25), (0.434421818256383, -1.0, 1.0, 0.0),
         (1.0, 1.0, 0.0, 0.6683298125519929)],
    ),
    # N and dN/dt both ~0: flight and contact each deferred to the other at one instant
    "N = 0 tangency": (
        dict(m=0.20969363486673673, c=0.0, k=2.0818481858848616, e_c=0.0,
             phi=1.1654216626502293e-190, c_r=1.0, R=1.0, mu=1.4836769939755359, d=0.0,
             g=0.0, levitate=True),
        13.466073993105262, 0.6218951587218364 - 0.7831005117852636j,
        -2.4877342293903776e-27 + 1.3254640346284061e-27j,
        [(2.5910310228484863, 1.0, 1.0, 2.2250738585072014e-308),
         (2.5910310228484863, 0.37, 1.0, 2.2250738585072014e-308),
         (1.7139042566149303, 1.0, 0.5, 1.6169902024107445)],
    ),
    # a denormal outward force made the low-speed rule divide by zero
    "denormal outward force": (
        dict(m=1.0, c=0.0, k=0.0, e_c=0.0, phi=0.0, c_r=1.0, R=1.0, mu=0.0, d=1e-06, g=0.0,
             levitate=False),
        10.0, 0j, 1 + 0j, [(1.0, 1.0, 0.0, 5e-324)],
    ),
    # at rest on the wall under a 1e-313 N force pulling inward: g'' = 2 Re(conj(z) z'')
    # kept a few subnormal bits of the wrong sign, and the cubic's value underflowed to
    # -0.0, a false root; flight and contact swapped with 1e-16 s progress each
    "subnormal force at rest on the wall": (
        dict(m=79.43282347242814, c=0.0, k=0.0, e_c=1e-06, phi=1.11e-308, c_r=1e-06,
             R=1.4055e-05, mu=1.936, d=0.0, g=0.0, levitate=True),
        1.0, 0j, -2.1401 - 0.451j,
        [(2.1001913985461242, 0.0, 0.0, 0.0),
         (0.00016106877466719004, 0.0, 0.5, 2.225073858507203e-309)],
    ),
    # lift-off onto a free orbit that is the wall itself to rounding (spring force =
    # centripetal force, light damping): g' and g'' were noise, the safe steps 1e-12 s
    "orbit hugging the wall after lift-off": (
        dict(m=3.1622776601683795, c=2.18e-4, k=31.6, e_c=7.8e-3, phi=1.1675, c_r=1.0,
             R=16.4, mu=1.71, d=1.0, g=0.0, levitate=True),
        3.1622776601683795, 0.8775825618903728 + 0.479425538604203j,
        0.13207114752408347 - 0.2417546139353087j,
        [(7.943282347242816, 0.0, 0.5, 8.636e-14), (1.0, 0.0, 0.0, 1.2e-85)],
    ),
    # sliding with no spin, no stiffness and a 1e-313-scale force: the quadratures' error
    # scale RTOL * force * step underflowed to 0, and the error ratio divided by it
    "zero quadrature scale": (
        dict(m=10.0**0.0001, c=0.30645776667198604, k=0.0, e_c=0.008812477882559172,
             phi=0.21847372314578806, c_r=0.0007, R=0.0011094252347227794,
             mu=1.23612693087726, d=0.0, g=0.0, levitate=True),
        10.0**1e-12, 0.9983311027073072 - 2.2606985748068535e-82j,
        1.0940229283516185 + 0.1765356520875684j,
        [(0.87794780371698, 0.0, 1.0, 2.2250738585e-313),
         (2.706929219243636e-06, 1.0, 1.0, 0.8566378332269446),
         (0.0012271309434914875, 0.37, 0.5, 0.6505749283211385),
         (0.07817697848514178, 1.0, 0.5, 1.0313241891874585)],
    ),
    # k = 2e-200: the steady offset f0/kappa overflowed in the envelope bound
    "tiny stiffness": (
        dict(m=1.0, c=0.0, k=1.9729346285183482e-200, e_c=0.0, phi=0.0, c_r=1e-09, R=1e-09,
             mu=0.0, d=0.0, g=0.0, levitate=False),
        1.0, 0j, 0j, [(1.0, 1.0, 1.0, 1.0), (1.0, 1.0, 1.0, 1.0)],
    ),
}


@pytest.mark.parametrize("name", list(CASES))
def test_fuzz_regression(name: str) -> None:
    par, W_ref, U0, dU0, steps = CASES[name]
    p = RotorParams(**par)
    core = TouchdownCore.from_scaled(p, W_ref, U0=U0, dU0=dU0)
    for h, w_scale, amb, f_scale in steps:
        W = w_scale * W_ref
        F = f_scale * p.m * p.c_r * W_ref**2 * cmath.exp(1.3j)
        rep = core.step(h, W, F, amb)
        assert rep.status == 0, rep.message
        assert rep.work <= rep.work_cap
        assert math.isfinite(core.z.real) and abs(core.z) <= p.c_r * (1 + 1e-12)
        assert rep.E_diss >= 0.0
