/* Hand-written C of the 3-D N-body problem, the baseline of bench/scale.
 *
 * N bodies of unit mass, G = 1: H = sum_i |p_i|^2 / 2 - sum_{i<j} 1 / |q_i - q_j|, so
 * q_i' = p_i and p_i' = -sum_{j != i} (q_i - q_j) / |q_i - q_j|^3. One call visits each pair
 * once (one sqrt and one division a pair) and adds the force to both bodies. N comes from
 * params.h, which bench/scale writes for each size.
 *
 * State y = (q_0x, q_0y, q_0z, ..., q_{N-1}z, p_0x, ..., p_{N-1}z), sicm's order of the leaves
 * of (up (up x y z) ...) and (down (down px py pz) ...). hand_kernel has a sicm kernel's ABI
 * (in = (t, y), out = (1, y')), for bench/scale-aux/rhs_harness.c; compiled with
 * -DHAND_KERNEL_ONLY there, and without it this is the whole program (hand_rk8pd.h), which
 * also reports the closest approach of two bodies after any step.
 */
#include <math.h>

#include "params.h"

enum { DIM = 6 * N };

void hand_kernel(const double *in, double *out, const double *p);

static void hand_deriv(const double *y, double *dydt) {
  const double *q = y, *p = y + 3 * N;
  double *dq = dydt, *dp = dydt + 3 * N;
  for (int i = 0; i < 3 * N; i++) {
    dq[i] = p[i];
    dp[i] = 0;
  }
  for (int i = 0; i < N; i++)
    for (int j = i + 1; j < N; j++) {
      const double dx = q[3 * i] - q[3 * j], dy = q[3 * i + 1] - q[3 * j + 1],
                   dz = q[3 * i + 2] - q[3 * j + 2];
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double k = 1.0 / (r2 * sqrt(r2));
      dp[3 * i] -= k * dx, dp[3 * i + 1] -= k * dy, dp[3 * i + 2] -= k * dz;
      dp[3 * j] += k * dx, dp[3 * j + 1] += k * dy, dp[3 * j + 2] += k * dz;
    }
}

void hand_kernel(const double *in, double *out, const double *p) {
  (void)p;
  out[0] = 1.0;
  hand_deriv(in + 1, out + 1);
}

#ifndef HAND_KERNEL_ONLY
static double hand_closest = INFINITY;

static double distance(const double *q, int i, int j) {
  const double dx = q[3 * i] - q[3 * j], dy = q[3 * i + 1] - q[3 * j + 1],
               dz = q[3 * i + 2] - q[3 * j + 2];
  return sqrt(dx * dx + dy * dy + dz * dz);
}

static double hand_energy(const double *y) {
  double e = 0;
  for (int i = 0; i < 3 * N; i++)
    e += 0.5 * y[3 * N + i] * y[3 * N + i];
  for (int i = 0; i < N; i++)
    for (int j = i + 1; j < N; j++)
      e -= 1.0 / distance(y, i, j);
  return e;
}

static void hand_watch(const double *y) {
  for (int i = 0; i < N; i++)
    for (int j = i + 1; j < N; j++)
      hand_closest = fmin(hand_closest, distance(y, i, j));
}

#define HAND_WATCH
#include "hand_rk8pd.h"
#endif
