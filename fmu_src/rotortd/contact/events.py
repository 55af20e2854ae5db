"""The one vocabulary of segment events, for both spin models (docs/architecture.md)."""

from __future__ import annotations

import enum


class Event(str, enum.Enum):
    """The one vocabulary of segment events (``SegmentEnd.event``, ``Contact.kind``), for
    both spin models. A str enum: a member equals its value ("lift_off" == LIFT_OFF), so
    records and tests may compare with the plain string; the core compares members."""

    __str__ = str.__str__

    IMPACT = "impact"
    """Flight: the rotor reaches the wall moving outward (normal speed resolved)."""
    TOUCH = "touch"
    """Flight: at the wall with zero normal speed to resolution, curving outward."""
    CLEAR = "clear"
    """Flight (held spin): the search used its advances; resume from the segment's end."""
    CONTACT = "contact"
    """Flight (spin a state): at the wall; the core classifies impact or touch."""
    LIFT_OFF = "lift_off"
    """Contact: the normal force reaches 0 (it never pulls)."""
    SLIP_ZERO = "slip_zero"
    """Sliding: the slip v_rel reaches 0."""
    SLIP_STUCK = "slip_stuck"
    """Sliding (held spin): zero slip that sliding cannot leave; rolling follows."""
    SLIP_START = "slip_start"
    """Rolling: the static friction needed reaches mu N (the friction cone's edge)."""
    SEPARATE = "separate"
    """Contact, compliant law: the penetration reaches 0 (the contact opens)."""
    CLAMP_END = "clamp_end"
    """Contact, compliant law: the law's value, clamped at 0 inside the penetration, is
    positive again."""
    RACE_STOP = "race_stop"
    """Contact, turning race with static friction: its spin reaches 0."""
    BREAKAWAY = "breakaway"
    """Contact, race held at rest: the static torque that holds it reaches T_b0."""


# The members as module constants, for the hot paths (segment ends, event functions): in
# Python 3.11 reading ``Event.X`` passes through EnumType.__getattr__'s hook, ~900
# instructions; a module constant, ~20. The same objects (``CONTACT is Event.CONTACT``).
IMPACT, TOUCH, CLEAR, CONTACT = Event.IMPACT, Event.TOUCH, Event.CLEAR, Event.CONTACT
LIFT_OFF, SLIP_ZERO, SLIP_STUCK = Event.LIFT_OFF, Event.SLIP_ZERO, Event.SLIP_STUCK
SLIP_START = Event.SLIP_START
SEPARATE, CLAMP_END, RACE_STOP, BREAKAWAY = (Event.SEPARATE, Event.CLAMP_END, Event.RACE_STOP,
                                             Event.BREAKAWAY)
