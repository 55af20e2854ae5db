"""The contact pair's interface carries a counter-body that moves and turns (issue 23, item 2).

A test-only counter-body, ``FreeRing``: a free rigid ring (mass m_b, polar inertia J_b about
its centre, bore R_b = R + c_r, no support), implementing ``rotortd.bodies.bearing.CounterBody``.
Through ``rotortd.contact.pair.ContactPair`` with the spinning rigid rotor, frictionless and
frictional impacts at random states

* use W = the rotor's W + diag(1/m_b, 1/m_b + R_b^2/J_b);
* conserve linear momentum and angular momentum about the origin (to rounding);
* leave the relative normal speed at -d_eff times its value before (d_eff = d unless the
  energetic cap lowered it), and the slip at the law's v_rel+;
* never create energy.

A second test-only counter-body, ``OscillatingRing``, moves its centre on a known path: the
free-flight search (``rotortd.segments.spin_flight.SpinFlight`` with ``bearing=``) finds a grazing
contact with it, at the analytic time, and only because it adds the path's bounds.

And the chapter's case: the held-speed rotor (``RigidRotor.held``, J = inf) on the fixed
rigid bearing gives the held reset law ``impact.reset`` (a declared accelerator) to
rounding.
"""

from __future__ import annotations

import cmath
import math
import random

import pytest
from rotortd.bodies.bearing import FixedRigidBearing
from rotortd.bodies.rotor import RigidRotor
from rotortd.contact.impact import reset
from rotortd.contact.pair import ContactPair

M, R, C_R = 50.0, 0.04, 0.7e-3


class FreeRing:
    """A free rigid ring (test-only counter-body), SI, inertial: centre z_b (m), velocity
    v_b (m/s), spin omega_b (rad/s), mass m_b (kg), inertia J_b (kg m^2), bore R_b (m)."""

    def __init__(self, *, m_b: float, J_b: float, R_b: float, c_r: float, z_b: complex,
                 v_b: complex, omega_b: float) -> None:
        self.m_b, self.J_b, self.R_b, self.c_r = m_b, J_b, R_b, c_r
        self.z_b, self.v_b, self.omega_b = z_b, v_b, omega_b

    def centre(self) -> complex:
        return self.z_b

    def velocity(self) -> complex:
        return self.v_b

    def surface_speed(self, n: complex) -> float:
        return self.R_b * self.omega_b

    def delassus(self, n: complex) -> tuple[float, float, float]:
        return (1.0 / self.m_b, 0.0, 1.0 / self.m_b + self.R_b * self.R_b / self.J_b)

    def apply_impulse(self, P_n: float, P_t: float, n: complex) -> None:
        self.v_b += complex(P_n, P_t) * n / self.m_b
        self.omega_b += self.R_b * P_t / self.J_b

    def max_excursion(self, h: float) -> float:
        return abs(self.v_b) * h

    def record(self) -> dict[str, float]:
        return {"x_b": self.z_b.real, "y_b": self.z_b.imag, "omega_b": self.omega_b}


def _momenta(rotor: RigidRotor, z: complex, v: complex, psi: float, Omega: float,
             ring: FreeRing) -> tuple[complex, float, float]:
    """(linear momentum, angular momentum about the origin, kinetic energy) of both."""
    E = cmath.exp(1j * (psi + rotor.phi))
    zG, vG = z + rotor.e_c * E, v + 1j * rotor.e_c * Omega * E
    P = rotor.m * vG + ring.m_b * ring.v_b
    L = (rotor.m * (zG.conjugate() * vG).imag + rotor.J * Omega
         + ring.m_b * (ring.z_b.conjugate() * ring.v_b).imag + ring.J_b * ring.omega_b)
    T = 0.5 * (rotor.m * abs(vG) ** 2 + rotor.J * Omega ** 2 + ring.m_b * abs(ring.v_b) ** 2
               + ring.J_b * ring.omega_b ** 2)
    return P, L, T


