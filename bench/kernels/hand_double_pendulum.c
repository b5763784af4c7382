/* Hand-written C of the planar double pendulum's state derivative, the baseline for its sicm
 * kernel.
 *
 * Bob 1 (mass m1) hangs on a rod of length l1 from a fixed pivot, bob 2 (mass m2) on a rod of
 * length l2 from bob 1; theta1, theta2 are measured from the downward vertical. With
 * M = m1 + m2 and d = theta1 - theta2, Lagrange's equations
 *
 *   M l1 theta1'' + m2 l2 cos(d) theta2'' = -m2 l2 sin(d) theta2'^2 - M g sin(theta1)
 *   l1 cos(d) theta1'' + l2 theta2''      =  l1 sin(d) theta1'^2    - g sin(theta2)
 *
 * are solved by Cramer's rule; the determinant is M l1 l2 - m2 l1 l2 cos^2(d), never zero
 * because m1 > 0:
 *
 *   theta1'' = (m2 g sin(theta2) cos(d) - m2 sin(d) (l1 theta1'^2 cos(d) + l2 theta2'^2)
 *               - M g sin(theta1)) / (l1 (M - m2 cos^2(d)))
 *   theta2'' = (M (l1 theta1'^2 sin(d) - g sin(theta2) + g sin(theta1) cos(d))
 *               + m2 l2 theta2'^2 sin(d) cos(d)) / (l2 (M - m2 cos^2(d)))
 *
 * sin(d) and cos(d) come from the angle-difference formulas, so one call costs two sin/cos
 * pairs (which the C compiler merges into sincos) and one division. Parameters as in
 * bench/double-pendulum.sicm: m1 = 1, m2 = 1.5, l1 = 1, l2 = 0.75, g = 9.8. Same ABI as a
 * sicm kernel: in = (t, theta1, theta2, theta1', theta2'), out = (1, theta1', theta2',
 * theta1'', theta2''); p is unused.
 */
#include <math.h>

void hand_double_pendulum(const double *in, double *out, const double *p);

static const double kM1 = 1.0;
static const double kM2 = 1.5;
static const double kL1 = 1.0;
static const double kL2 = 0.75;
static const double kG = 9.8;

void hand_double_pendulum(const double *in, double *out, const double *p) {
  (void)p;
  const double total = kM1 + kM2;
  const double theta1 = in[1], theta2 = in[2], w1 = in[3], w2 = in[4];
  const double s1 = sin(theta1), c1 = cos(theta1);
  const double s2 = sin(theta2), c2 = cos(theta2);
  const double sd = s1 * c2 - c1 * s2; /* sin(theta1 - theta2) */
  const double cd = c1 * c2 + s1 * s2; /* cos(theta1 - theta2) */
  const double w1sq = w1 * w1, w2sq = w2 * w2;
  /* One division for both accelerations: 1 / (l2 D) = (l1 / l2) / (l1 D), D = M - m2 cos^2(d). */
  const double inv1 = 1.0 / (kL1 * (total - kM2 * cd * cd));
  const double inv2 = (kL1 / kL2) * inv1;
  out[0] = 1.0;
  out[1] = w1;
  out[2] = w2;
  out[3] =
      (kM2 * kG * s2 * cd - kM2 * sd * (kL1 * w1sq * cd + kL2 * w2sq) - total * kG * s1) * inv1;
  out[4] = (total * (kL1 * w1sq * sd - kG * s2 + kG * s1 * cd) + kM2 * kL2 * w2sq * sd * cd) * inv2;
}
