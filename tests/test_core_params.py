"""Parameter and input validation: every bad value is named with its range."""

from __future__ import annotations

import math

import pytest
from rotortd import InputError, ParameterError, RotorParams, TouchdownCore

BAD = [
    ("m", 0.0),
    ("m", -1.0),
    ("c_r", 0.0),
    ("R", -0.1),
    ("k", -1.0),
    ("c", -5.0),
    ("d", 1.5),
    ("d", -0.1),
    ("mu", -0.2),
    ("e_c", -1e-4),
    ("g", -9.81),
    ("m", math.nan),
    ("k", math.inf),
    ("phi", math.nan),
    ("c", -math.inf),
]


@pytest.mark.parametrize(("name", "value"), BAD)
def test_bad_parameter_is_named(name: str, value: float) -> None:
    with pytest.raises(ParameterError) as exc:
        RotorParams(**{name: value})
    assert str(exc.value).startswith(f"{name} = ")
    assert "range" in str(exc.value) or "finite" in str(exc.value)


def test_initial_position_outside_clearance() -> None:
    p = RotorParams()
    with pytest.raises(ParameterError, match="outside the clearance"):
        TouchdownCore(p, z0=1.01 * p.c_r)


def test_scaled_conversion_round_trip_and_Omega_zero() -> None:
    p = RotorParams()
    sp = p.scaled(184.2)
    assert sp.gamma == pytest.approx(0.152009, abs=1e-6)
    assert sp.omega == pytest.approx(0.760043, abs=1e-6)
    assert sp.rho == pytest.approx(3 / 7, rel=1e-15)
    assert sp.R_over_cr == pytest.approx(57.142857, rel=1e-7)
    back = RotorParams.from_scaled(sp, 184.2, m=p.m, c_r=p.c_r)
    for f in ("c", "k", "e_c", "R"):
        assert getattr(back, f) == pytest.approx(getattr(p, f), rel=1e-14)
    with pytest.raises(ParameterError, match="Omega = 0"):
        p.scaled(0.0)


def test_steady_whirl_not_admissible_is_an_error() -> None:
    p = RotorParams().replace(c=0.05 * 50 * 184.2)  # below gamma_BEB: U* outside
    with pytest.raises(ParameterError, match="not admissible"):
        TouchdownCore.on_steady_whirl(p, 184.2)


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"h": 0.0}, "h"),
        ({"h": math.nan}, "h"),
        ({"Omega": math.inf}, "Omega"),
        ({"amb_on": 1.5}, "amb_on"),
        ({"amb_on": -0.1}, "amb_on"),
        ({"F_ext": complex(math.nan, 0)}, "F_x"),
    ],
)
def test_bad_input_is_named_and_state_kept(kw: dict, name: str) -> None:
    core = TouchdownCore(RotorParams())
    core.step(1e-3, 184.2)
    before = core.get_state()
    args = {"h": 1e-3, "Omega": 184.2} | kw
    with pytest.raises(InputError, match=f"^{name} = "):
        core.step(**args)
    assert core.get_state() == before


def test_declared_ranges_lie_inside_the_model_domain() -> None:
    """Every FMU range of a RotorParams field (``limits.LIMITS``) is inside the domain that
    RotorParams checks: both ends construct (the others at their defaults)."""
    from dataclasses import fields

    from rotortd.limits import LIMITS

    names = {f.name for f in fields(RotorParams)} & set(LIMITS)
    assert len(names) >= 9, names
    for name in sorted(names):
        for end in (LIMITS[name].lo, LIMITS[name].hi):
            RotorParams(**{name: end})
