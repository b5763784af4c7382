#!/usr/bin/env python3
"""The figure 1.7 integration of bench/evolve-driven-pendulum.sicm, in SciPy.

The periodically driven pendulum (m = 1, l = 1, g = 9.8, pivot at
a cos(omega t) with a = 0.1, omega = 2 sqrt(g)) from theta = 1, thetadot = 0,
t = 0 to 100, by solve_ivp's DOP853 (the same Dormand-Prince 8(5,3) pair as
GSL's rk8pd) at rtol = atol = 1e-12, with the solution sampled every 0.01
(t_eval, 10001 points) as sicm's monitor is called. The right-hand side is
the same equation sicm derives from the Lagrangian, written in NumPy as one
would write it by hand.

Prints the angle at t = 10 and t = 100 (see bench/evolve-driven-pendulum.sicm
on why only the first can agree), the number of samples and right-hand-side
evaluations, and the wall time of the solve_ivp call alone, in the format bench/evolve-vs-scipy reads; the
interpreter's start-up and the imports are in the whole-process time only.
"""
import time

import numpy as np
from scipy.integrate import solve_ivp

M, L, G, A = 1.0, 1.0, 9.8, 0.1
OMEGA = 2.0 * np.sqrt(G)


def rhs(t, y):
    """(theta, thetadot)' for the pendulum on the driven pivot (SICM 1.6.2)."""
    theta, thetadot = y
    return np.array([thetadot, (A * OMEGA**2 * np.cos(OMEGA * t) - G) * np.sin(theta) / L])


def main():
    t_eval = np.linspace(0.0, 100.0, 10001)
    start = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, 100.0), [1.0, 0.0], method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=t_eval)
    seconds = time.perf_counter() - start
    if not sol.success:
        raise SystemExit(f"solve_ivp failed: {sol.message}")
    print(f"theta-at-10 {float(sol.y[0, 1000])!r}")
    print(f"theta-at-100 {float(sol.y[0, -1])!r}")
    print(f"samples {sol.t.size}")
    print(f"rhs-evaluations {sol.nfev}")
    print(f"integrate-seconds {seconds!r}")


if __name__ == "__main__":
    main()
