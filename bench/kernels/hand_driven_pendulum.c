/* Hand-written C of the driven pendulum's state derivative, the baseline for its sicm kernel.
 *
 * The pendulum of length l hangs from a pivot at height y_s(t) = a cos(omega t) in a uniform
 * field g (SICM 1.6.2). Lagrange's equation for the angle theta from the downward vertical is
 *
 *   theta'' = (a omega^2 cos(omega t) - g) sin(theta) / l,
 *
 * with the book's m = 1, l = 1, g = 9.8, a = 0.1, omega = 2 sqrt(g); the mass cancels. The
 * constants are folded by hand, as a careful C programmer would, so that one call costs one
 * sin, one cos and three multiplications. Same ABI as a sicm kernel:
 * in = (t, theta, thetadot), out = (1, thetadot, theta''); p is unused.
 */
#include <math.h>

void hand_driven_pendulum(const double *in, double *out, const double *p);

static const double kG = 9.8;
static const double kL = 1.0;
static const double kA = 0.1;
static const double kOmega = 6.260990336999411; /* 2 sqrt(9.8) */

void hand_driven_pendulum(const double *in, double *out, const double *p) {
  (void)p;
  /* Folded at compile time: a omega^2 / l and g / l. */
  const double drive = kA * kOmega * kOmega / kL, gravity = kG / kL;
  const double t = in[0], theta = in[1], thetadot = in[2];
  out[0] = 1.0;
  out[1] = thetadot;
  out[2] = (drive * cos(kOmega * t) - gravity) * sin(theta);
}
