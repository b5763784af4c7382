# Reference for henon-heiles-section-50-orbits.sicm (100 crossings) and
# tests/numerics/section-henon-heiles.sicm (5): the first N upward crossings
# of x = 0 by the Henon-Heiles orbit through (y, p_y) = (0.1, 0.05) on the
# section at E = 1/8, by mpmath's Taylor-series ODE solver at 30 digits, each
# crossing bracketed on a grid of 0.25 time units and found by mpmath's root
# finder. Prints time, y, p_y per crossing. Usage: python3 THIS [N], N = 100
# by default (some minutes).
import sys

import mpmath as mp

count = int(sys.argv[1]) if len(sys.argv) > 1 else 100

mp.mp.dps = 30
E = mp.mpf(1) / 8
y0, py0 = mp.mpf('0.1'), mp.mpf('0.05')
V = lambda x, y: (x * x + y * y) / 2 + x * x * y - y**3 / 3
px0 = mp.sqrt(2 * (E - V(0, y0)) - py0**2)
f = mp.odefun(lambda t, s: [s[2], s[3], -s[0] - 2 * s[0] * s[1], -s[1] - s[0]**2 + s[1]**2],
              0, [mp.mpf(0), y0, px0, py0], tol=mp.mpf(10)**-28, degree=30)
x = lambda t: f(t)[0]
times = []
t, step = mp.mpf(0), mp.mpf('0.25')
while len(times) < count:
    a, b = t, t + step
    if x(a) < 0 <= x(b):
        times.append(mp.findroot(x, (a, b), solver='anderson'))
    t = b
for r in times:
    print(mp.nstr(r, 20), mp.nstr(f(r)[1], 20), mp.nstr(f(r)[3], 20))