def _random_case(rng: random.Random, mu: float) -> dict:
    e_c = rng.choice([0.0, rng.uniform(0.0, 0.5 * R)])
    J = M * R * R * rng.uniform(0.3, 3.0)
    J = max(J, 1.01 * M * mu * e_c * (R + e_c))  # well posed (rigid.check_well_posed)
    ring = FreeRing(m_b=rng.uniform(0.5, 100.0), J_b=rng.uniform(1e-4, 1.0), R_b=R + C_R,
                    c_r=C_R, z_b=complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-3,
                    v_b=complex(rng.uniform(-1, 1), rng.uniform(-1, 1)),
                    omega_b=rng.uniform(-300.0, 300.0))
    n = cmath.exp(1j * rng.uniform(-math.pi, math.pi))
    rdot = rng.uniform(1e-3, 2.0)
    v = ring.v_b + complex(rdot, rng.uniform(-3.0, 3.0)) * n
    return {"rotor": RigidRotor(M, J, e_c, rng.uniform(-3, 3), R), "ring": ring, "n": n,
            "z": ring.z_b + C_R * n, "v": v, "psi": rng.uniform(-10, 10),
            "Omega": rng.uniform(-500.0, 500.0), "d": rng.uniform(0.0, 1.0), "mu": mu}


@pytest.mark.parametrize("friction", ["frictionless", "frictional"])
def test_free_ring_impacts_conserve_momentum(friction: str) -> None:
    rng = random.Random(23)
    capped = 0
    for _ in range(2000):
        c = _random_case(rng, 0.0 if friction == "frictionless" else rng.uniform(0.05, 1.0))
        rotor, ring, n = c["rotor"], c["ring"], c["n"]
        pair = ContactPair(rotor, ring)
        assert abs(pair.gap(c["z"])) <= 1e-15 * C_R
        P0, L0, T0 = _momenta(rotor, c["z"], c["v"], c["psi"], c["Omega"], ring)
        W = pair.delassus(n, c["psi"])
        Wr = rotor.delassus(n, c["psi"])
        ring_w = (1.0 / ring.m_b, 0.0, 1.0 / ring.m_b + ring.R_b * ring.R_b / ring.J_b)
        assert (W.nn, W.nt, W.tt) == (Wr.nn + ring_w[0], Wr.nt + ring_w[1], Wr.tt + ring_w[2])
        rdot, vrel = pair.velocities(n, c["v"], c["Omega"])
        r = pair.impact(W, c["mu"], c["d"], rdot, vrel)
        v_plus = rotor.velocity_after(c["v"], n, c["psi"], r)
        Omega_plus = c["Omega"] + r.dOmega
        pair.apply(r, n)
        P1, L1, T1 = _momenta(rotor, c["z"], v_plus, c["psi"], Omega_plus, ring)
        scale_P = rotor.m * (abs(c["v"]) + rotor.e_c * abs(c["Omega"])) + ring.m_b * abs(
            ring.v_b) + abs(complex(r.P_n, r.P_t))
        assert abs(P1 - P0) <= 1e-14 * scale_P
        scale_L = (abs(L0) + rotor.J * abs(Omega_plus) + ring.J_b * abs(ring.omega_b)
                   + 1e-3 * scale_P)
        assert abs(L1 - L0) <= 1e-13 * scale_L, (L0, L1)
        assert T1 <= T0 * (1.0 + 1e-13)  # no impact creates energy
        rdot_plus, vrel_plus = pair.velocities(n, v_plus, Omega_plus)
        assert rdot_plus == pytest.approx(-r.d_eff * rdot, abs=1e-12 * (rdot + abs(vrel)))
        assert vrel_plus == pytest.approx(r.vrel_plus, abs=1e-12 * (rdot + abs(vrel)))
        if friction == "frictionless":
            assert r.P_t == 0.0 and r.d_eff == c["d"]
        capped += r.d_eff < c["d"]
    print(f"{friction}: {capped} of 2000 impacts capped")


