"""The step: the one step loop (``simulator.TouchdownCore._segments``), the held-spin core
(``simulator``, with its flight and contact segments chosen in ``flight_step`` and
``contact_step``), the spin-state core (``spin_core``), what a step reports (``report``)
and the state record by component (``state``). Frame and units: inertial, SI."""
