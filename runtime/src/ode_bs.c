/* Bulirsch-Stoer: modified midpoint rule with extrapolation, adaptive in order and step size.
 *
 * Approach. One step of length H from (t, y) is computed several times with
 * Gragg's modified midpoint rule, using n_j substeps of size H/n_j for
 * j = 1, 2, ..., with n_j = 2, 4, 6, 8, 12, 16, 24, 32 (Bulirsch's
 * sequence, that of the original method and of scmutils). Gragg showed that
 * the error of that rule has an asymptotic expansion in even powers of the
 * substep size, so the results T_j1 can be extrapolated to substep size
 * zero by fitting a polynomial in (H/n_j)^2 and evaluating it at 0. The
 * Aitken-Neville recurrence builds the table
 *
 *     T_{j,k+1} = T_{j,k} + (T_{j,k} - T_{j-1,k}) / ((n_j / n_{j-k})^2 - 1)
 *
 * in which T_{j,j} has order 2j (local error O(H^(2j+1))). The difference
 * of the two best entries of a row, T_{jj} - T_{j,j-1}, estimates the error
 * of the lower one and is what the error test uses, so the step keeps the
 * more accurate T_{jj} (local extrapolation).
 *
 * Smoothness. Results should depend smoothly on the initial state: the
 * book differentiates surface-of-section maps by central differences with
 * increments of 1e-6 at tolerance 1e-12 (Figure 3.12, area preservation),
 * which needs the map to vary by much less than 1e-12 except through the
 * state. Two things break that, and both are dealt with here:
 *
 *   - Rounding in the extrapolation. T_jj = sum_i c_i T_i1, and for the
 *     harmonic sequence n_j = 2j of ODEX the absolute sum of the weights
 *     (the Lebesgue constant) is 56, 119 and 256 at rows 7 to 9: the few
 *     units in the last place of rounding error in each midpoint result
 *     become 100 to 500 units in T_jj, a noise of about 3e-13 at |y| = 10
 *     that differs from one initial state to the next. With Bulirsch's
 *     sequence the constant stays below 9 up to row 8. Its rows need more
 *     substeps: the work grows by 5 to 35% at tolerances 1e-8 to 1e-12, and
 *     by up to 50% at 1e-14.
 *   - Step sizes chosen from noise. See the last point of Control.
 *
 * Control. We follow the order and step size strategy of Deuflhard (1983)
 * as presented by Hairer, Norsett and Wanner, "Solving Ordinary Differential
 * Equations I", section II.9 (the code ODEX), in our own formulation:
 *
 *   - For every row j >= 2 the error estimate err_j gives the step H_j that
 *     would make that row's error just acceptable,
 *     H_j = H * 0.94 (0.65 / err_j)^(1/(2j-1)), clamped to [H/50, 4H], and
 *     the work per unit time W_j = A_j / H_j, where A_j = 1 + n_1 + ... + n_j
 *     counts the rhs evaluations needed to build row j.
 *   - A step has a target row k (the order 2k). Rows are built up to k+1 at
 *     most. The step is accepted at the first row j >= k-1 whose error is
 *     <= 1. A convergence monitor rejects early: if at row k-1 the error
 *     exceeds (n_k n_{k+1} / n_1^2)^2, or at row k it exceeds
 *     (n_{k+1} / n_1)^2, extrapolating further is unlikely to succeed (each
 *     new row reduces the error by roughly (n_1 / n_{j+1})^2), so the step
 *     is retried at once with a shorter H.
 *   - After an accepted step at row a, the next target is the row of least
 *     work per unit step among a-1, a and a+1: lower the order if
 *     W_{a-1} < 0.8 W_a, raise it if W_a < 0.9 W_{a-1} (row a+1 was not
 *     computed, so its step is estimated as H_a A_{a+1} / A_a); otherwise
 *     keep it. Right after a rejection neither order nor step may grow.
 *   - An estimate err_j below the rounding level of T_jj (see noise_floor)
 *     measures rounding, not truncation, and is raised to that level before
 *     it predicts H_j. Otherwise the first step, which the initial step
 *     guess keeps short, has an estimate that is rounding noise (0 from one
 *     initial state, 4e-5 from another 1e-6 away); the growth factors it
 *     gives, and after them the whole sequence of steps and orders, change
 *     at random from one initial state to the next, and the result jumps by
 *     about the tolerance.
 *
 * Between calls the step size and target row persist. A step shortened to
 * land exactly on the caller's t1 is accepted at the first row that meets
 * the tolerance (rows 2 or 3 for a short step, so small increments cost
 * 7 to 13 evaluations) and, unless it needed more rows than the target,
 * leaves the step size and order the controller had reached untouched, so
 * that a monitor loop calling evolve repeatedly resumes where it was.
 *
 * Errors. A right-hand side returning non-finite values is treated as a
 * step that was too long: H is halved and the step retried. A step that
 * would not move t (H below the resolution of t) fails with SICM_ESTEP.
 *
 * Limits. Explicit method: on stiff problems the step is limited by
 * stability and the work explodes; the stiffness watch of ode.c then stops
 * a long run with SICM_ESTIFF and points to cvode-bdf. Target orders
 * go up to 2 (kMaxRow - 1) = 14 with kMaxRow = 8 rows (a step may end at
 * row 8, order 16, costing 105 evaluations); at tolerances near machine
 * precision round-off in the extrapolation limits the attainable accuracy.
 * Like every adaptive method, the result is only piecewise smooth in the
 * initial state: where a small change of it changes the number of steps or
 * an order, the result jumps by about the error, which is of the order of
 * the tolerance.
 * Gragg's smoothing step (the average at the end of the midpoint rule) is
 * used; it costs one evaluation per row and damps the midpoint rule's weakly
 * unstable oscillation. There is no dense output: steps are shortened to hit
 * t1 instead, which costs little for the monitor loops of SICM. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_internal.h"

enum { kMaxRow = 8 }; /* rows j = 1..kMaxRow; targets 2..kMaxRow-1 */

