"""Parameter sweeps of the touchdown model on Dask: attractor signatures and regimes.

``rotortd sweep`` (docs/sweeps.md). The modules, by job:

  spec       the grammar: parameter names, ranges, axes, settings, start labels, and what a
             point is (``point_params``: the chapter's set with the named fields replaced;
             ``spin_inputs``: J and T_drive, the spin as a state)
  starts     the initial state of a run (rest, steady, large, cycle[:BRANCH], drop,
             continuation), in a SpinCore when J is given
  signature  run to the attractor (``rotortd_tools.attractor``) and summarise it as a row
  schema     the output columns and their types
  jobs       one run (point, start) as a row, alone or chained from a previous state
  store      the Parquet directory: part files, description, resume
  plan       what remains to run: independent jobs and continuation chains
  execute    serial or Dask execution, ``run_sweep``

Frame and units: parameters are the chapter's scaled set (docs/model.md §1) plus ``Omega`` in
rad/s; times are scaled, t = Omega tau (one revolution is 2 pi); positions in c_r, speeds
in c_r Omega, angles in rad, co-rotating (U = z e^{-i psi}/c_r). The names below are the
package's interface (tests, ``rotortd_tools.cli``, ``sweep_plot``, docs/scripts).
"""

from rotortd_tools.attractor import (
    DROP_OUTCOMES,
    DropRecorder,
    Recorder,
    classify,
    classify_drop,
    detect_period,
    regime_group,
    run_drop,
)
from rotortd_tools.sweep.execute import (
    dask_client,
    run_dask,
    run_serial,
    run_sweep,
    submit_plan,
)
from rotortd_tools.sweep.jobs import Job, base_row, point_key, run_batch, run_job, run_segment
from rotortd_tools.sweep.plan import Plan, all_jobs, batches, chains_of, make_plan
from rotortd_tools.sweep.schema import COLUMNS, DROP_REGIMES, REGIMES, arrow_schema
from rotortd_tools.sweep.signature import signature, simulate, simulate_drop
from rotortd_tools.sweep.spec import (
    ALIASES,
    CONTINUATION,
    CYCLE_BRANCHES,
    DROP_G,
    PARAM_NAMES,
    RANGES,
    SCALED_NAMES,
    SIMPLE_STARTS,
    SPIN_NAMES,
    Axis,
    Settings,
    SweepError,
    SweepSpec,
    canonical_name,
    check_value,
    cycle_finder,
    drop_params,
    parse_axis,
    parse_spec,
    parse_starts,
    point_params,
    spin_inputs,
)
from rotortd_tools.sweep.starts import NoStart, core_for, make_start
from rotortd_tools.sweep.store import (
    FORMAT_VERSION,
    META_FILE,
    ParquetSink,
    part_files,
    prepare_output,
    read_meta,
    read_sweep,
    spec_meta,
)

__all__ = [
    "ALIASES", "COLUMNS", "CONTINUATION", "CYCLE_BRANCHES", "DROP_G", "DROP_OUTCOMES",
    "DROP_REGIMES", "FORMAT_VERSION", "META_FILE", "PARAM_NAMES", "RANGES", "REGIMES",
    "SCALED_NAMES", "SIMPLE_STARTS", "SPIN_NAMES", "Axis", "DropRecorder", "Job",
    "NoStart", "ParquetSink", "Plan", "Recorder", "Settings", "SweepError", "SweepSpec",
    "all_jobs", "arrow_schema", "base_row", "batches", "canonical_name", "chains_of",
    "check_value", "classify", "classify_drop", "core_for", "cycle_finder", "dask_client",
    "detect_period", "drop_params", "make_plan", "make_start", "parse_axis", "parse_spec",
    "parse_starts", "part_files", "point_key", "point_params", "prepare_output",
    "read_meta", "read_sweep", "regime_group", "run_batch", "run_dask", "run_drop",
    "run_job", "run_segment", "run_serial", "run_sweep", "signature", "simulate",
    "simulate_drop", "spec_meta", "spin_inputs", "submit_plan",
]
