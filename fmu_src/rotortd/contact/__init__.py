"""The contact: the pair of bodies (``pair.ContactPair``: gap, normal, relative velocity,
slip, Delassus matrix), the impact laws (``impact``: the held-spin reset law, a declared
accelerator of the pair's law in ``rotortd.bodies.rotor``), the rigorous contact search of a
free flight (``search``, with the step's work units) and the wall's forces under held inputs
(``wall``). Frame and units: inertial, SI."""
