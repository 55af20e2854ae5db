"""The PythonFMU adapter class in-process, without the FMU binary: paths that a real FMU run
cannot reach easily (a core step that stops at its work cap, host clock mismatch)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "fmu_src"))

from pythonfmu.enums import Fmi2Status
from RotorTouchdown import RotorTouchdown


def _slave(**params: Any) -> RotorTouchdown:
    slave = RotorTouchdown(instance_name="unit")
    for name, value in params.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    return slave


def _errors(slave: RotorTouchdown) -> list[str]:
    return [m.msg for m in slave.log_queue if m.status == Fmi2Status.error]


def test_init_is_cheap_and_builds_nothing() -> None:
    slave = RotorTouchdown(instance_name="unit")
    assert slave._core is None and slave.log_queue == []


def test_work_cap_step_is_refused_and_time_stays(monkeypatch: pytest.MonkeyPatch) -> None:
    slave = _slave(g=9.81)
    assert slave.do_step(0.0, 1e-4)
    core = slave._core
    real_step = core.step

    def capped_step(h: float, *args: Any, **kwargs: Any) -> Any:
        rep = real_step(h / 2, *args, **kwargs)     # the core got only half way
        rep.status, rep.message = 1, "step work exceeded its cap"
        return rep

    monkeypatch.setattr(core, "step", capped_step)
    assert slave.do_step(1e-4, 1e-4) is False
    assert any("step incomplete" in m and "work" in m for m in _errors(slave))
    assert core.t == pytest.approx(1.5e-4, abs=1e-15)


def test_communication_point_mismatch_is_refused() -> None:
    slave = _slave()
    assert slave.do_step(0.0, 1e-4)
    assert slave.do_step(5e-4, 1e-4) is False
    assert any("communication point" in m for m in _errors(slave))


def test_state_document_is_plain_json() -> None:
    slave = _slave(g=9.81)
    for i in range(10):
        assert slave.do_step(i * 1e-4, 1e-4)
    state = slave._get_fmu_state()
    blob = RotorTouchdown._fmu_state_to_bytes(state)
    doc = json.loads(blob)
    assert doc["schema"] == "rotortd-fmu-state" and doc["core"]["schema"] == "rotortd-state"
    assert RotorTouchdown._fmu_state_from_bytes(blob) == state


def test_state_outputs_are_published_by_name_from_the_table() -> None:
    """Every field of the core's StateOutputs is shown by exactly one output of the variable
    table (Var.shows), and after steps through impacts and contact each output holds the
    core's value of its field, by name; a table that names a field the core does not
    have is refused."""
    from rotortd_fmi import touchdown as td
    from rotortd_fmi import touchdown_variables as tv

    slave = _slave(g=9.81, start_steady=True)
    slave.amb_on = 0.0
    t = 0.0
    for _ in range(150):  # the drop: impacts, then contact
        assert slave.do_step(t, 1e-3)
        t += 1e-3
    out = slave._core.outputs()
    assert out.n_impacts > 10 and out.mode != 0
    shows = {v.shows: v.name for v in tv.TABLE if v.shows}
    assert sorted(shows) == sorted(out._fields)
    for field, name in shows.items():
        assert getattr(slave, name) == getattr(out, field), (name, field)
    assert slave.in_contact == (out.mode != 0)
    with pytest.raises(RuntimeError, match="the variable table shows"):
        td.state_publisher((*out._fields, "omega_b"))
