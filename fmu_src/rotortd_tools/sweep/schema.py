"""The sweep's output schema: one row per (point, start), its columns and types."""

from __future__ import annotations

import math
from typing import Any

from rotortd_tools.attractor import DROP_OUTCOMES
from rotortd_tools.sweep.spec import PARAM_NAMES

REGIMES = ("free", "period-1", "period-2", "period-n", "irregular", "rub", "dry-whirl",
           "no-start", "failed")
"""Regime groups (``regime`` itself says ``period-<n>`` with the exact n)."""
DROP_REGIMES = (*DROP_OUTCOMES, "no-start", "failed")
"""The ``regime`` of a ``drop`` run: its outcome (``classify_drop``)."""


COLUMNS: tuple[tuple[str, str], ...] = (
    ("key", "str"), ("index", "i8"), ("start", "str"),
    *((n, "f8") for n in PARAM_NAMES),
    ("transient", "f8"), ("record", "f8"),
    ("status", "str"), ("message", "str"), ("regime", "str"), ("period", "i8"),
    ("period_time", "f8"), ("r_max", "f8"), ("r_min", "f8"), ("n_impacts", "i8"),
    ("impact_rate", "f8"), ("impacts_per_rev", "f8"), ("v_mean", "f8"), ("v_std", "f8"),
    ("v_min", "f8"), ("v_max", "f8"), ("contact_frac", "f8"), ("slide_frac", "f8"),
    ("roll_frac", "f8"), ("final_mode", "i8"), ("U_re", "f8"), ("U_im", "f8"),
    ("dU_re", "f8"), ("dU_im", "f8"), ("sec_angle", "list"), ("sec_speed", "list"),
    ("Omega_end", "f8"), ("Omega_mean", "f8"), ("whirl_mean", "f8"), ("slip_mean", "f8"),
    ("slip_ratio", "f8"), ("final_state", "str"), ("cpu_s", "f8"),
)
"""Output columns and types (str, int64, float64, list<float64>). Store format 4 added the
real bearing's twelve parameters (options as 1.0/0.0, NaN without a bearing). Format 2 added
``J``, ``T_drive`` (parameters, NaN when not given) and ``Omega_end`` (final spin, rad/s),
``Omega_mean``, ``whirl_mean`` (rad/s), ``slip_mean`` (m/s), ``slip_ratio`` (the drop's
window means, NaN for other starts)."""


def arrow_schema():
    """The pyarrow schema of the output."""
    import pyarrow as pa

    types = {"str": pa.string(), "i8": pa.int64(), "f8": pa.float64(),
             "list": pa.list_(pa.float64())}
    return pa.schema([(name, types[t]) for name, t in COLUMNS])



def empty_signature() -> dict[str, Any]:
    """The signature columns of a run that produced none (NaN, 0, empty)."""
    ident = {*PARAM_NAMES, "transient", "record"}
    out: dict[str, Any] = {n: math.nan for n, t in COLUMNS if t == "f8" and n not in ident}
    out.update({"period": 0, "n_impacts": 0, "final_mode": -1, "sec_angle": [],
                "sec_speed": [], "status": "", "message": "", "regime": ""})
    return out


