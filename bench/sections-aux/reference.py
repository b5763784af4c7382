"""bench/sections-aux/reference.py: the reference points of bench/sections.

usage: bench/peers/.venv/bin/python bench/sections-aux/reference.py [--t-final T] [ORBIT ...]

The Henon-Heiles section (E = 1/8, x = 0, p_x > 0) of the orbits of
events.sicm and sampling.sicm (the same starts, the same numbering), by
heyoka's Taylor integrator in quadruple precision (real128, tolerance its
epsilon, 1.9e-34) with its own event detection: an independent computation
(heyoka's, not sicm's, integrator and root finder) whose points are exact
to far below double rounding on the regular orbits. Each start (y, p_y) is
the double sicm reads; p_x is computed from them in quadruple precision on
E = 1/8 (sicm's double p_x is within an ulp of it). Prints "orbit t y p_y"
per point, with 36 significant digits. A crossing at t = 0 (every start lies
on x = 0) is not one, as `crossings` counts.
"""
import argparse
import sys

import heyoka as hy
import numpy as np

# The starts of events.sicm, in its order.
STARTS = [(.1, .05), (0., .3), (-.2, 0.), (.3, -.1), (.45, 0.),
          (-.1, -.2), (.2, .2), (0., 0.), (.55, 0.), (-.3, .1)]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--t-final", type=float, default=1000.)
    p.add_argument("orbits", nargs="*", type=int)
    a = p.parse_args()
    R = hy.real128
    x, y, px, py = hy.make_vars("x", "y", "px", "py")
    system = [(x, px), (y, py), (px, -x - 2. * x * y), (py, -y - x * x + y * y)]
    points = []

    def found(ta, t, d_sign):
        ta.update_d_output(t)
        points.append((t, ta.d_output[1], ta.d_output[3]))

    event = hy.nt_event(x, found, direction=hy.event_direction.positive, fp_type=R)
    ta = hy.taylor_adaptive(system, np.array([R(0)] * 4), nt_events=[event], fp_type=R)
    for i in a.orbits or range(len(STARTS)):
        y0, py0 = (R(float(v)) for v in STARTS[i])
        E = R(1) / 8
        px0 = np.sqrt(2 * (E - (y0 * y0 / 2 - y0 * y0 * y0 / 3)) - py0 * py0)
        ta.time = R(0)
        ta.state[:] = [R(0), y0, px0, py0]
        ta.reset_cooldowns()
        points.clear()
        ta.propagate_until(R(a.t_final))
        for t, yy, pp in points:
            if t > 0:
                print(i, t, yy, pp)  # real128 prints its 36 digits
    return 0


if __name__ == "__main__":
    sys.exit(main())
