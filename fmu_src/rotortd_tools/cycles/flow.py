"""The scaled free flow (docs/model.md §1): system matrix, closed-form flight and its gamma
derivative.

Scaled co-rotating frame: t = Omega tau, U = z e^{-i psi}/c_r (in c_r), U' = dU/dt (in c_r
Omega); w = (U, U') obeys w' = A w + b. Independent of the core (numpy/scipy).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.optimize
from rotortd import ScaledParams
from rotortd.scaled import regular_equilibrium


def system_matrix(sp: ScaledParams) -> np.ndarray:
    """A of w' = A w + b, w = (U, U') (complex 2x2, scaled co-rotating)."""
    return np.array(
        [[0.0, 1.0], [1.0 - sp.omega**2 - 1j * sp.gamma, -sp.gamma - 2j]], dtype=complex
    )



class ScaledFlow:
    """Closed-form free flight in the scaled co-rotating frame (independent of the core).

    w(t) = e^{A t} (w0 - w_eq) + w_eq, w_eq = (U*, 0); also the derivative of w(t) with
    respect to gamma (through A and U*), from the block exponential
    exp([[A, dA], [0, A]] t) whose upper-right block is d/dgamma e^{A t}.
    """

    def __init__(self, sp: ScaledParams) -> None:
        self.sp = sp
        self.A = system_matrix(sp)
        self.U_eq = regular_equilibrium(sp)
        self.w_eq = np.array([self.U_eq, 0.0], dtype=complex)
        self.dA = np.array([[0.0, 0.0], [-1j, -1.0]], dtype=complex)  # dA/dgamma
        den = complex(sp.omega**2 - 1.0, sp.gamma)
        self.dw_eq = np.array([-1j * self.U_eq / den, 0.0], dtype=complex)  # dw_eq/dgamma

    def expA(self, t: float) -> np.ndarray:
        """e^{A t} (complex 2x2)."""
        return scipy.linalg.expm(self.A * t)

    def state(self, w0: np.ndarray, t: float) -> np.ndarray:
        """w(t) from w0 = (U0, U0') after a free flight of scaled time t."""
        return self.expA(t) @ (w0 - self.w_eq) + self.w_eq

    def states(self, w0: np.ndarray, ts: np.ndarray) -> np.ndarray:
        """w at many times (shape (len(ts), 2)), by the eigen-decomposition of A."""
        lam, V = np.linalg.eig(self.A)
        c = np.linalg.solve(V, w0 - self.w_eq)
        modes = np.exp(np.outer(ts, lam)) * c
        return modes @ V.T + self.w_eq

    def rate(self, w: np.ndarray) -> np.ndarray:
        """w' = A w + b = A (w - w_eq)."""
        return self.A @ (w - self.w_eq)

    def dgamma(self, w0: np.ndarray, t: float) -> np.ndarray:
        """d w(t)/d gamma at fixed w0 and t."""
        n = 2
        M = np.zeros((2 * n, 2 * n), dtype=complex)
        M[:n, :n] = self.A * t
        M[n:, n:] = self.A * t
        M[:n, n:] = self.dA * t
        E = scipy.linalg.expm(M)
        eA, deA = E[:n, :n], E[:n, n:]
        return deA @ (w0 - self.w_eq) + (np.eye(n) - eA) @ self.dw_eq


def real_jac(C: np.ndarray) -> np.ndarray:
    """Real 4x4 matrix of the complex-linear map dw -> C dw on (Re U, Im U, Re U', Im U')."""
    n = C.shape[0]
    R = np.zeros((2 * n, 2 * n))
    for i in range(n):
        for j in range(n):
            c = C[i, j]
            R[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = [[c.real, -c.imag], [c.imag, c.real]]
    return R


def to_real(w: np.ndarray) -> np.ndarray:
    """(U, U') complex -> (Re U, Im U, Re U', Im U')."""
    return np.array([w[0].real, w[0].imag, w[1].real, w[1].imag])
