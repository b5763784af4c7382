#!/usr/bin/env python3
"""bench/taylor-vs-heyoka-aux/heyoka_side.py: the problems of bench/taylor-vs-heyoka by heyoka.

usage: bench/peers/.venv/bin/python heyoka_side.py kepler|nbody [--tol TOL] [--long-double]
       [--compact] [--bodies N]
           [-r ROUNDS] [--compact]

kepler: the Kepler problem of kepler.sicm (GM = 1, e = .9 from periapsis, the
initial state computed in double as the sicm program computes it) to
t = 2 pi 100. nbody: the planetary system of nbody.sicm (planetary_state below)
to t = 100. heyoka's adaptive Taylor integrator (tolerance --tol; the order
follows from it; --long-double: np.longdouble), made once (LLVM compilation,
"jit_s"), then for each round reset to the initial state and timed around
propagate_until alone with time.perf_counter and time.process_time. Prints
one line "heyoka tol=... order=... jit_s=... median_s=... cpu_s=... steps=N"
and then the final state (time first, then the state as the sicm program
prints it), one number a line, in double.
"""
import argparse
import math
import statistics
import time

import heyoka as hy
import numpy as np

from planetary import planetary_state


def kepler(fp):
    x, y, vx, vy = hy.make_vars("x", "y", "vx", "vy")
    r3 = (x * x + y * y) ** (-3. / 2)
    system = [(x, vx), (y, vy), (vx, -x * r3), (vy, -y * r3)]
    e = .9
    state = [1. - e, 0., 0., math.sqrt((1. + e) / (1. - e))]
    return system, np.array(state, dtype=fp), 2 * math.pi * 100


def nbody(fp, bodies=10):
    masses, state = planetary_state(bodies)
    system = hy.model.nbody(len(masses), masses=masses, Gconst=1.)
    return system, np.array(state, dtype=fp), 100.


def main():
    p = argparse.ArgumentParser()
    p.add_argument("problem", choices=["kepler", "nbody"])
    p.add_argument("--tol", type=float, default=1e-12)
    p.add_argument("--long-double", action="store_true")
    p.add_argument("--compact", action="store_true", help="heyoka's compact mode")
    p.add_argument("-r", "--rounds", type=int, default=11)
    p.add_argument("--bodies", type=int, default=10, help="nbody: the star and N - 1 planets")
    a = p.parse_args()
    fp = np.longdouble if a.long_double else np.float64
    system, state, t_final = kepler(fp) if a.problem == "kepler" else nbody(fp, a.bodies)
    t0 = time.perf_counter()
    ta = hy.taylor_adaptive(system, state, tol=fp(a.tol), fp_type=fp, compact_mode=a.compact)
    jit = time.perf_counter() - t0
    walls, cpus = [], []
    for _ in range(a.rounds):
        ta.time = fp(0)
        ta.state[:] = state
        w, c = time.perf_counter(), time.process_time()
        result = ta.propagate_until(fp(t_final))
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    steps = result[3]
    print(f"heyoka tol={a.tol:g} order={ta.order} jit_s={jit:.3g} "
          f"median_s={statistics.median(walls):.6g} cpu_s={statistics.median(cpus):.6g} "
          f"steps={steps}")
    print(repr(float(ta.time)))
    for x in ta.state:
        print(repr(float(x)))


if __name__ == "__main__":
    main()
