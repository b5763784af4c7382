/* Hand-written C of the planar N-link chain, the baseline of bench/scale.
 *
 * Link i (mass m_i at its end, length l_i) hangs from the end of link i-1, the first from a
 * fixed pivot; theta_i is measured from the downward vertical, g = G. With the tail masses
 * mu_j = sum_{i>=j} m_i, the kinetic energy is (1/2) w^T M w with
 *
 *   M_jk = mu_max(j,k) l_j l_k cos(theta_j - theta_k)
 *
 * and Lagrange's equations are M theta'' = f with
 *
 *   f_j = -sum_k mu_max(j,k) l_j l_k sin(theta_j - theta_k) theta_k'^2 - mu_j g l_j sin(theta_j).
 *
 * One call: N sin/cos pairs (the differences' sines and cosines by the angle-difference
 * formulas), M and f in O(N^2), then M is factored by Cholesky in place and the two triangular
 * systems solved, O(N^3). The parameters (N, G, mass[], length[]) come from params.h, which
 * bench/scale writes for each size.
 *
 * State y = (theta_0..theta_{N-1}, theta'_0..theta'_{N-1}). hand_kernel has a sicm kernel's
 * ABI (in = (t, y), out = (1, y')), for bench/scale-aux/rhs_harness.c; compiled with
 * -DHAND_KERNEL_ONLY there, and without it this is the whole program (hand_rk8pd.h).
 */
#include <math.h>

#include "params.h"

enum { DIM = 2 * N };

void hand_kernel(const double *in, double *out, const double *p);

/* The mass matrix (lower triangle and diagonal) and the force at angles th, velocities w. */
static void chain_matrix(const double *th, const double *w, double m[N][N], double *f) {
  double s[N], c[N], tail[N];
  double mu = 0;
  for (int j = N - 1; j >= 0; j--) {
    mu += mass[j];
    tail[j] = mu;
    s[j] = sin(th[j]);
    c[j] = cos(th[j]);
  }
  for (int j = 0; j < N; j++)
    f[j] = -tail[j] * G * length[j] * s[j];
  for (int j = 0; j < N; j++) {
    m[j][j] = tail[j] * length[j] * length[j];
    for (int k = 0; k < j; k++) {
      const double a = tail[j] * length[j] * length[k]; /* max(j, k) = j */
      const double sd = s[j] * c[k] - c[j] * s[k], cd = c[j] * c[k] + s[j] * s[k];
      m[j][k] = a * cd;
      f[j] -= a * sd * w[k] * w[k];
      f[k] += a * sd * w[j] * w[j]; /* sin(theta_k - theta_j) = -sd */
    }
  }
}

/* Solves m x = f in place (x in f) by Cholesky; m's lower triangle becomes the factor. */
static void cholesky_solve(double m[N][N], double *f) {
  for (int j = 0; j < N; j++) {
    double d = m[j][j];
    for (int k = 0; k < j; k++)
      d -= m[j][k] * m[j][k];
    d = sqrt(d);
    m[j][j] = d;
    for (int i = j + 1; i < N; i++) {
      double x = m[i][j];
      for (int k = 0; k < j; k++)
        x -= m[i][k] * m[j][k];
      m[i][j] = x / d;
    }
  }
  for (int i = 0; i < N; i++) { /* L z = f */
    double x = f[i];
    for (int k = 0; k < i; k++)
      x -= m[i][k] * f[k];
    f[i] = x / m[i][i];
  }
  for (int i = N - 1; i >= 0; i--) { /* L^T x = z */
    double x = f[i];
    for (int k = i + 1; k < N; k++)
      x -= m[k][i] * f[k];
    f[i] = x / m[i][i];
  }
}

static void hand_deriv(const double *y, double *dydt) {
  double m[N][N];
  for (int j = 0; j < N; j++)
    dydt[j] = y[N + j];
  chain_matrix(y, y + N, m, dydt + N);
  cholesky_solve(m, dydt + N);
}

void hand_kernel(const double *in, double *out, const double *p) {
  (void)p;
  out[0] = 1.0;
  hand_deriv(in + 1, out + 1);
}

#ifndef HAND_KERNEL_ONLY
/* (1/2) w^T M w - g sum_j mu_j l_j cos(theta_j). */
static double hand_energy(const double *y) {
  double m[N][N], f[N], e = 0, mu = 0;
  chain_matrix(y, y + N, m, f);
  for (int j = 0; j < N; j++) {
    e += 0.5 * m[j][j] * y[N + j] * y[N + j];
    for (int k = 0; k < j; k++)
      e += m[j][k] * y[N + j] * y[N + k];
  }
  for (int j = N - 1; j >= 0; j--) {
    mu += mass[j];
    e -= mu * G * length[j] * cos(y[j]);
  }
  return e;
}

#include "hand_rk8pd.h"
#endif