/* Substeps n_j of row j (index 0 unused): Bulirsch's sequence, n_j = 2 n_{j-2}. */
static const int kSubsteps[kMaxRow + 1] = {0, 2, 4, 6, 8, 12, 16, 24, 32};

/* Where a step accepted at row j is stable (see sicm_ode_stability), for
 * the stiffness watch. Measured on the stability function R_j(z) = T_jj for
 * y' = lambda y, z = H lambda: midpoint and extrapolate as below, written
 * out in complex arithmetic, scanning |z| in steps of 1e-3 along each axis
 * until |R_j| first exceeds 1 + 1e-3. Rows 1, 3, 5 and 7 (orders 2, 6, 10,
 * 14) grow slightly on the imaginary axis from small |z| on (|R| > 1 from
 * 0.02, 0.08, 0.4, 1.1); the slack of 1e-3 a step is what error control
 * absorbs at a loose tolerance. As a check, the controller
 * integrating y' = lambda y from a tiny start at tolerances 1e-3 to 1e-13
 * settles at row 4 and holds |H lambda| at 5.5 (real) and 3.85 (imaginary). */
static const sicm_ode_stability kStability[kMaxRow + 1] = {
    {0, 0},       {3.09, 0.71}, {4.46, 3.36}, {5.89, 1.46}, {5.55, 3.86},
    {6.15, 3.05}, {7.00, 4.14}, {8.09, 7.15}, {9.32, 6.57}};

/* Rounding error of one midpoint result T_j1, in units of the last place
 * of the solution, before the extrapolation amplifies it (see noise_floor):
 * the n_j <= 32 substeps add up to about sqrt(n_j) units. */
static const double kMidpointUlps = 8;

typedef struct {
  int k;         /* target row for the next step, 2..kMaxRow-1 */
  int f0_valid;  /* f0 = f(t_f0, y) at the current point */
  double *f0;    /* derivative at the start of the step */
  double *table; /* kMaxRow rows of dim: the Aitken-Neville tableau, see extrapolate */
  double *z0, *z1, *fz, *diff, *work;
  double cost[kMaxRow + 1];     /* A_j: rhs evaluations to build rows 1..j */
  double lebesgue[kMaxRow + 1]; /* sum of |weights| of T_i1 in T_jj */
} bs_state;

