#!/usr/bin/env python3
"""bench/sections-heyoka.py: the Henon-Heiles section of bench/sections by heyoka.

usage: bench/peers/.venv/bin/python bench/sections-heyoka.py [--tol TOL] [-r ROUNDS]
           [--t-final T] [--points FILE]

The same problem as bench/sections-aux/events.sicm: E = 1/8, the section
x = 0 with p_x > 0, coordinates (y, p_y), the same ten starts (y, p_y) with
p_x from the energy, each orbit to t = 1000 (--t-final). heyoka's adaptive
Taylor integrator (double precision, tolerance --tol, default its epsilon
2.2e-16; the order follows from it) with a non-terminal event on x in the
positive direction: heyoka finds the event's roots on each step's Taylor
polynomial, and the callback takes the state there from the step's dense
output (update_d_output). A crossing at t = 0 (every start lies on x = 0) is
dropped, as sicm's `crossings` counts none there.

The integrator is made once (heyoka compiles it with LLVM: "jit s"); each
round then integrates the ten orbits from their starts, timed in the process
with time.perf_counter (and its CPU time with time.process_time); the
median and the min and max of the rounds are printed, one line "heyoka
tol=... order=... jit_s=... median_s=... min_s=... max_s=... cpu_s=...
points=N" (cpu_s the median CPU time of a round). --points FILE writes the points, "orbit t y p_y" per line, for
bench/sections to compare with its reference. Needs bench/peers/setup.
"""
import argparse
import statistics
import sys
import time

import heyoka as hy
import numpy as np

# The starts of bench/sections-aux/events.sicm, in its order.
STARTS = [(.1, .05), (0., .3), (-.2, 0.), (.3, -.1), (.45, 0.),
          (-.1, -.2), (.2, .2), (0., 0.), (.55, 0.), (-.3, .1)]
E = 1 / 8


def start_state(y0, py0):
    """As section->state: p_x from the energy, in double precision."""
    px2 = 2 * (E - (y0 * y0 / 2 - y0 * y0 * y0 / 3)) - py0 * py0
    return [0., y0, np.sqrt(px2), py0]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--tol", type=float, default=None,
                   help="heyoka's tolerance (default: its epsilon)")
    p.add_argument("-r", "--rounds", type=int, default=21)
    p.add_argument("--t-final", type=float, default=1000.)
    p.add_argument("--points", help="write the points here")
    a = p.parse_args()

    x, y, px, py = hy.make_vars("x", "y", "px", "py")
    system = [(x, px), (y, py), (px, -x - 2. * x * y), (py, -y - x * x + y * y)]
    points = []

    def crossing(ta, t, d_sign):
        # t is the event's time; the dense output of the step holds the state.
        ta.update_d_output(t)
        points.append((t, ta.d_output[1], ta.d_output[3]))

    event = hy.nt_event(x, crossing, direction=hy.event_direction.positive)
    kwargs = {} if a.tol is None else {"tol": a.tol}
    start = time.perf_counter()
    ta = hy.taylor_adaptive(system, [0.] * 4, nt_events=[event], **kwargs)
    jit = time.perf_counter() - start

    def run():
        orbits = []
        for y0, py0 in STARTS:
            ta.time = 0.
            ta.state[:] = start_state(y0, py0)
            ta.reset_cooldowns()
            points.clear()
            ta.propagate_until(a.t_final)
            orbits.append([q for q in points if q[0] > 0])
        return orbits

    orbits = run()  # warm-up
    times, cpu = [], []
    for _ in range(a.rounds):
        start, start_cpu = time.perf_counter(), time.process_time()
        run()
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    n = sum(len(o) for o in orbits)
    if a.points:
        with open(a.points, "w") as f:
            for i, orbit in enumerate(orbits):
                for t, yy, pp in orbit:
                    f.write(f"{i} {t!r} {float(yy)!r} {float(pp)!r}\n")
    print(f"heyoka tol={ta.tol:.3g} order={ta.order} jit_s={jit:.4f} "
          f"median_s={statistics.median(times):.5f} min_s={min(times):.5f} "
          f"max_s={max(times):.5f} cpu_s={statistics.median(cpu):.5f} points={n}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
