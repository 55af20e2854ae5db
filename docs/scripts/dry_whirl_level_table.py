"""The dry whirl orbit's integrand as a function of the energy level: how many terms.

    python docs/scripts/dry_whirl_level_table.py     # a second

docs/notes/dry-whirl-quadrature.md §10 (issue 26 item 1 with a held drive torque, not built):
with T_drive held the level K = 2 (E + T_drive psi) moves every step, and the orbit's
integrand F = sqrt(I_P(beta) / (K - 2 V(theta, psi))) (V the periodic part of the
potential, theta = psi + phi - beta) is expanded in 2V/K,

    F = sqrt(I_P / K) sum_k b_k (2V/K)^k,   b_k = C(2k, k) / 4^k,

so that each harmonic of the orbit is c_jl(K) = sum_k a_jlk K^(-1/2-k) with a_jlk fixed by
the rotor and the held inputs. For the chapter's rotor (g = 9.81, J = m R^2/2, bearing off,
no F_ext) rolling at Omega, with K = I0 Omega^2: eps = max|2V|/K, the orders k with a term
above 1e-16 |F_00|, the number of such terms (the table a_jlk) against F's own, and the
largest error of the summed expansion against F, relative to |F_00|. DFTs on a 48 x 48 grid
of (beta, psi) (numpy: a script, not the core).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "fmu_src"))

from rotortd import RotorParams

N, TRIM, SPEEDS = 48, 1e-16, (60.0, 200.0, 2000.0)


def main() -> int:
    p = RotorParams(g=9.81)
    J = 0.5 * p.m * p.R ** 2
    I0, c2 = J + p.m * (p.R ** 2 + p.e_c ** 2), 2.0 * p.m * p.R * p.e_c
    grid = 2.0 * np.pi * np.arange(N) / N
    beta, psi = np.meshgrid(grid, grid, indexing="ij")
    theta = psi + p.phi - beta
    G = -p.m * p.g  # the weight, along -y (N)
    V = -p.c_r * G * np.sin(theta) + p.m * p.g * p.e_c * np.sin(psi + p.phi)
    IP = I0 - c2 * np.cos(beta)
    print("Omega (rad/s)   eps       orders  table terms  F's terms  error/|F00|")
    for W in SPEEDS:
        K = I0 * W * W
        F = np.sqrt(IP / (K - 2.0 * V))
        f00 = abs(np.fft.fft2(F)[0, 0]) / N ** 2
        total, k_max, summed = 0, 0, np.zeros_like(F)
        for k in range(40):
            term = np.sqrt(IP / K) * math.comb(2 * k, k) / 4 ** k * (2.0 * V / K) ** k
            n = int(np.sum(np.abs(np.fft.fft2(term)) / N ** 2 > TRIM * f00))
            if n == 0:
                break
            total, k_max, summed = total + n, k, summed + term
        own = int(np.sum(np.abs(np.fft.fft2(F)) / N ** 2 > TRIM * f00))
        err = np.max(np.abs(summed - F)) / f00
        print(f"{W:13g}  {np.max(np.abs(2.0 * V)) / K:8.2e}  0-{k_max:<5d} {total:11d}"
              f"  {own:9d}  {err:.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