static int n_of(int j) {
  return kSubsteps[j];
}

/* The Lebesgue constant of extrapolation at row j: T_jj = sum_i c_i T_i1
 * with c_i the Lagrange weights at 0 of the nodes (1/n_i)^2, and this is
 * sum_i |c_i|, the factor by which rounding errors in the T_i1 can grow. */
static double lebesgue_constant(int j) {
  double sum = 0;
  for (int i = 1; i <= j; i++) {
    double c = 1;
    const double ni2 = (double)n_of(i) * n_of(i);
    for (int l = 1; l <= j; l++)
      if (l != i) c *= ni2 / (ni2 - (double)n_of(l) * n_of(l));
    sum += fabs(c);
  }
  return sum;
}

static double *row(const sicm_ode *o, bs_state *b, int j) {
  return b->table + (j - 1) * o->dim;
}

static int initial_target(const sicm_ode *o) {
  double tol = o->rel_tol > 0 ? o->rel_tol : o->abs_tol;
  int k = (int)(-log10(tol) * 0.6 + 1.5);
  return k < 2 ? 2 : k > kMaxRow - 1 ? kMaxRow - 1 : k;
}

static int bs_init(sicm_ode *o) {
  bs_state *b = calloc(1, sizeof *b);
  if (!b) return SICM_ENOMEM;
  o->backend = b;
  const size_t n = o->dim;
  b->table = malloc(kMaxRow * n * sizeof *b->table);
  b->f0 = malloc(7 * n * sizeof *b->f0);
  if (!b->table || !b->f0) return SICM_ENOMEM;
  b->z0 = b->f0 + n;
  b->z1 = b->z0 + n;
  b->fz = b->z1 + n;
  b->diff = b->fz + n;
  b->work = b->diff + n; /* 2n */
  b->cost[0] = 1;        /* f0 */
  for (int j = 1; j <= kMaxRow; j++) {
    b->cost[j] = b->cost[j - 1] + n_of(j);
    b->lebesgue[j] = lebesgue_constant(j);
  }
  b->k = initial_target(o);
  return SICM_SUCCESS;
}

static void bs_free(sicm_ode *o) {
  bs_state *b = o->backend;
  if (!b) return;
  free(b->table);
  free(b->f0);
  free(b);
}

static void bs_reset(sicm_ode *o) {
  bs_state *b = o->backend;
  b->k = initial_target(o);
  b->f0_valid = 0;
}

/* Gragg's modified midpoint rule over [t, t + H] with n substeps, starting
 * from y with derivative b->f0; the smoothed result goes to out. Uses n rhs
 * evaluations. Returns SICM_SUCCESS, SICM_EUSER or SICM_EBADFUNC. */
static int midpoint(sicm_ode *o, bs_state *b, double t, const double *y, double H, int n,
                    double *out) {
  const size_t dim = o->dim;
  const double h = H / n;
  double *zp = b->z0, *zc = b->z1; /* z_{m-1}, z_m */
  memcpy(zp, y, dim * sizeof *zp);
  for (size_t i = 0; i < dim; i++)
    zc[i] = y[i] + h * b->f0[i];
  for (int m = 1; m < n; m++) {
    int s = sicm_ode_call_rhs(o, t + m * h, zc, b->fz);
    if (s != SICM_SUCCESS) return s;
    for (size_t i = 0; i < dim; i++)
      zp[i] += 2 * h * b->fz[i]; /* z_{m+1} */
    double *tmp = zp;
    zp = zc;
    zc = tmp;
  }
  int s = sicm_ode_call_rhs(o, t + H, zc, b->fz);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < dim; i++)
    out[i] = 0.5 * (zc[i] + zp[i] + h * b->fz[i]);
  return SICM_SUCCESS;
}

