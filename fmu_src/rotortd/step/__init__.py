"""The step: the one core and its one step loop (``simulator.TouchdownCore``, ``_segments``),
the segment choices of the held spin (``flight_step``, ``contact_step``: the declared
accelerators) and of the spin as a state (``spin_step``, bound by the core when J is
finite; ``SpinCore`` is the core with J required), what a step reports (``report``) and
the state record by component (``state``). Frame and units: inertial, SI."""
