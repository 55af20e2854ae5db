"""Run the FMU once through ``fmpy.simulate_fmu`` in its own process (validation runs).

    python tests/validation_runner.py '{"fmu": ..., "stop_time": ..., "output_interval": ...,
        "start_values": {...}, "output": [...], "input_file": null | path, "out": path}'

Writes the result with ``fmpy.util.write_csv`` and leaves with ``os._exit(0)`` so that a
crash in the FMU (or PythonFMU's heap corruption at interpreter exit) cannot take the caller
down; the caller checks the file and the final time. The same pattern as tests/fmu_scenarios.py.
"""

from __future__ import annotations

import json
import os
import sys
import traceback


def main() -> None:
    """Parse the JSON spec, simulate, write the CSV, exit without interpreter teardown."""
    from fmpy import simulate_fmu
    from fmpy.util import read_csv, write_csv

    spec = json.loads(sys.argv[1])
    rc = 0
    try:
        inp = read_csv(spec["input_file"]) if spec.get("input_file") else None
        res = simulate_fmu(spec["fmu"], stop_time=spec["stop_time"],
                           output_interval=spec["output_interval"],
                           start_values=spec["start_values"], output=spec["output"], input=inp)
        write_csv(spec["out"], res)
    except Exception:
        traceback.print_exc()
        rc = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(rc)


if __name__ == "__main__":
    main()
