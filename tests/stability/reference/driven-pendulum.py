#!/usr/bin/env python3
"""The independent reference of tests/stability/chaos-driven-pendulum.sicm.

The driven pendulum of figure 1.7 (m = 1, l = 1, g = 9.8, pivot at
a cos(omega t) with a = .1, omega = 2 sqrt(g)) from theta = 1 at rest, to
t = 10, with mpmath's Taylor-series integrator (odefun) in 40-digit
arithmetic. The parameters are the doubles sicm computes with (9.8 and .1
are not exact in binary), so this solves the very problem the test poses.
Two runs (32 digits, tolerance 1e-28, degree 30; 40 digits, 1e-35,
degree 40) agree to all 30 digits printed:

    theta(10)    =  1.27379225442614753302903760182
    thetadot(10) = -3.45379718978430955121602856519

Needs python3-mpmath; takes about a minute.
"""
import math

import mpmath as mp

mp.mp.dps = 40
g, a, omega = mp.mpf(9.8), mp.mpf(0.1), mp.mpf(2 * math.sqrt(9.8))


def derivative(t, y):
    theta, thetadot = y
    # Lagrange's equation of the pendulum whose pivot moves as a cos(omega t)
    return [thetadot, -(g - a * omega**2 * mp.cos(omega * t)) * mp.sin(theta)]


solution = mp.odefun(derivative, 0, [mp.mpf(1), mp.mpf(0)], tol=mp.mpf(10)**-35, degree=40)
theta, thetadot = solution(10)
print(mp.nstr(theta, 30), mp.nstr(thetadot, 30))
