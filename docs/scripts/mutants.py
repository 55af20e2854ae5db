"""Mutation audit of the quick test group (issue 27): does it catch real-looking bugs?

    python docs/scripts/mutants.py --list               # the table, and where each change applies
    python docs/scripts/mutants.py --only E1,S1         # run two mutants
    python docs/scripts/mutants.py [--jobs 1] [--timeout 1800] [--json docs/mutants.json]
    python docs/scripts/mutants.py --docs               # the table of docs/mutants.md from the json

Each mutant is one physically meaningful change of the sources, located by an exact snippet
(``old`` -> ``new``), never by file or line: the snippet must occur exactly once in all of
fmu_src/**/*.py of the copy, whichever file holds it (so moving a module does not break the
table). A snippet found 0 or more than once is reported as status ``stale`` with its count.

For each mutant: a temporary copy of the working tree (the files git lists, tracked and
untracked, uncommitted changes included; not .git, models/*.fmu or caches), the change
applied there, then the quick group run on the copy,

    python -m pytest -m "not slow" -x -q -p no:cacheprovider HINT_FILES
    python -m pytest -m "not slow" -x -q -p no:cacheprovider --ignore=HINT_FILE... tests

with PYTHONPATH=<copy>/fmu_src and the copy as working directory. The FMU tests build their
FMU from the copy (tests/conftest.py: build.py of the copy), so they run the mutated adapter.
``hint`` lists test files run first (the ones expected to kill it), in a session of their
own; the second session runs the rest. With ``-x`` a killed mutant stops at its first
failure, and a survivor runs the whole quick group (both sessions) anyway.

Results: ``killed`` (with the first failing test's node id), ``survived`` (the whole quick
group passed), ``stale`` (snippet count != 1), ``timeout``, ``error`` (pytest could not run;
the tail of its output is kept). A survivor must be killed by a new test of a documented
claim, or shown equivalent: its ``equivalent`` field gives the argument. The table is
printed and written to docs/mutants.json (with --only, the other rows are kept). docs/mutants.md
says how long a full run takes; run it again whenever the core changes.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_JSON = ROOT / "docs" / "mutants.json"
CLAIMS = "tests/test_documented_claims.py"


@dataclass(frozen=True)
class Mutant:
    """One single change: ``old`` replaced by ``new`` where it occurs (once) in fmu_src."""

    id: str
    area: str
    what: str
    old: str
    new: str
    hint: tuple[str, ...] = ()
    equivalent: str = ""
    note: str = ""
    """For a survivor neither killed nor shown equivalent yet: what is known (shown in the
    table)."""


M = Mutant
MUTANTS: tuple[Mutant, ...] = (
    # ---------------------------------------------------------------- impact laws
    M("I1", "impact law", "friction impulse of the held impact law with the wrong sign",
      "dvt = mu * (1.0 + d) * rdot * s", "dvt = -mu * (1.0 + d) * rdot * s",
      ("tests/test_core_impact.py",)),
    M("I2", "impact law", "restitution d -> 0.999 d in the held impact law",
      "v_plus = complex(-d * rdot, vt_p) * n", "v_plus = complex(-0.999 * d * rdot, vt_p) * n",
      ("tests/test_core_impact.py",)),
    M("I3", "impact law", "stick cap removed: friction may reverse the slip",
      "    stick = abs(dvt) > abs(vrel_m)\n", "    stick = False\n",
      ("tests/test_core_impact.py",)),
    M("I4", "impact law", "impact dissipation without its friction part",
      "E = 0.5 * m * (1.0 - d * d) * rdot * rdot + 0.5 * P_t * (vrel_m + vrel_p)",
      "E = 0.5 * m * (1.0 - d * d) * rdot * rdot",
      ("tests/test_core_impact.py",)),
    M("R1", "spin-state impact law", "sliding impact's friction against the pre-impact slip",
      "sig = 1.0 if Pt > 0.0 else -1.0\n    Pn = D / (w.nn + mu * sig * w.nt)",
      "sig = 1.0 if vrel > 0.0 else -1.0\n    Pn = D / (w.nn + mu * sig * w.nt)",
      ("tests/test_rigid.py",)),
    M("R2", "spin-state impact law", "energetic cap removed (Newton's restitution may gain)",
      "if dT > 0.0:  # Newton's restitution would create energy: cap it",
      "if False:  # Newton's restitution would create energy: cap it",
      ("tests/test_rigid.py",)),
    M("R3", "spin-state impact law", "sticking impact accepted only inside half the cone",
      "if Pn >= 0.0 and abs(Pt) <= mu * Pn:", "if Pn >= 0.0 and abs(Pt) <= 0.5 * mu * Pn:",
      ("tests/test_rigid.py",)),
    M("R4", "spin state", "Delassus W_nn without the spin's share B^2/J",
      "return cls(B, A, J, im + B * B * iJ, A * B * iJ, im + A * A * iJ)",
      "return cls(B, A, J, im, A * B * iJ, im + A * A * iJ)",
      ("tests/test_rigid.py",)),
    M("R5", "spin state", "the centre's velocity after an impact: the mass centre's turn "
      "with the wrong sign", "return v - complex(r.P_n, r.P_t) * n / self.m - r.dOmega * iE",
      "return v - complex(r.P_n, r.P_t) * n / self.m + r.dOmega * iE",
      ("tests/test_spin_core.py",)),
    # ---------------------------------------------------------------- contact search
    M("E1", "contact search", "resolution TOL_G loosened a thousandfold (issue 27)",
      "TOL_G_ULPS = 64.0", "TOL_G_ULPS = 64000.0", (CLAIMS,)),
    M("E2", "contact search", "spin-state search's TOL_G loosened a thousandfold",
      "TOL_G = 16.0 * EPS\n", "TOL_G = 16000.0 * EPS\n", (CLAIMS,)),
    M("E3", "contact search", "Newton polish of an impact skipped",
      "        for _ in range(3):\n            if g1 <= 0.0:\n",
      "        for _ in range(0):\n            if g1 <= 0.0:\n", (CLAIMS,)),
    M("E4", "contact search", "quartic remainder dropped from the search's cubic bound",
      "c3 = g3 + (slack + 16.0 * EPS * (s0 + V * (s1 + V * s2)) + TINY)",
      "c3 = g3 + (16.0 * EPS * (s0 + V * (s1 + V * s2)) + TINY)",
      ("tests/test_core_events.py",)),
    M("E5", "contact search", "touch test ignores the exact g''' at rounding level",
      "if g2 > tol_g2 or (g2 >= -tol_g2 and self.g3(z, v, E) > 0.0):", "if g2 > tol_g2:",
      (CLAIMS,)),
    M("E6", "contact search", "spin-state Newton polish stops at 1e-10 instead of 4 eps",
      "POLISH_G = 4.0 * EPS", "POLISH_G = 1e-10", (CLAIMS, "tests/test_spin_flight.py")),
    # ---------------------------------------------------------------- contact modes
    M("S1", "contact transitions", "sliding lifts off only once N < -1e-9 of the force "
      "scale (the wall pulls; issue 27)", "            if gn <= 0.0 or sv <= 0.0:\n",
      "            if gn < -1e-9 * self.force_tol / RTOL or sv <= 0.0:\n", (CLAIMS,)),
    M("S2", "contact modes", "sliding friction with the wrong sign",
      "        self.mus = wf.mu * slip\n", "        self.mus = -wf.mu * slip\n",
      ("tests/test_contact.py",)),
    M("S3", "contact modes", "sliding integrator tolerance 1e-13 -> 1e-9",
      "RTOL = 1e-13\n\"\"\"Relative tolerance of the sliding integrator.\"\"\"",
      "RTOL = 1e-9\n\"\"\"Relative tolerance of the sliding integrator.\"\"\"",
      ("tests/test_contact.py",)),
    M("S4", "contact transitions", "sliding event located to 1e-9 of the time, not 1 ulp",
      "or hi - lo <= 2e-16 * (abs(u) + hi) + 1e-300,",
      "or hi - lo <= 1e-9 * (abs(u) + hi) + 1e-300,", ("tests/test_contact.py",),
      note="survives the quick group since the search also stops on the rounding band of "
           "the event functions (seen[hi] >= -noise, added after this mutant was written): "
           "no quick test has a sliding event whose search ends on the bracket's width; "
           "not shown equivalent, not run against the slow group"),
    M("C1", "contact transitions", "lift-off tie-break at N = 0 inverted (leaves while N "
      "grows)", "return wf.gn_rate(self._theta, self._dtheta, E, dd) <= 0.0",
      "return wf.gn_rate(self._theta, self._dtheta, E, dd) >= 0.0",
      (CLAIMS,)),
    M("C2", "contact transitions", "slip zero always rolls (friction cone not checked)",
      "        self._choose_contact_mode()\n\n    def _cone_sign(",
      "        self._mode = MODE_ROLLING\n\n    def _cone_sign(",
      (CLAIMS,)),
    M("RO1", "contact modes", "rolling exit search: curvature bound M quartered (a step "
      "may jump over a lift-off or cone exit)",
      "M = abs(self.a1) * self.nu1**2 + abs(self.a2) * self.nu2**2",
      "M = 0.25 * (abs(self.a1) * self.nu1**2 + abs(self.a2) * self.nu2**2)",
      (CLAIMS,)),
    M("RO2", "contact modes", "rolling proved endless from one phasor's amplitude only",
      "return self.C - abs(self.a1) - abs(self.a2) > 0.0",
      "return self.C - abs(self.a1) > 0.0", (CLAIMS,)),
    M("RO3", "contact modes", "rolling exit search that ran out of advances claims its whole "
      "span free of exits", "        return None, u  # f > 0 on [0, u]",
      "        return None, x_max  # f > 0 on [0, u]", (CLAIMS,)),
    M("RU1", "contact modes", "linearised rub admitted at a 1e-10 error budget (1e-14)",
      "LINEAR_BUDGET = 1e-14", "LINEAR_BUDGET = 1e-10", ("tests/test_contact.py",)),
    M("RU2", "contact modes", "rub locked when the snap moves the state by 1e-10 (1e-14)",
      "LOCK_TOL = 1e-14", "LOCK_TOL = 1e-10", ("tests/test_contact.py",)),
    M("SC1", "spin-state contact", "spin-state contact: the midpoint check of the event "
      "functions dropped", "        if self._margin(mid) <= 0.0:\n",
      "        if False:\n", ("tests/test_spin_contact_mp.py",)),
    # ---------------------------------------------------------------- low-speed rule
    M("L1", "low-speed rule", "chattering threshold ETA_HEIGHT tenfold",
      "ETA_HEIGHT = 1e-14", "ETA_HEIGHT = 1e-13", ("tests/test_contact.py",)),
    M("L2", "low-speed rule", "cascade count N_CASCADE 1000 -> 100",
      "N_CASCADE = 1000", "N_CASCADE = 100", ("tests/test_contact.py",)),
    M("L3", "low-speed rule", "the impact that starts contact keeps its restitution",
      "r = reset(n, v_minus, p.m, 0.0, p.mu, p.R, W)",
      "r = reset(n, v_minus, p.m, p.d, p.mu, p.R, W)", (CLAIMS,)),
    M("L4", "low-speed rule", "accumulation time of the cascade halved (t_contact_entry)",
      "self._t_contact = t + (2.0 * d * r.rdot / ((1.0 - d) * A) if d < 1.0 else 0.0)",
      "self._t_contact = t + (d * r.rdot / ((1.0 - d) * A) if d < 1.0 else 0.0)",
      ("tests/test_contact.py",)),
    # ---------------------------------------------------------------- forces, spin, clock
    M("F1", "model forces", "imbalance force doubled",
      "self.F1 = p.e_c * self.Omega * self.Omega * cmath.exp(1j * p.phi)",
      "self.F1 = 2.0 * p.e_c * self.Omega * self.Omega * cmath.exp(1j * p.phi)",
      ("tests/test_core_flight.py",)),
    M("F2", "model forces", "AMB bias force with the wrong sign",
      "return 1j * self.m * self.g if self.levitate else 0j",
      "return -1j * self.m * self.g if self.levitate else 0j", ("tests/test_core_flight.py",)),
    M("F3", "imbalance torque", "T_imb's segment term with the wrong sign",
      "rep.P_imb -= p.e_c * p.m * W * W * (self._fm.imb_eph * E * K.conjugate()).imag",
      "rep.P_imb += p.e_c * p.m * W * W * (self._fm.imb_eph * E * K.conjugate()).imag",
      ("tests/test_imbalance_torque.py",)),
    M("K1", "clock", "the clock drifts by 1e-12 s per step",
      "        t = self._t + y\n        self._t_lo = (t - self._t) - y\n",
      "        t = self._t + y + 1e-12\n        self._t_lo = (t - self._t) - y\n",
      ("tests/test_core_state.py",)),
    M("K2", "clock", "the clock drifts by 1e-13 s per step",
      "        t = self._t + y\n        self._t_lo = (t - self._t) - y\n",
      "        t = self._t + y + 1e-13\n        self._t_lo = (t - self._t) - y\n",
      ("tests/test_core_state.py",)),
    M("P1", "report", "F_n_peak sums the step's contact segments' peaks instead of taking "
      "the largest (issue 27; issue 24 made impulses leave it)",
      "self.F_n_peak = max(self.F_n_peak, mc * tal.peak)",
      "self.F_n_peak = self.F_n_peak + mc * tal.peak", (CLAIMS,)),
    # ---------------------------------------------------------------- work bound
    M("W1", "work bound", "WORK_MAX tenfold", "WORK_MAX = 1_600_000", "WORK_MAX = 16_000_000",
      (CLAIMS,)),
    M("W2", "work bound", "the step loop's work check ten times late",
      "                if work.total > cap:\n", "                if work.total > 10 * cap:\n",
      ("tests/test_work_bound.py",)),
    M("W3", "work bound", "a segment of the event loop costs 1 unit instead of 8",
      "SEGMENT_WORK = 8", "SEGMENT_WORK = 1", (CLAIMS,)),
    # ---------------------------------------------------------------- adapter
    M("A1", "adapter validation", "range check of tunables changed mid-run removed "
      "(issue 27)", "            self._require_ranges(tuple(changes))\n", "",
      (CLAIMS,)),
    M("A2", "adapter publishing", "F_n published as F_n_peak",
      "self.F_n = F_n = rep.F_n\n", "self.F_n = F_n = rep.F_n_peak\n", ("tests/test_fmu.py",)),
    M("A3", "adapter validation", "fixed parameters may change mid-run",
      "            if not _same(getattr(self, name), value):\n",
      "            if False:\n", ("tests/test_fmu_misuse.py",)),
    M("A4", "adapter validation", "a communication point up to 1 s off is accepted",
      "if not abs(current_time - t) <= tol:", "if not abs(current_time - t) <= 1.0 + tol:",
      ("tests/test_fmu_misuse.py",)),
    M("A5", "adapter validation", "ranges exclusive of their bounds",
      "if lo <= x <= hi and x - x == 0.0:", "if lo < x < hi and x - x == 0.0:",
      ("tests/test_fmu_misuse.py",)),
    M("A6", "adapter publishing", "T_f published with the wrong sign",
      "self.T_f = T_f = rep.T_f\n", "self.T_f = T_f = -rep.T_f\n", ("tests/test_fmu.py",)),
    # ---------------------------------------------------------------- state round trip
    M("T1", "state round trip", "the sliding step size is not restored (slide_step)",
      '("contact.slide_step", "slide_step", INF_NULL),',
      '("contact.slide_step", "slide_step", Codec(lambda x: None, lambda x: math.inf)),',
      ("tests/test_core_state.py",)),
    M("T2", "state round trip", "version 1 and 2 states are read as version 3",
      '        if st["version"] < 3:\n            st = upgrade(st)\n', "",
      ("tests/test_core_state.py",)),
    M("T3", "state round trip", "the clock's rounding error is not restored (t_lo)",
      '("clock.t_lo", "t_lo", FLOAT),', '("clock.t_lo", "t_lo", Codec(lambda x: 0.0, float)),',
      ("tests/test_core_state.py",)),
    # ---------------------------------------------------------------- the real bearing (24)
    M("B1", "real bearing: compliant law", "the contact damping's sign flipped "
      "(N = K delta^p (1 - chi delta'))", "N_law = N_el * (1.0 + self.cs.chi * dd)",
      "N_law = N_el * (1.0 - self.cs.chi * dd)", ("tests/test_real_bearing_core.py",)),
    M("B2", "real bearing: compliant law", "chi from the closing speed without the floor "
      "(a slow closure undamped)", "return c_d / max(v_onset, V_FLOOR)",
      "return c_d / max(v_onset, 1e-300)", ("tests/test_real_bearing_core.py",)),
    M("B3", "real bearing: contact forces", "the contact's torque on the spin loses its lever "
      "B (the imbalance's)", "dOm = dOm0 - (B * N + A * Ft) * iJ",
      "dOm = dOm0 - (A * Ft) * iJ", ("tests/test_real_bearing_core.py",)),
    M("B4", "real bearing: race", "friction does not turn the race in contact",
      "wbd = wbd0 + R_b * Ft * self.iJb", "wbd = wbd0", ("tests/test_real_bearing_core.py",)),
    M("B5", "real bearing: race", "the race breaks away at twice its static friction",
      "if hold and law.R_b * abs(f.F_t) > law.T_b0:",
      "if hold and law.R_b * abs(f.F_t) > 2.0 * law.T_b0:",
      ("tests/test_real_bearing_core.py",)),
    M("B6", "real bearing: impulses", "an impulse on the sprung race moves it twice as much",
      "self.v_b += complex(P_n, P_t) * n / bp.m_b",
      "self.v_b += 2.0 * complex(P_n, P_t) * n / bp.m_b",
      ("tests/test_real_bearing_core.py", "tests/test_real_race.py")),
    M("B7", "real bearing: events", "the midpoint check of the contact's event functions "
      "removed", "if self._margin(self._hermite(y, f0, y1, f1, Hs, 0.5)) <= 0.0:",
      "if False:", ("tests/test_real_bearing_core.py",)),
    # ---------------------------------------------------------------- spin quiet step (#26)
    M("Q1", "spin quiet step", "the clearance proof without the acceleration term",
      "return max(abs(z0), abs(z0 + h * v0)) + hh * A <= r_in",
      "return max(abs(z0), abs(z0 + h * v0)) <= r_in", ("tests/test_spin_quiet.py",)),
    M("Q2", "spin quiet step", "the second-order torque without e^{i delta}'s real part",
      "t1 = TJ + mJ * (y1.imag * (1.0 - s1) + y1.real * d1)", "t1 = TJ + mJ * y1.imag",
      ("tests/test_spin_quiet.py",)),
    M("Q3", "spin quiet step", "y'' at the nodes without the spring's share (kA y)",
      "Mpp.append([((1.0 if i == j else 0.0) - cA * GNp[j] - kA * GN[j]) / m",
      "Mpp.append([((1.0 if i == j else 0.0) - cA * GNp[j]) / m",
      ("tests/test_spin_quiet.py",)),
    M("Q4", "spin quiet step", "the truncation estimate at W h instead of 2 W h",
      "w6 = 2.0 * Wt * h", "w6 = Wt * h", ("tests/test_spin_quiet.py",)),
    M("Q5", "spin quiet lane", "the lane's T_imb without the drive torque's impulse",
      "), (J * (W - W0) - T * h + R0) / h", "), (J * (W - W0) + R0) / h",
      ("tests/test_spin_quiet.py",)),
    # ---------------------------------------------------------------- dry whirl step map (#26)
    M("DM1", "dry whirl step map", "the map's u trimmed to the phase tolerance alone (not to "
      "TOL_IMPULSE of u, which the mean impulse d00 u carries)",
      "TOL_IMPULSE * u_min)  # (u carries", "1e300 * u_min)  # (u carries",
      ("tests/test_dry_whirl_orbit.py",)),
    M("DM2", "dry whirl step map", "the map's choice left out of the state (a restored "
      "state takes Newton where the run it continues took the map)",
      "orbit_step=(self._orbit.last_rem if", "orbit_step=(math.nan if",
      ("tests/test_dry_whirl_orbit.py",)),
    M("DM3", "dry whirl step map", "the residual rounded relative to h, not to x",
      "        return r0 + f00 * x + 2.0", "        return f00 * (u_lin + x) - rem + 2.0",
      ("tests/test_dry_whirl_orbit.py",)),
    M("DM4", "dry whirl step map", "the step loop asks the orbit again after the core's "
      "rolling step was refused by it (the build charged twice, the map built early)",
      "        st.orbit_asked = asked", "        st.orbit_asked = False",
      ("tests/test_dry_whirl_orbit.py",)),
    # ---------------------------------------------------------------- dry whirl level table (#26)
    M("DW1", "dry whirl level table", "the level held at the step's start in the periodic "
      "part's weights (X = 1 + delta u taken as 1)",
      "        X = 1.0 + self.delta * u", "        X = 1.0", ("tests/test_dry_whirl_driven.py",)),
    M("DW2", "dry whirl level table", "the Levin terms m >= 1 all of one sign",
      "(-1.0) ** m * math.prod(p0 - k - i for i in range(m))",
      "math.prod(p0 - k - i for i in range(m))",
      ("tests/test_dry_whirl_driven.py",)),
    M("DW3", "dry whirl level table", "the table also at the direct panel's steps (a turn "
      "of theta below TABLE_TURN)",
      "    if h.p.R / h.p.c_r * rem * abs(Omega) <= TABLE_TURN:",
      "    if h.p.R / h.p.c_r * rem * abs(Omega) <= -1.0:", ("tests/test_dry_whirl_driven.py",)),
    M("DW4", "dry whirl level table", "the mean's change with the level dropped (its "
      "integral taken at the step's start level)",
      "        return acc * u", "        return 0.0 * acc", ("tests/test_dry_whirl_driven.py",)),
)


NOTES = {m.id: m.note for m in MUTANTS if m.note}


# ---------------------------------------------------------------------------- the copy
def source_files(root: Path) -> list[Path]:
    """The working tree's files (tracked and untracked, uncommitted changes included), as
    git lists them; without git, every file but caches, .git, .venv, out and built FMUs."""
    try:
        out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=root,
                             capture_output=True, check=True).stdout.decode()
        return [root / p for p in out.split("\0") if p and (root / p).is_file()]
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", ".venv", "__pycache__", "out", ".pytest_cache", ".ruff_cache"}
        return [p for p in root.rglob("*") if p.is_file()
                and not skip.intersection(p.relative_to(root).parts) and p.suffix != ".fmu"]


def make_copy(root: Path, files: list[Path], git: bool = True) -> Path:
    """A temporary copy of ``files`` (paths under root), made a git repository with every
    file staged (tests list the repository's files with ``git ls-files``; no commit)."""
    dest = Path(tempfile.mkdtemp(prefix="rotortd-mutant-"))
    for f in files:
        target = dest / f.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(f, target)
    if not git:
        return dest
    for cmd in (["git", "init", "-q"], ["git", "add", "-A"]):
        subprocess.run(cmd, cwd=dest, check=True, capture_output=True)
    return dest


def locate(src_root: Path, old: str) -> tuple[list[Path], int]:
    """(files holding ``old``, total count) over src_root/fmu_src/**/*.py."""
    hits, total = [], 0
    for f in sorted((src_root / "fmu_src").rglob("*.py")):
        n = f.read_text(encoding="utf-8").count(old)
        if n:
            hits.append(f)
            total += n
    return hits, total


def apply(copy: Path, m: Mutant) -> str | None:
    """Apply m in the copy; None when done, else why not (stale)."""
    if not m.old:
        return "no snippet"
    hits, total = locate(copy, m.old)
    if total != 1:
        return f"snippet found {total} times"
    f = hits[0]
    f.write_text(f.read_text(encoding="utf-8").replace(m.old, m.new), encoding="utf-8")
    return None


# ---------------------------------------------------------------------------- one run
_FAILED = re.compile(r"^(FAILED|ERROR) (\S+)", re.MULTILINE)


def pytest_commands(hint: tuple[str, ...]) -> list[list[str]]:
    """The quick group with -x in two sessions: the hint files first (pytest would merge
    them into the directory's order if given with it), then the rest of tests/."""
    base = [sys.executable, "-m", "pytest", "-m", "not slow", "-x", "-q",
            "-p", "no:cacheprovider"]
    if not hint:
        return [[*base, "tests"]]
    return [[*base, *hint], [*base, *(f"--ignore={h}" for h in hint), "tests"]]


def run_mutant(m: Mutant, base: Path, files: list[Path], timeout: float, keep: bool
               ) -> dict[str, Any]:
    """Copy ``files`` of the snapshot ``base``, mutate, run the quick group; the row."""
    row: dict[str, Any] = {"id": m.id, "area": m.area, "change": m.what, "old": m.old,
                           "new": m.new, "equivalent": m.equivalent, "test": "",
                           "seconds": 0.0}
    t0 = time.monotonic()
    copy = make_copy(base, files)
    try:
        hits, count = locate(copy, m.old) if m.old else ([], 0)
        row["file"] = str(hits[0].relative_to(copy)) if count == 1 else ""
        why = apply(copy, m)
        if why is not None:
            row.update(status="stale", count=count, detail=why)
            return row
        env = dict(os.environ)
        env.pop("ROTORTD_FMU", None)
        env["PYTHONPATH"] = str(copy / "fmu_src")
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        for cmd in pytest_commands(m.hint):
            try:
                proc = subprocess.run(cmd, cwd=copy, env=env, text=True, capture_output=True,
                                      timeout=max(1.0, timeout - (time.monotonic() - t0)))
            except subprocess.TimeoutExpired:
                row.update(status="timeout", detail=f"quick group over {timeout:g} s")
                return row
            out = proc.stdout + proc.stderr
            failed = _FAILED.search(out)
            if proc.returncode in (0, 5):  # passed, or nothing left to run (5)
                row["status"] = "survived"
                continue
            if proc.returncode == 1 and failed:
                row.update(status="killed", test=failed.group(2))
            else:
                row.update(status="error", detail=f"pytest rc={proc.returncode}: {out[-1500:]}")
            break
        return row
    finally:
        row["seconds"] = round(time.monotonic() - t0, 1)
        if keep:
            row["copy"] = str(copy)
        else:
            shutil.rmtree(copy, ignore_errors=True)


# ---------------------------------------------------------------------------- table
def table(rows: list[dict[str, Any]]) -> str:
    """The markdown table of the results."""
    lines = ["| id | area | change | result | killing test | s |", "|---|---|---|---|---|---|"]
    for r in rows:
        result = r.get("status", "not run")
        note = NOTES.get(r["id"], "")
        if result == "survived" and r.get("equivalent"):
            result = f"survived, equivalent: {r['equivalent']}"
        elif result == "survived" and note:
            result = f"survived; {note}"
        elif result == "stale":
            result = f"stale ({r.get('detail', '')})"
        lines.append(f"| {r['id']} | {r['area']} | {r['change']} | {result} | "
                     f"{r.get('test') and '`' + r['test'] + '`'} | {r.get('seconds', '')} |")
    return "\n".join(lines)


def summary(doc: dict[str, Any]) -> str:
    """One line: the counts of each result and the run's time."""
    rows = doc.get("mutants", [])
    counts = {k: sum(r.get("status") == k for r in rows)
              for k in ("killed", "survived", "stale", "timeout", "error")}
    equiv = sum(r.get("status") == "survived" and bool(r.get("equivalent")) for r in rows)
    parts = [f"{n} {k}" for k, n in counts.items() if n]
    line = f"{len(rows)} mutants: {', '.join(parts)}"
    if counts["survived"]:
        line += f" ({equiv} of the survivors shown equivalent)"
    if "full_run_seconds" in doc:
        line += (f". Full run: {doc['full_run_seconds'] / 60:.0f} min wall time with "
                 f"--jobs {doc.get('full_run_jobs', doc.get('jobs', 1))}")
    return line + "."


def write_docs(json_path: Path, page: Path) -> None:
    """Put the table of ``json_path`` into the ``mutants`` block of ``page``."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from mdblock import replace_block

    doc = json.loads(json_path.read_text(encoding="utf-8"))
    replace_block(page, "mutants", summary(doc) + "\n\n" + table(doc.get("mutants", [])))


def list_table(mutants: tuple[Mutant, ...]) -> str:
    """Each mutant and where its snippet applies in the working tree (no run)."""
    lines = []
    for m in mutants:
        hits, count = locate(ROOT, m.old) if m.old else ([], 0)
        where = (str(hits[0].relative_to(ROOT)) if count == 1
                 else f"STALE: snippet found {count} times")
        lines.append(f"{m.id:4} {m.area:22} {where:34} {m.what}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", default="", help="comma-separated mutant ids")
    ap.add_argument("--list", action="store_true", help="list the mutants, run nothing")
    ap.add_argument("--jobs", type=int, default=1, help="mutants run at once (default 1)")
    ap.add_argument("--timeout", type=float, default=1800.0,
                    help="seconds for one mutant's quick group (default 1800)")
    ap.add_argument("--json", type=Path, default=DEFAULT_JSON, help="where to write results")
    ap.add_argument("--keep", action="store_true", help="keep the temporary copies")
    ap.add_argument("--docs", action="store_true",
                    help="only rewrite the table of docs/mutants.md from the json")
    args = ap.parse_args(argv)
    if args.docs:
        write_docs(args.json, ROOT / "docs" / "mutants.md")
        return 0
    mutants = MUTANTS
    if args.only:
        wanted = [s.strip() for s in args.only.split(",") if s.strip()]
        unknown = set(wanted) - {m.id for m in mutants}
        if unknown:
            ap.error(f"unknown mutant id(s): {', '.join(sorted(unknown))}")
        mutants = tuple(m for m in mutants if m.id in wanted)
    if args.list:
        print(list_table(mutants))
        return 0
    t0 = time.monotonic()
    tree = source_files(ROOT)
    base = make_copy(ROOT, tree, git=False)  # one snapshot: edits during the run do not leak
    files = [base / f.relative_to(ROOT) for f in tree]
    try:
        with ThreadPoolExecutor(max(1, args.jobs)) as pool:
            futures = [pool.submit(run_mutant, m, base, files, args.timeout, args.keep)
                       for m in mutants]
            rows = []
            for fut in futures:
                row = fut.result()
                rows.append(row)
                print(f"{row['id']}: {row['status']} {row.get('test', '')} "
                      f"({row['seconds']} s)", flush=True)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    wall = round(time.monotonic() - t0, 1)
    previous: dict[str, Any] = {}
    if args.only and args.json.exists():
        previous = json.loads(args.json.read_text(encoding="utf-8"))
    by_id = {r["id"]: r for r in previous.get("mutants", [])}
    by_id.update({r["id"]: r for r in rows})
    order = [m.id for m in MUTANTS]
    all_rows = [by_id[i] for i in order if i in by_id]
    doc = {"command": "python docs/scripts/mutants.py" + (f" --only {args.only}"
                                                           if args.only else ""),
           "wall_seconds": wall, "jobs": args.jobs, "mutants": all_rows}
    if not args.only:
        doc["full_run_seconds"], doc["full_run_jobs"] = wall, args.jobs
    elif "full_run_seconds" in previous:  # (a partial run keeps the full run's figures)
        doc["full_run_seconds"] = previous["full_run_seconds"]
        doc["full_run_jobs"] = previous.get("full_run_jobs", previous.get("jobs", 1))
    args.json.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    print(table(rows))
    print(f"{len(rows)} mutants in {wall} s wall time "
          f"({sum(r['status'] == 'killed' for r in rows)} killed, "
          f"{sum(r['status'] == 'survived' for r in rows)} survived)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
