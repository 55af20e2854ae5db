"""The one root finder of the core: regula falsi with the Illinois modification.

Frame and units: whatever the caller's function has (a local time in s, in every use).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

ROOT_ITERS = 60
"""Most evaluations of an event location by ``illinois`` in the contact segments (bisection
where the iteration stalls reaches 4 ulp in at most 53). With at most 9 columns of
extrapolation, 18 + ... + 2 = 90 right-hand sides, one location costs at most
60 (2 * 90 + 16) = 11,760 units (gbs.RHS_WORK, gbs.STEP_WORK)."""


def illinois(at: Callable[[float], tuple[float, Any]], a: float, fa: float, b: float,
             fb: float, yb: Any, narrow: Callable[[float, float, float], bool],
             max_iter: int, level: float = 0.0) -> tuple[float, float, Any]:
    """The crossing of ``level`` by f in (a, b]: f(a) > level >= f(b) (above the level
    before the event, at or below it from the event on). ``at(x)`` returns (f(x), payload);
    ``yb`` is the payload of b. Each iteration takes the secant point of f - level over the
    bracket (the midpoint where the secant leaves it) and keeps the sign change; an end kept
    twice in a row has its value halved (Illinois), so the convergence is superlinear and
    never one-sided. Stops when ``narrow(a, b, g)`` (g: f(b) - level, halved as the
    iteration halves it) or after max_iter evaluations (the work bound: each evaluation's
    work is the caller's, counted in ``at``). Returns (a, b, the payload of b): b is at or
    past the crossing, a before it.

    The secant is taken of f - level, not of f: with f(a) and f(b) both above 0 near the
    crossing of a positive level, the secant of f left the bracket and every iteration fell
    back to the midpoint (28 evaluations per event of the held sliding, found on a fuzz
    case). With level = 0 the values are f's own, bit for bit."""
    side = 0
    fa, fb = fa - level, fb - level  # (x - y > 0 exactly when x > y, gradual underflow)
    for _ in range(max_iter):
        if narrow(a, b, fb):
            break
        x = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not a < x < b:
            x = 0.5 * (a + b)
        fx, yx = at(x)
        fx -= level
        if fx > 0.0:
            a, fa = x, fx
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb, yb = x, fx, yx
            if side == 1:
                fa *= 0.5
            side = 1
    return a, b, yb
