"""Drivetrain of the rotor: ``J Omega' = T_motor - b Omega + T_bearing`` (SI units).

The motor is either a torque input held over the step (``MOTOR_TORQUE``) or a PI speed
controller ``u = Kp (Omega_set - Omega) + Ki I``, ``I' = Omega_set - Omega`` with the torque
limited to ``|T_motor| <= T_max`` (``MOTOR_PI``). Anti-windup: the integrator is frozen
while the controller saturates; on the limit where a frozen integrator would leave the
limit but a running one would push back (a Filippov sliding segment) the integrator follows
the limit, ``Kp e + Ki I = +-T_max``.

For inputs held over a step every regime is a linear ODE with constant coefficients and is
advanced in closed form; regime switches (the limit reached or left) are located by
bisection on the closed form, so a step is exact to round-off. ``psi`` is the spin angle.
Units: Omega rad/s, psi rad, I rad, torques N m, J kg m^2, b N m s/rad, Kp N m s/rad,
Ki N m/rad, impulses N m s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

MOTOR_TORQUE = 0
MOTOR_PI = 1

LIN, SAT, SLIDE = 0, 1, 2          # PI regimes: linear, saturated (I frozen), sliding on limit
_MAX_SEGMENTS = 64                 # switches per step before the rest is done without events


class DriveError(ValueError):
    """An invalid drivetrain parameter or input (the message names it)."""


@dataclass(frozen=True)
class DriveParams:
    """Drivetrain parameters (SI). Defaults: J = m R^2/2 of the chapter's rotor."""

    J: float = 0.04            # polar inertia [kg m^2], > 0
    b: float = 1e-4            # viscous drag [N m s/rad], >= 0
    motor: int = MOTOR_TORQUE  # MOTOR_TORQUE or MOTOR_PI
    Kp: float = 0.2            # PI proportional gain [N m s/rad], >= 0
    Ki: float = 2.0            # PI integral gain [N m/rad], >= 0
    T_max: float = 5.0         # PI torque limit [N m], > 0

    def validate(self) -> DriveParams:
        """Return self, or raise DriveError naming the bad field."""
        checks = (("J", self.J > 0), ("b", self.b >= 0), ("Kp", self.Kp >= 0),
                  ("Ki", self.Ki >= 0), ("T_max", self.T_max > 0))
        for name, ok in checks:
            value = getattr(self, name)
            if not (math.isfinite(value) and ok):
                raise DriveError(f"{name}={value!r} out of range")
        if self.motor not in (MOTOR_TORQUE, MOTOR_PI):
            raise DriveError(f"motor={self.motor!r} must be 0 (torque) or 1 (PI)")
        return self

    def replace(self, **changes: float) -> DriveParams:
        """Validated copy with some fields changed."""
        return replace(self, **changes).validate()


@dataclass
class DriveReport:
    """Step averages over one step [N m] and the regime at its end."""

    T_motor: float = 0.0    # motor torque, averaged
    T_drag: float = 0.0     # drag torque -b Omega, averaged (< 0 for Omega > 0)
    regime: int = LIN       # PI regime at the end (LIN for the torque motor)
    segments: int = 1       # closed-form segments used


def _phi1(x: float) -> float:
    """(e^x - 1)/x, stable near 0."""
    return math.expm1(x) / x if abs(x) > 1e-5 else 1.0 + x / 2 + x * x / 6


def _phi2(x: float) -> float:
    """(e^x - 1 - x)/x^2, stable near 0."""
    if abs(x) > 1e-3:
        return (math.expm1(x) - x) / (x * x)
    return 0.5 + x / 6 + x * x / 24 + x ** 3 / 120


def _ch_sh(x2: float) -> tuple[float, float]:
    """cosh(sqrt(x2)) and sinh(sqrt(x2))/sqrt(x2) for real x2 of either sign."""
    if abs(x2) < 1e-8:
        return 1.0 + x2 / 2 + x2 * x2 / 24, 1.0 + x2 / 6 + x2 * x2 / 120
    if x2 > 0:
        r = math.sqrt(x2)
        return math.cosh(r), math.sinh(r) / r
    r = math.sqrt(-x2)
    return math.cos(r), math.sin(r) / r