/* Row j has just been stored as T_{j,1} in row(j); rows 1..j-1 hold the
 * previous row of the tableau in reverse, row(l) = T_{j-1, j-l}. Fold the
 * new entry in, leaving row(l) = T_{j, j-l+1}: afterwards row(1) = T_{jj}
 * (the best value) and row(2) = T_{j,j-1} (for the error estimate). */
static void extrapolate(const sicm_ode *o, bs_state *b, int j) {
  const size_t dim = o->dim;
  for (int l = j; l >= 2; l--) {
    const double r = (double)n_of(j) / n_of(l - 1), c = 1.0 / (r * r - 1.0);
    double *hi = row(o, b, l), *lo = row(o, b, l - 1);
    for (size_t i = 0; i < dim; i++)
      lo[i] = hi[i] + (hi[i] - lo[i]) * c;
  }
}

/* The level below which the error estimate of row j is rounding noise, in
 * the units of sicm_ode_error_norm: kMidpointUlps units in the last place
 * of each component (the larger of its start and end values), times the
 * row's Lebesgue constant. It is capped at 0.1, well below the error the
 * step size prediction aims at, so that at tolerances near the rounding
 * level it slows the growth of the step but never shrinks it. */
static double noise_floor(const sicm_ode *o, const bs_state *b, int j, const double *y0,
                          const double *y1) {
  const double ulps = kMidpointUlps * b->lebesgue[j] * DBL_EPSILON;
  double m = 0;
  for (size_t i = 0; i < o->dim; i++) {
    const double scale = o->abs_tol + o->rel_tol * fabs(y1[i]);
    const double r = ulps * fmax(fabs(y0[i]), fabs(y1[i])) / scale;
    if (r > m) m = r;
  }
  return fmin(m, 0.1);
}

static int fail_step_size(sicm_ode *o, double t, const double *y, double H) {
  char detail[200];
  snprintf(detail, sizeof detail,
           "the error test fails even for the shortest step the resolution of t allows "
           "(h = %.3g); the solution may be singular here",
           H);
  return sicm_ode_fail(o, SICM_ESTEP, t, y, "step size too small", detail);
}

/* Choose the target row and step after a step accepted at row a.
 * Hopt[j] and W[j] are known for 2 <= j <= a. */
static void choose_next(const bs_state *b, int a, int kc, int after_reject, const double *Hopt,
                        const double *W, int *knew, double *Hnew) {
  if (a - 1 >= 2 && W[a - 1] < 0.8 * W[a]) {
    *knew = a - 1;
    *Hnew = Hopt[a - 1];
  } else if (a + 1 <= kMaxRow - 1 && (a == 2 || W[a] < 0.9 * W[a - 1])) {
    *knew = a + 1;
    *Hnew = Hopt[a] * b->cost[a + 1] / b->cost[a];
  } else {
    *knew = a;
    *Hnew = Hopt[a];
  }
  if (after_reject && *knew > kc) { /* only when a >= kc, so Hopt[kc] is known */
    *knew = kc;
    *Hnew = Hopt[kc];
  }
  /* A step accepted at the last row (a = kMaxRow) must not target it: the
   * next step builds rows up to target + 1, and the tableau has kMaxRow. */
  if (*knew > kMaxRow - 1) {
    *knew = kMaxRow - 1;
    *Hnew = Hopt[kMaxRow - 1];
  }
}

