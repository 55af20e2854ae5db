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