def first_root(f: object, h: float, n: int = 16) -> float | None:
    """First tau in (0, h] where the continuous f(tau) changes sign from f(0+) (bisection
    on samples h/n apart; assumes at most one sign change between samples)."""
    f0 = f(0.0)  # type: ignore[operator]
    a = 0.0
    for k in range(1, n + 1):
        b = h * k / n
        fb = f(b)  # type: ignore[operator]
        if (fb > 0) != (f0 > 0) or fb == 0.0:
            for _ in range(200):
                mid = 0.5 * (a + b)
                if mid <= a or mid >= b:
                    break
                if (f(mid) > 0) == (f0 > 0) and f(mid) != 0.0:  # type: ignore[operator]
                    a = mid
                else:
                    b = mid
            return b
        a = b
    return None


class DriveCore:
    """Exact stepping of the drivetrain for inputs held over a step.

    State: t [s], Omega [rad/s], psi [rad, unwrapped], I [rad] (PI integral of the speed
    error), regime. Cumulative angular impulses [N m s]: H_motor, H_drag, H_bearing, with
    J (Omega - Omega0) = H_motor + H_drag + H_bearing to round-off.
    """

    def __init__(self, params: DriveParams, Omega0: float, psi0: float = 0.0,
                 I0: float = 0.0, t0: float = 0.0) -> None:
        self.params = params.validate()
        self.t, self.Omega, self.psi, self.I = float(t0), float(Omega0), float(psi0), float(I0)
        self.Omega0 = float(Omega0)
        self.H_motor = self.H_drag = self.H_bearing = 0.0
        self.regime = LIN

    # ------------------------------------------------------------------ public
    def step(self, h: float, T_bearing: float = 0.0, T_in: float = 0.0,
             Omega_set: float = 0.0, hold_speed: bool = False) -> DriveReport:
        """Advance by h [s] with T_bearing, T_in (torque motor) and Omega_set held.

        hold_speed: Omega is not integrated (the spin lives elsewhere, e.g. in the bearing
        FMU); the motor and drag torques are evaluated at the held Omega."""
        for name, v in (("h", h), ("T_bearing", T_bearing), ("T_in", T_in),
                        ("Omega_set", Omega_set)):
            if not math.isfinite(v):
                raise DriveError(f"{name}={v!r} is not finite")
        if not h > 0:
            raise DriveError(f"step size h={h!r} must be > 0")
        p = self.params
        if p.motor == MOTOR_TORQUE:
            H_m, H_int, segs = T_in * h, self._torque_segment(h, T_in + T_bearing, hold_speed), 1
            self.regime = LIN
        else:
            H_m, H_int, segs = self._pi_step(h, T_bearing, Omega_set, hold_speed)
        H_d = -p.b * H_int
        self.H_motor += H_m
        self.H_drag += H_d
        self.H_bearing += T_bearing * h
        self.t += h
        return DriveReport(T_motor=H_m / h, T_drag=H_d / h, regime=self.regime, segments=segs)

    def pi_output(self, Omega_set: float) -> float:
        """The unlimited controller output u = Kp e + Ki I [N m] at the current state."""
        return self.params.Kp * (Omega_set - self.Omega) + self.params.Ki * self.I

    def get_state(self) -> dict[str, float]:
        """JSON-able state (schema rotortd-drive-state)."""
        return {"schema": "rotortd-drive-state", "t": self.t, "Omega": self.Omega,
                "psi": self.psi, "I": self.I, "Omega0": self.Omega0,
                "H_motor": self.H_motor, "H_drag": self.H_drag,
                "H_bearing": self.H_bearing, "regime": self.regime}

    def set_state(self, s: dict[str, float]) -> None:
        """Restore a get_state() dict."""
        if s.get("schema") != "rotortd-drive-state":
            raise DriveError("not a rotortd-drive-state")
        for key in ("t", "Omega", "psi", "I", "Omega0", "H_motor", "H_drag", "H_bearing"):
            setattr(self, key, float(s[key]))
        self.regime = int(s["regime"])

    # ------------------------------------------------------------------ closed forms
    def _omega_const_torque(self, tau: float, T: float, hold: bool) -> tuple[float, float]:
        """Omega(tau) and its integral [rad] under a constant torque T (N m) and drag."""
        if hold:
            return self.Omega, self.Omega * tau
        p = self.params
        x = -p.b / p.J * tau
        w = self.Omega * math.exp(x) + T / p.J * tau * _phi1(x)
        return w, self.Omega * tau * _phi1(x) + T / p.J * tau * tau * _phi2(x)

    def _torque_segment(self, tau: float, T: float, hold: bool) -> float:
        """Advance under constant motor + bearing torque T; returns the integral of Omega."""
        w, integ = self._omega_const_torque(tau, T, hold)
        self.Omega, self.psi = w, self.psi + integ
        return integ

    def _pi_linear(self, tau: float, T_b: float, ws: float, hold: bool
                   ) -> tuple[float, float, float]:
        """Unsaturated PI: (Omega, I, integral of Omega) at tau."""
        p = self.params
        w0, i0 = self.Omega, self.I
        if hold:
            e = ws - w0
            return w0, i0 + e * tau, w0 * tau
        if p.Ki == 0.0:
            w, integ = _p_only(w0, p, T_b, ws, tau)
            return w, i0 + ws * tau - integ, integ
        i_eq = (p.b * ws - T_b) / p.Ki
        y0, y1 = w0 - ws, i0 - i_eq
        a11, a12, a21 = -(p.Kp + p.b) / p.J, p.Ki / p.J, -1.0
        s = a11 / 2
        q2 = s * s - p.Ki / p.J
        ch, sh = _ch_sh(q2 * tau * tau)
        es = math.exp(s * tau)
        sh *= tau
        w = ws + es * (ch * y0 + sh * ((a11 - s) * y0 + a12 * y1))
        i = i_eq + es * (ch * y1 + sh * (a21 * y0 - s * y1))
        return w, i, ws * tau - (i - i0)

    # ------------------------------------------------------------------ PI regimes
    def _pi_step(self, h: float, T_b: float, ws: float, hold: bool) -> tuple[float, float, int]:
        """Piecewise-exact PI step; returns (motor impulse, integral of Omega, segments)."""
        H_m = H_int = 0.0
        left, segs = h, 0
        self.regime = self._decide(T_b, ws, hold)
        while left > 0.0:
            segs += 1
            tau = left if segs > _MAX_SEGMENTS else self._event(left, T_b, ws, hold)
            dH_m, dI = self._advance(tau, T_b, ws, hold)
            H_m, H_int, left = H_m + dH_m, H_int + dI, left - tau
            if left <= 1e-15 * h:
                break
            self.regime = self._decide(T_b, ws, hold)
        return H_m, H_int, segs

    def _limit_sign(self, ws: float) -> float:
        u = self.pi_output(ws)
        return 1.0 if u >= 0 else -1.0

    def _decide(self, T_b: float, ws: float, hold: bool) -> int:
        """Regime at the current state; on the limit from the outward derivatives of u
        with the integrator running (o_lin) and frozen (o_sat)."""
        p = self.params
        u = self.pi_output(ws)
        tol = 1e-12 * p.T_max
        if abs(u) < p.T_max - tol:
            return LIN
        if abs(u) > p.T_max + tol:
            return SAT
        sig = self._limit_sign(ws)
        dw = 0.0 if hold else (sig * p.T_max - p.b * self.Omega + T_b) / p.J
        e = ws - self.Omega
        o_sat = sig * (-p.Kp * dw)
        o_lin = o_sat + sig * p.Ki * e
        scale = 1e-9 * (p.Kp * abs(dw) + p.Ki * abs(e)) + 1e-300
        if o_lin <= scale:
            return LIN
        return SAT if o_sat >= 0.0 else SLIDE

    def _state_at(self, tau: float, T_b: float, ws: float, hold: bool,
                  regime: int) -> tuple[float, float, float, float]:
        """(Omega, I, integral of Omega, motor impulse) after tau in a regime."""
        p = self.params
        if regime == LIN:
            w, i, integ = self._pi_linear(tau, T_b, ws, hold)
            if hold:   # u(tau) = Kp e + Ki (I0 + e tau), e constant
                e = ws - w
                H_m = p.Kp * e * tau + p.Ki * (self.I * tau + 0.5 * e * tau * tau)
            else:      # from J dOmega = H_m - b int Omega + T_b tau (exact algebra)
                H_m = p.J * (w - self.Omega) + p.b * integ - T_b * tau
            return w, i, integ, H_m
        sig = self._limit_sign(ws)
        T_m = sig * p.T_max
        w, integ = self._omega_const_torque(tau, T_m + T_b, hold)
        i = self.I if regime == SAT or p.Ki == 0 else (T_m - p.Kp * (ws - w)) / p.Ki
        return w, i, integ, T_m * tau

    def _event(self, left: float, T_b: float, ws: float, hold: bool) -> float:
        """Length of the current regime's segment within `left` (next switch or left)."""
        p = self.params
        regime, sig = self.regime, self._limit_sign(ws)
        if regime == LIN:
            def f(tau: float) -> float:
                w, i, _, _ = self._state_at(tau, T_b, ws, hold, LIN)
                return abs(p.Kp * (ws - w) + p.Ki * i) - p.T_max
        elif regime == SAT:
            def f(tau: float) -> float:
                w, _, _, _ = self._state_at(tau, T_b, ws, hold, SAT)
                return sig * (p.Kp * (ws - w) + p.Ki * self.I) - p.T_max
        else:
            def f(tau: float) -> float:
                w, _, _, _ = self._state_at(tau, T_b, ws, hold, SLIDE)
                dw = 0.0 if hold else (sig * p.T_max - p.b * w + T_b) / p.J
                return sig * (p.Ki * (ws - w) - p.Kp * dw)
        n = 16 if regime != LIN else max(16, math.ceil(8 * left * math.sqrt(
            p.Ki / p.J + ((p.Kp + p.b) / p.J) ** 2)))
        root = first_root(f, left, n)
        return left if root is None or root <= 0.0 else min(root, left)

    def _advance(self, tau: float, T_b: float, ws: float, hold: bool) -> tuple[float, float]:
        """Move the state by tau in the current regime; returns (motor impulse, int Omega)."""
        w, i, integ, H_m = self._state_at(tau, T_b, ws, hold, self.regime)
        self.Omega, self.I, self.psi = w, i, self.psi + integ
        return H_m, integ


def _p_only(w0: float, p: DriveParams, T_b: float, ws: float, tau: float
            ) -> tuple[float, float]:
    """P control (Ki = 0): Omega(tau) and its integral."""
    lam = (p.Kp + p.b) / p.J
    T = (p.Kp * ws + T_b) / p.J
    x = -lam * tau
    return (w0 * math.exp(x) + T * tau * _phi1(x),
            w0 * tau * _phi1(x) + T * tau * tau * _phi2(x))


def held_speed_report(params: DriveParams, Omega: float, h: float, T_in: float = 0.0,
                      Omega_set: float = 0.0, I0: float = 0.0) -> tuple[DriveReport, float]:
    """Motor and drag torques averaged over h at a held speed (stateless helper);
    returns (report, I at the end)."""
    core = DriveCore(params, Omega, I0=I0)
    rep = core.step(h, 0.0, T_in, Omega_set, hold_speed=True)
    return rep, core.I