static int bs_evolve(sicm_ode *o, double *t, double t1, double *y) {
  bs_state *b = o->backend;
  const size_t dim = o->dim;
  const double dir = t1 > *t ? 1.0 : -1.0;
  int after_reject = 0;
  unsigned long steps = 0;
  while (*t != t1) {
    if (!b->f0_valid) {
      int s = sicm_ode_start_derivative(o, *t, y, b->f0);
      if (s != SICM_SUCCESS) return s;
      b->f0_valid = 1;
    }
    if (o->h == 0) {
      int s;
      o->h = sicm_ode_initial_step(o, *t, y, b->f0, t1, 2 * b->k - 1, b->work, &s);
      if (s != SICM_SUCCESS) return sicm_ode_fail_user(o, *t, y);
    }
    if (steps >= o->max_steps) return sicm_ode_fail_max_steps(o, *t, y);

    const int kc = b->k;
    const int final = fabs(o->h) >= fabs(t1 - *t);
    const double H = final ? t1 - *t : o->h;
    /* A step cut short to land on t1 may stop at any row that converged:
     * with small increments (a monitor loop) rows 2 or 3 usually suffice. */
    const int shortened = final && fabs(H) < fabs(o->h);
    if (*t + H == *t || fabs(H) < 16 * DBL_EPSILON * fabs(*t)) return fail_step_size(o, *t, y, H);

    double Hopt[kMaxRow + 1], W[kMaxRow + 1];
    int accepted = 0, last = 0, nonfinite = 0;
    for (int j = 1; j <= kc + 1; j++) {
      int s = midpoint(o, b, *t, y, H, n_of(j), row(o, b, j));
      if (s == SICM_EUSER) return sicm_ode_fail_user(o, *t, y);
      if (s != SICM_SUCCESS) {
        nonfinite = 1;
        break;
      }
      extrapolate(o, b, j);
      if (j == 1) continue;
      const double *best = row(o, b, 1), *next = row(o, b, 2);
      for (size_t i = 0; i < dim; i++)
        b->diff[i] = best[i] - next[i];
      const double err = sicm_ode_error_norm(o, b->diff, best);
      if (!isfinite(err)) {
        nonfinite = 1;
        break;
      }
      const double expo = 1.0 / (2 * j - 1);
      const double e = fmax(err, noise_floor(o, b, j, y, best));
      const double fac = e == 0 ? 4.0 : fmin(4.0, fmax(0.02, 0.94 * pow(0.65 / e, expo)));
      Hopt[j] = H * fac;
      W[j] = b->cost[j] / fabs(Hopt[j]);
      last = j;
      if (j < kc - 1 && !shortened) continue;
      if (err <= 1) {
        accepted = j;
        break;
      }
      /* Convergence monitor: give up on this H when the later rows cannot
       * plausibly bring the error below 1. */
      const double n1 = n_of(1), nk = n_of(kc), nk1 = n_of(kc + 1);
      if (j == kc - 1 && err > (nk * nk1 / (n1 * n1)) * (nk * nk1 / (n1 * n1))) break;
      if (j == kc && err > (nk1 / n1) * (nk1 / n1)) break;
    }

    if (accepted) {
      memcpy(y, row(o, b, 1), dim * sizeof *y);
      *t = final ? t1 : *t + H;
      b->f0_valid = 0;
      steps++;
      o->stats.steps++;
      /* A shortened step that converged easily says nothing about the
       * longer step and its order, which the next call will resume with;
       * the controller only learns from full steps and from hard ones. */
      if (!(shortened && !after_reject && accepted <= kc)) {
        int knew;
        double Hnew;
        choose_next(b, accepted, kc, after_reject, Hopt, W, &knew, &Hnew);
        b->k = knew;
        if (after_reject && fabs(Hnew) > fabs(H)) Hnew = H;
        o->h = dir * fabs(Hnew);
      }
      after_reject = 0;
      int s = sicm_ode_watch_stiffness(o, *t, y, H, t1, kStability[accepted]);
      if (s != SICM_SUCCESS) return s;
    } else {
      o->stats.rejected_steps++;
      after_reject = 1;
      if (nonfinite || last < 2) {
        o->h = 0.5 * H;
      } else {
        int knew = last < kc ? last : kc;
        if (knew - 1 >= 2 && W[knew - 1] < 0.8 * W[knew]) knew--;
        b->k = knew;
        /* Rows that had not converged can still predict a longer step when
         * round-off dominates; never retry with a step that is not shorter. */
        o->h = dir * fmin(fabs(Hopt[knew]), 0.9 * fabs(H));
      }
    }
  }
  return SICM_SUCCESS;
}

const sicm_ode_step_type sicm_ode_bs_type = {"bulirsch-stoer", bs_init, bs_evolve, bs_reset,
                                             bs_free,          NULL,    NULL};
