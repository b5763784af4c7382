"""The planetary systems of bench/taylor-vs-heyoka, for both of its sides."""
import math


def planetary_state(n=10):
    """A star (mass 1) and n - 1 planets (mass 1e-4) on near-circular orbits of radii
    1.6^(k-1), k = 1 .. n-1, at angles 2.4 k, inclined by 0.02 k radians: masses, and
    positions and velocities by body (x y z vx vy vz), rounded to 12 digits as nbody.sicm
    writes them."""
    masses = [1.] + [1e-4] * (n - 1)
    state = [0.] * 6
    for k in range(1, n):
        r, phi, inc = 1.6 ** (k - 1), 2.4 * k, 0.02 * k
        v = math.sqrt(1 / r)
        state += [r * math.cos(phi), r * math.sin(phi), 0.,
                  -v * math.sin(phi) * math.cos(inc), v * math.cos(phi) * math.cos(inc),
                  v * math.sin(inc)]
    return masses, [float(f"{x:.12g}") for x in state]
