"""get_state/set_state: JSON round trip, bit-for-bit continuation, schema check."""

from __future__ import annotations

import json

import pytest
from rotortd import ParameterError, RotorParams, TouchdownCore

W0 = 184.2


@pytest.mark.parametrize("gamma", [0.3, 0.065, 0.1])
def test_restore_reproduces_run_bit_for_bit(gamma: float) -> None:
    p = RotorParams().replace(c=gamma * 50 * W0)
    core = TouchdownCore(p, 0.2 * p.c_r, 0.5j * p.c_r * W0)
    for _ in range(300):
        core.step(1e-3, W0)
    saved = json.loads(json.dumps(core.get_state()))
    ref = [_step_row(core) for _ in range(400)]
    twin = TouchdownCore(RotorParams())
    twin.set_state(saved)
    again = [_step_row(twin) for _ in range(400)]
    assert twin.get_state() == core.get_state()
    assert ref == again


def _step_row(core: TouchdownCore) -> tuple:
    """A step's report (contact force, friction torque, impacts) and the mode after it."""
    r = core.step(1e-3, W0)
    return r.F_contact, r.T_f, core.mode, len(r.impacts)


def test_foreign_state_is_refused() -> None:
    core = TouchdownCore(RotorParams())
    st = core.get_state() | {"version": 99}
    with pytest.raises(ParameterError, match="version"):
        core.set_state(st)
