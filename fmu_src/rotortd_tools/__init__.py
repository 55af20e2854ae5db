"""Offline tools for the RotorTouchdown FMU (plots). Uses numpy/matplotlib; never imported by
the FMU itself."""
