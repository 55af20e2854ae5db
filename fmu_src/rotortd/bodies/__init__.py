"""The bodies: the rotor (``rotor.RigidRotor``: mass, polar inertia, imbalance, radius; the
spin held is its J = inf case) and the touchdown bearing it meets (``bearing``: the
counter-body protocol and the chapter's fixed rigid race). Frame and units: inertial, SI."""