def test_held_rotor_on_the_fixed_bearing_is_the_held_reset_law() -> None:
    """``impact.reset`` (the held-speed core's accelerator) equals the pair's law with
    J = inf on the chapter's bearing, at random states, to rounding of |v| + R |Omega|."""
    rng = random.Random(5)
    worst = 0.0
    for _ in range(20000):
        mu, d = rng.uniform(0.0, 1.5), rng.uniform(0.0, 1.0)
        Omega = rng.uniform(-1e3, 1e3)
        n = cmath.exp(1j * rng.uniform(-math.pi, math.pi))
        v = complex(rng.uniform(1e-4, 3.0), rng.uniform(-50.0, 50.0)) * n
        pair = ContactPair(RigidRotor.held(M, 3e-4, 0.2, R), FixedRigidBearing(c_r=C_R))
        held = reset(n, v, M, d, mu, R, Omega)
        rdot, vrel = pair.velocities(n, v, Omega)
        r = pair.impact(pair.delassus(n, 0.7), mu, d, rdot, vrel)
        v_plus = pair.rotor.velocity_after(v, n, 0.7, r)
        assert r.dOmega == 0.0 and r.d_eff == d
        err = abs(v_plus - held.v_plus) / (abs(v) + R * abs(Omega))
        worst = max(worst, err, abs(r.P_n - held.P_n) / (M * (abs(v) + R * abs(Omega))))
    assert worst <= 4e-15, worst


class OscillatingRing:
    """A test-only counter-body whose centre moves on a known path, c(s) = A sin(nu s) on
    the x axis (m; s from the flight's start), with the bounds the search needs."""

    moves = True

    def __init__(self, *, c_r: float, A: float, nu: float) -> None:
        self.c_r, self.A, self.nu, self.rate = c_r, A, nu, nu

    def path(self, s: float) -> tuple[complex, complex, complex, complex]:
        A, nu = self.A, self.nu
        sn, cs = math.sin(nu * s), math.cos(nu * s)
        return (complex(A * sn), complex(A * nu * cs), complex(-A * nu * nu * sn),
                complex(-A * nu ** 3 * cs))

    def path_bounds(self, s: float, tau: float) -> tuple[float, float, float, float, float]:
        A, nu = self.A, self.nu
        return (A, A * nu, A * nu * nu, A * nu ** 3, A * nu ** 4)


@pytest.mark.parametrize("excess", [1e-6, 1e-9, 1e-12, -1e-9])
def test_search_finds_a_grazing_contact_with_a_moving_circle(excess: float) -> None:
    """A rotor at rest at the origin (bearing off, no gravity, no imbalance) and a race
    whose centre oscillates with amplitude A = c_r (1 + excess): the gap |z - c(s)| reaches
    c_r only near the turning point nu s = pi/2, tangentially as excess -> 0. The search
    finds the first contact at asin(1/(1 + excess))/nu, on the moving circle; with
    excess < 0 there is none. Against the fixed bearing there is no contact at all."""
    from rotortd.params import RotorParams
    from rotortd.segments.spin_flight import SpinFlight

    p = RotorParams(e_c=0.0, g=0.0)
    nu = 200.0
    ring = OscillatingRing(c_r=p.c_r, A=p.c_r * (1.0 + excess), nu=nu)
    rem = 2.0 / nu  # past the turning point at pi/(2 nu)
    end = SpinFlight(p, 0.04, a=0.0, F_ext=0j, T_drive=0.0, z=0j, v=0j, psi=0.0, Omega=0.0,
                     bearing=ring).run(rem)
    fixed = SpinFlight(p, 0.04, a=0.0, F_ext=0j, T_drive=0.0, z=0j, v=0j, psi=0.0,
                       Omega=0.0).run(rem)
    assert fixed.event is None and fixed.duration == rem
    if excess < 0.0:
        assert end.event is None and end.duration == rem
        return
    s_true = math.asin(1.0 / (1.0 + excess)) / nu
    rdot = p.c_r * nu * math.cos(nu * s_true)  # separation speed at the crossing
    assert end.event == "contact"
    # the conditioning limit of an impact time, eps c_r / rdot, with a margin of 64
    assert abs(end.duration - s_true) <= 64 * 2.2e-16 * (p.c_r / rdot + s_true)
    c = ring.path(end.duration)[0]
    assert abs(abs(end.z - c) - p.c_r) <= 4 * 2.2e-16 * p.c_r
    # the path's bounds are what makes the search rigorous: without them it steps past
    ring.path_bounds = lambda s, tau: (0.0, 0.0, 0.0, 0.0, 0.0)
    blind = SpinFlight(p, 0.04, a=0.0, F_ext=0j, T_drive=0.0, z=0j, v=0j, psi=0.0, Omega=0.0,
                       bearing=ring).run(rem)
    assert blind.event is None
