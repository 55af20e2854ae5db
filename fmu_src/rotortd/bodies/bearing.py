"""The touchdown bearing as a body of its own: the counter-body of the contact pair.

Frame and units: inertial, SI. The rotor (geometric centre z, radius R) meets the bearing's
race, a circle of bore radius R_b = R + c_r whose centre is ``centre``: the rotor touches it
when |z - centre| = c_r, with the outward normal n = (z - centre)/c_r and the tangent i n.
A counter-body owns what the contact pair (``rotortd.contact.pair``) needs of it:

- its motion: ``centre`` (m) and ``velocity`` (m/s) of the race's centre;
- ``surface_speed`` (m/s): the race surface's speed along i n at the contact, R_b omega_b
  for a race turning at omega_b (rad/s);
- ``delassus(n)`` (1/kg): its share (W_nn, W_nt, W_tt) of the contact's Delassus matrix in
  the (n, i n) frame: an impulse (P_n + i P_t) n on it changes the relative normal speed
  and slip at the contact by -W_b (P_n, P_t);
- ``apply_impulse(P_n, P_t, n)`` (N s): its response to that impulse;
- for the contact search: ``moves`` (False for a centre that stays where it is), the path
  of its centre over the rotor's next flight, ``path(s)`` = (c, c', c'', c''') at s seconds
  from the flight's start (m, m/s, m/s^2, m/s^3), ``path_bounds(s, tau)`` = bounds of
  (|c|, |c'|, |c''|, |c'''|, |c''''|) on [s, s + tau], and ``rate`` (1/s), the fastest
  rate of that path (the search's horizon is a fraction of 1/rate);
- ``KIND`` and ``record()``: its kind and its state as a plain dict; the core's state
  (``rotortd.step.state``, JSON ``rotortd-state`` 3) holds them as its "bearing" record.

``FixedRigidBearing`` is the chapter's bearing (docs/model.md §1): fixed at the origin,
rigid, not turning; it takes no share of W and no impulse changes it. A race that turns, a
housing on a spring-damper and a compliant contact (docs/model.md, the real bearing) are
further counter-bodies with this interface; ``tests/test_counter_body.py`` proves the
interface with a free rigid ring (impacts) and a ring whose centre oscillates (the free-flight
search, ``spin_flight.SpinFlight(..., bearing=)``, follows the gap to a moving centre).
"""

from __future__ import annotations

from typing import Protocol


class CounterBody(Protocol):
    """What the contact pair needs of the body the rotor touches (SI, inertial)."""

    c_r: float  # radial clearance (m): contact at |z - centre| = c_r

    def centre(self) -> complex: ...

    def velocity(self) -> complex: ...

    def surface_speed(self, n: complex) -> float: ...

    def delassus(self, n: complex) -> tuple[float, float, float]: ...

    def apply_impulse(self, P_n: float, P_t: float, n: complex) -> None: ...

    moves: bool  # the centre moves during a flight (the search then follows its path)
    rate: float  # fastest rate of the centre's path (1/s); 0 when it does not move

    def path(self, s: float) -> tuple[complex, complex, complex, complex]: ...

    def path_bounds(self, s: float, tau: float
                    ) -> tuple[float, float, float, float, float]: ...

    def record(self) -> dict[str, float]: ...


class FixedRigidBearing:
    """The chapter's touchdown bearing: a rigid circle of radial clearance c_r (m), centred
    at the origin, that neither moves nor turns. SI, inertial."""

    __slots__ = ("c_r",)
    moves = False
    rate = 0.0
    KIND = "fixed-rigid"
    """The "kind" of its state record (``rotortd.step.state``)."""

    def __init__(self, *, c_r: float) -> None:
        self.c_r = c_r

    def centre(self) -> complex:
        return 0j

    def velocity(self) -> complex:
        return 0j

    def surface_speed(self, n: complex) -> float:
        """The race does not turn: 0 m/s."""
        return 0.0

    def delassus(self, n: complex) -> tuple[float, float, float]:
        """Infinitely massive: no share of W (1/kg)."""
        return (0.0, 0.0, 0.0)

    def apply_impulse(self, P_n: float, P_t: float, n: complex) -> None:
        """Fixed and rigid: an impulse changes nothing."""

    def path(self, s: float) -> tuple[complex, complex, complex, complex]:
        return (0j, 0j, 0j, 0j)

    def path_bounds(self, s: float, tau: float) -> tuple[float, float, float, float, float]:
        return (0.0, 0.0, 0.0, 0.0, 0.0)

    def record(self) -> dict[str, float]:
        """No state of its own: {}."""
        return {}
