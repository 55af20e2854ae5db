"""rotortd_cosim: system-level co-simulation of the RotorTouchdown FMU with a drivetrain.

Scenes (:mod:`.scenes`), SSP files (:mod:`.ssp`), engine runners for FMPy's SSP master,
libcosimpy, ecospy and the native ``ecos`` CLI plus an in-process Jacobi master for the
coupling study (:mod:`.engines`), and ``python -m rotortd_cosim.run`` to run one engine in
its own process. Offline tooling (numpy, fmpy): never shipped inside an FMU.
"""
