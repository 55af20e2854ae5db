"""Shared fixtures: the RotorTouchdown FMU built once per test session."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def fmu_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Build the FMU once per session with build.py's own function (no validation here:
    test_fmu_validates does that). ROTORTD_FMU=path skips the build and tests that FMU."""
    prebuilt = os.environ.get("ROTORTD_FMU")
    if prebuilt:
        return Path(prebuilt).resolve()
    sys.path.insert(0, str(ROOT))
    import build

    spec = next(s for s in build.FMU_SPECS if s.name == "RotorTouchdown")
    return build.build_fmu(spec, tmp_path_factory.mktemp("fmu"))
