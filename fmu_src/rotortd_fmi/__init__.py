"""The PythonFMU adapters of the project's FMUs (FMI plumbing only; physics in rotortd).

``touchdown`` (RotorTouchdown, over ``rotortd``), ``drivetrain`` (Drivetrain, over
``rotortd_drive``) and ``events`` (TouchdownEvents, standard library); ``guard`` holds the
error guard the first two share. The FMU scripts in
fmu_src/ subclass these in a few lines: PythonFMU 0.7 compiles an FMU's script on every
fmi2Instantiate, while this package is compiled once per process. Importing the package
imports none of the three modules.
"""
