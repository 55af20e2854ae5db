"""The step: the one step loop (``simulator.TouchdownCore._segments``), the held-spin core
(``simulator``, with its flight and contact segments chosen in ``flight_step`` and
``contact_step``), the spin-state segment choices (``spin_step``, bound by the one core when J is finite; ``SpinCore`` is the core with J required), what a step reports (``report``)
and the state record by component (``state``). Frame and units: inertial, SI."""
