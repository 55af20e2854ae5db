"""Gragg–Bulirsch–Stoer extrapolation for small smooth ODE systems, pure Python.

Used for the sliding phase (contact.py), where a tolerance of 1e-13 relative is wanted:
extrapolation of the modified midpoint rule reaches order 2k with k columns, so steps stay
long at tight tolerances, and it shares no coefficients with the validation integrators
(scipy's DOP853 and mpmath's Taylor method).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

Vector = list[float]
Rhs = Callable[[float, Sequence[float]], Vector]
Sweep = Callable[[float, Sequence[float], Sequence[float], float, int], Vector]
"""A modified-midpoint sweep (u0, y0, f0, H, n) -> y(u0 + H): ``midpoint`` with its right-hand
side bound, or a caller's fused copy of it (contact.Sliding.midpoint_sweep)."""

RHS_WORK = 2
"""Work units per right-hand side of an extrapolated contact integrator (the held sliding,
the contact segments with the spin a state): a right-hand side costs about 2.2 us, two
units of about 1.1 us (measured on the held sliding and the spin state's rolling;
docs/model.md 7)."""
STEP_WORK = 16
"""Work units per extrapolated step beyond its right-hand sides: the tableau, error norm,
event test and step control (about 100 us at 9 columns, less at fewer)."""

SEQUENCE = (2, 4, 6, 8, 10, 12, 14, 16, 18)
"""Substep counts of the modified midpoint rule (the 'double harmonic' sequence)."""


def midpoint(
    rhs: Rhs, u0: float, y0: Sequence[float], f0: Sequence[float], H: float, n: int
) -> Vector:
    """Gragg's modified midpoint rule over [u0, u0 + H] with n substeps, smoothed at the end."""
    h = H / n
    h2 = 2.0 * h  # (a + 2.0 * h * b computes (2.0 * h) * b: once here, the same bits)
    ym = list(y0)
    yc = [a + h * b for a, b in zip(y0, f0)]
    for i in range(1, n):
        f = rhs(u0 + i * h, yc)
        ym, yc = yc, [a + h2 * b for a, b in zip(ym, f)]
    f = rhs(u0 + H, yc)
    return [0.5 * (a + b + h * c) for a, b, c in zip(yc, ym, f)]


def extrapolated_step(
    sweep: Sweep,
    u0: float,
    y0: Sequence[float],
    f0: Sequence[float],
    H: float,
    scale: Sequence[float],
    k_min: int = 3,
    k_max: int = len(SEQUENCE),
    k_fixed: int | None = None,
    aux_scale: Sequence[float] = (),
    aux_evals: list[int] | None = None,
) -> tuple[Vector, float, int, int]:
    """One extrapolated step of length H from (u0, y0) with f0 = y'(u0).

    ``scale[i]`` is the tolerance for component i (components beyond len(scale) are not
    error-controlled). Returns (y, err, k, nfev): err <= 1 means accepted at column k;
    with ``k_fixed`` exactly that many columns are used (for event re-integration).

    ``aux_scale`` gives tolerances of the last len(aux_scale) components (auxiliary
    quadratures) that must not change the others: they take no part in the acceptance or
    in k; once the step is accepted (or with ``k_fixed``), if their own error ratio exceeds
    1, further columns are built (up to k_max) for them alone, and y carries the
    controlled components of column k and the auxiliary ones of the first column where
    their ratio is <= 1 (or of k_max). nfev does not count those further sweeps (so that
    the caller's work count stays what it was without auxiliary components); their
    right-hand sides are added to ``aux_evals[0]`` when given.
    """
    table: list[Vector] = []
    err = float("inf")
    nfev = 0
    k_stop = k_fixed if k_fixed is not None else k_max
    for j in range(k_stop):
        n = SEQUENCE[j]
        extr = [sweep(u0, y0, f0, H, n)]
        nfev += n
        for r, b in zip(_RATIOS[j], table):
            extr.append([x + (x - w) / r for x, w in zip(extr[-1], b)])
        if j >= 1:
            err = _error_ratio(extr[j], extr[j - 1], scale)
            if k_fixed is None and j + 1 >= k_min and err <= 1.0:
                if aux_scale:
                    y = _refine_aux(sweep, u0, y0, f0, H, extr, j, aux_scale, k_max, aux_evals)
                    return y, err, j + 1, nfev
                return extr[j], err, j + 1, nfev
        table = extr
    if aux_scale and k_fixed is not None:
        y = _refine_aux(sweep, u0, y0, f0, H, table, k_stop - 1, aux_scale, k_max, aux_evals)
        return y, err, k_stop, nfev
    return table[-1], err, k_stop, nfev


def _refine_aux(sweep: Sweep, u0: float, y0: Sequence[float], f0: Sequence[float], H: float,
                row: list[Vector], j: int, aux_scale: Sequence[float], k_max: int,
                aux_evals: list[int] | None) -> Vector:
    """extrapolated_step's end with auxiliary components (its docstring): y of the tableau
    row ``row`` of column j (0-based), which was accepted, with its auxiliary components
    refined by further columns until their error ratio is <= 1."""
    na = len(aux_scale)
    y = row[j]
    jj = j
    a_err = _error_ratio(y[-na:], row[j - 1][-na:], aux_scale) if j >= 1 else math.inf
    while not a_err <= 1.0 and jj + 1 < k_max:
        jj += 1
        n = SEQUENCE[jj]
        new = [sweep(u0, y0, f0, H, n)]
        if aux_evals is not None:
            aux_evals[0] += n
        for r, b in zip(_RATIOS[jj], row):
            new.append([x + (x - w) / r for x, w in zip(new[-1], b)])
        a_err = _error_ratio(new[jj][-na:], new[jj - 1][-na:], aux_scale)
        row = new
    if jj > j:
        y = y[:-na] + row[jj][-na:]
    return y


_RATIOS = tuple(
    tuple((SEQUENCE[j] / SEQUENCE[j - col]) ** 2 - 1.0 for col in range(1, j + 1))
    for j in range(len(SEQUENCE))
)
"""Aitken–Neville divisors (n_j / n_{j-col})^2 - 1 of row j, columns 1..j."""


def _error_ratio(a: Sequence[float], b: Sequence[float], scale: Sequence[float]) -> float:
    """max_i |a_i - b_i| / scale_i over the controlled components; NaN once any is NaN."""
    err = 0.0
    for x, w, s in zip(a, b, scale):
        e = abs(x - w) / s
        if e > err or e != e:
            err = e
    return err


def next_step_size(H: float, err: float, k: int) -> float:
    """Step-size proposal after a step with error ratio ``err`` at column ``k`` (order 2k)."""
    if err == 0.0:
        return 4.0 * H
    fac = 0.9 * (0.5 / err) ** (1.0 / (2 * k - 1))
    return H * min(4.0, max(0.2, fac))
