/* scmutils' quality-controlled methods: RK4 (qcrk4) and the trapezoid rule (qcctrap2), each
 * made adaptive by step doubling with local extrapolation.
 *
 * Approach. scmutils (numerics/ode/qc.scm, "quality-control") makes an
 * adaptive method of a one-step method of order p as in Numerical Recipes
 * (section 16.2): every step of size h is taken twice, once whole, giving
 * y1, and once as two halves, giving y2. The error of y2 is about
 * (y2 - y1) / (2^p - 1), so the step returns the extrapolated
 *
 *     y2 + (y2 - y1) / (2^p - 1),
 *
 * in which the leading error terms of the two results cancel: the local
 * error drops from O(h^(p+1)) to O(h^(p+2)).
 *
 * Error measure. What is compared with the tolerance is the difference
 * y2 - y1 itself, not the smaller error of the extrapolated result, and it
 * is measured as scmutils measures it (its max-norm, advance.scm), relative
 * to the size of the component:
 *
 *     err = max_i |y2_i - y1_i| / (rel_tol ((|y2_i| + |y1_i|) / 2 + 1e-10)),
 *
 * where 1e-10 (scmutils' *norm-breakpoint*) is the size below which the
 * measure turns absolute. abs_tol plays no part, except that with
 * rel_tol = 0 the measure is purely absolute, |y2_i - y1_i| / abs_tol.
 * evolve's single "local error" eps (both tolerances) thus means what it
 * means in scmutils. A step is accepted when err <= 2 (scmutils' dead zone
 * around 1); the extrapolated result's error is then far below the
 * tolerance (for RK4, y2 alone is within 2 eps / 15 relative).
 *
 * Step control, scmutils' own. After every try, accepted or not, the next
 * step is 0.9 h max(err, 1e-20)^(-1/(p+1)), the step that would bring err
 * to 1, with no bound on the growth (scmutils bounds it only by the
 * interval of the call). A try that fails, because a value became
 * non-finite or (qcctrap2) the corrector did not converge, is retried with
 * 0.3 h if the first half failed and 0.5 h otherwise. The first step is the
 * whole interval to t1, as scmutils' advancer first tries the caller's dt.
 * Unlike scmutils, which starts each call at its dt again, the step size is
 * kept between calls; a step shortened to land on t1 and accepted at its
 * first try leaves it alone, since a short step's error says little about
 * the longer one.
 *
 * The methods.
 *   qcrk4     classical fourth-order Runge-Kutta, p = 4. f at the start of a
 *             step is shared by the first half and the whole step: 11 rhs
 *             evaluations per accepted step, 10 per rejected try.
 *   qcctrap2  the trapezoid rule y' = y + h/2 (f(y) + f(y')), p = 2, solved
 *             as scmutils' c-trapezoid does, by corrector iteration from an
 *             Euler predictor: iterates until two successive ones differ by
 *             less than 2 in the error measure with a tenth of the tolerance
 *             (scmutils' *corrector-convergence-margin*); it fails when an
 *             iterate does not come closer than the one before.
 *
 * Limits. The corrector iteration converges only for h |lambda| < 2, lambda
 * the fastest rate of the system, so qcctrap2, though implicit, is no
 * better than an explicit method on stiff problems; both are watched for
 * stiffness like the explicit methods (ode_stiffness.c) and point to
 * cvode-bdf. Both are of low order, so their steps shrink with the
 * tolerance as eps^(1/(p+1)): at tight tolerances they take many more steps
 * than Bulirsch-Stoer or rk8pd, qcctrap2 by far the most. The relative measure makes a component
 * that passes through zero hold the step for a while, as in scmutils. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_internal.h"

/* scmutils' constants (qc.scm, advance.scm, ode-advancer.scm). */
static const double kBreakpoint = 1e-10;       /* *norm-breakpoint* */
static const double kAcceptable = 2.0;         /* the dead zone: accept err <= 2 */
static const double kDamping = 0.9;            /* qc-damping */
static const double kZeroProtect = 1e-20;      /* qc-zero-protect */
static const double kFirstHalfReduction = 0.3; /* *qc-halfstep-reduction-factor* */
static const double kReduction = 0.5;          /* second half or whole step failed */
static const double kCorrectorMargin = 0.1;    /* *corrector-convergence-margin* */

/* The two results compared differ by a few units in the last place from
 * rounding alone, about 1e-15 of their size, which a relative tolerance
 * below this cannot accept: a failure then says so (scmutils would shrink
 * the step for ever). */
static const double kRoundingTolerance = 1e-15;

/* A bound scmutils does not have: corrector iterations of one trapezoid
 * step. Each iterate must come closer than the last, so only a contraction
 * near 1 (h |lambda| near 2) gets here; giving up retries a shorter step,
 * where the contraction is faster. */
enum { kMaxCorrections = 100 };

typedef struct qc_state qc_state;

/* A one-step method: from (t, y), whose derivative is f, a step of size h
 * into out (not aliasing y). Returns SICM_SUCCESS, SICM_EUSER, SICM_EBADFUNC
 * (a non-finite value) or SICM_ECONV (a corrector that did not converge). */
typedef int (*qc_step)(sicm_ode *o, qc_state *b, double t, const double *y, const double *f,
                       double h, double *out);

typedef struct {
  qc_step step;
  int order;
  sicm_ode_stability stability; /* of the extrapolated step, for the stiffness watch */
} qc_method;

struct qc_state {
  const qc_method *method;
  int f0_valid; /* f0 = f(t, y) at the current point */
  double *f0, *ym, *fm, *y2, *y1;
  double *work; /* 4 dim: the one-step method's scratch */
};

/* The error measure above, of the difference between results a and b, with
 * the tolerances multiplied by margin. A NaN anywhere gives NaN. */
static double qc_error(const sicm_ode *o, const double *a, const double *b, double margin) {
  double m = 0;
  for (size_t i = 0; i < o->dim; i++) {
    const double scale =
        o->rel_tol > 0 ? o->rel_tol * (0.5 * (fabs(a[i]) + fabs(b[i])) + kBreakpoint) : o->abs_tol;
    const double r = fabs(a[i] - b[i]) / (margin * scale);
    if (!(r <= m)) m = r;
  }
  return m;
}

/* ---- the one-step methods --------------------------------------------- */

static int rk4_step(sicm_ode *o, qc_state *b, double t, const double *y, const double *f, double h,
                    double *out) {
  const size_t n = o->dim;
  double *k2 = b->work, *k3 = k2 + n, *k4 = k3 + n, *yt = k4 + n;
  for (size_t i = 0; i < n; i++)
    yt[i] = y[i] + 0.5 * h * f[i];
  int s = sicm_ode_call_rhs(o, t + 0.5 * h, yt, k2);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < n; i++)
    yt[i] = y[i] + 0.5 * h * k2[i];
  s = sicm_ode_call_rhs(o, t + 0.5 * h, yt, k3);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < n; i++)
    yt[i] = y[i] + h * k3[i];
  s = sicm_ode_call_rhs(o, t + h, yt, k4);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < n; i++)
    out[i] = y[i] + h / 6 * (f[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  return SICM_SUCCESS;
}

/* The trapezoid rule by corrector iteration: x_0 = y + h f (Euler), then
 * x_{k+1} = y + h/2 (f + f(t + h, x_k)) until |x_{k+1} - x_k| is small. */
static int trapezoid_step(sicm_ode *o, qc_state *b, double t, const double *y, const double *f,
                          double h, double *out) {
  const size_t n = o->dim;
  double *prev = b->work, *next = prev + n, *fx = next + n;
  for (size_t i = 0; i < n; i++)
    prev[i] = y[i] + h * f[i];
  double change = INFINITY;
  for (int k = 0; k < kMaxCorrections; k++) {
    int s = sicm_ode_call_rhs(o, t + h, prev, fx);
    if (s != SICM_SUCCESS) return s;
    for (size_t i = 0; i < n; i++)
      next[i] = y[i] + 0.5 * h * (f[i] + fx[i]);
    const double c = qc_error(o, prev, next, kCorrectorMargin);
    if (c < kAcceptable) {
      memcpy(out, next, n * sizeof *out);
      return SICM_SUCCESS;
    }
    if (!(c < change)) return SICM_ECONV; /* not coming closer (or NaN) */
    change = c;
    double *tmp = prev;
    prev = next;
    next = tmp;
  }
  return SICM_ECONV;
}

/* Stability of the extrapolated steps (sicm_ode_stability), from their
 * stability functions on y' = lambda y, z = h lambda: with R1 that of the
 * one-step method, R(z) = R1(z/2)^2 + (R1(z/2)^2 - R1(z)) / (2^p - 1),
 * scanned along each axis in steps of 1e-3 until |R| first exceeds 1 + 1e-3.
 * qcrk4: 6.46 on the negative real axis, 1.38 on the imaginary axis (where
 * |R| exceeds 1 slightly for any step: 1 + 2e-4 at 1). qcctrap2: the
 * extrapolated trapezoid rule is stable on the real axis to 25.9 and on the
 * imaginary axis to 1.09, but its corrector iteration converges only for
 * |z| < 2, which bounds the real axis. */
static const qc_method kRk4 = {rk4_step, 4, {6.46, 1.38}};
static const qc_method kTrapezoid = {trapezoid_step, 2, {2.0, 1.09}};

/* ---- the quality-control driver ---------------------------------------- */

static int qc_init(sicm_ode *o) {
  qc_state *b = calloc(1, sizeof *b);
  if (!b) return SICM_ENOMEM;
  o->backend = b;
  b->method = o->type->data;
  const size_t n = o->dim;
  b->f0 = malloc(9 * n * sizeof *b->f0);
  if (!b->f0) return SICM_ENOMEM;
  b->ym = b->f0 + n;
  b->fm = b->ym + n;
  b->y2 = b->fm + n;
  b->y1 = b->y2 + n;
  b->work = b->y1 + n;
  return SICM_SUCCESS;
}

static void qc_free(sicm_ode *o) {
  qc_state *b = o->backend;
  if (!b) return;
  free(b->f0);
  free(b);
}

static void qc_reset(sicm_ode *o) {
  qc_state *b = o->backend;
  b->f0_valid = 0;
}

/* One try of a step of size h from (t, y), whose derivative is b->f0: in
 * two halves into b->y2, whole into b->y1. On failure *first_half says
 * whether the first half failed. */
static int qc_try(sicm_ode *o, qc_state *b, double t, const double *y, double h, int *first_half) {
  const qc_step step = b->method->step;
  *first_half = 1;
  int s = step(o, b, t, y, b->f0, 0.5 * h, b->ym);
  if (s != SICM_SUCCESS) return s;
  *first_half = 0;
  s = sicm_ode_call_rhs(o, t + 0.5 * h, b->ym, b->fm);
  if (s == SICM_SUCCESS) s = step(o, b, t + 0.5 * h, b->ym, b->fm, 0.5 * h, b->y2);
  if (s == SICM_SUCCESS) s = step(o, b, t, y, b->f0, h, b->y1);
  return s;
}

/* The step that would bring the error measure of a step h to 1. */
static double qc_adjust(const qc_method *m, double h, double err) {
  return kDamping * h * pow(fmax(err, kZeroProtect), -1.0 / (m->order + 1));
}

/* The failure when the step has shrunk below the resolution of t; last is
 * the status of the last failed try (SICM_SUCCESS: its error was too big). */
static int qc_fail_step(sicm_ode *o, double t, const double *y, double h, int last) {
  char detail[240];
  if (last == SICM_EBADFUNC)
    return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite derivative",
                         "the right-hand side is NaN or infinite for every step size down to "
                         "the resolution of t");
  if (last == SICM_ECONV) {
    snprintf(detail, sizeof detail,
             "the trapezoid rule's corrector iteration does not converge even for the "
             "shortest step the resolution of t allows (h = %.3g); the tolerance may be below "
             "the rounding errors of the iterates (%.0g and less)",
             h, 10 * kRoundingTolerance);
    return sicm_ode_fail(o, SICM_ECONV, t, y, "corrector did not converge", detail);
  }
  if (o->rel_tol > 0 && o->rel_tol < kRoundingTolerance)
    snprintf(detail, sizeof detail,
             "the error test fails even for the shortest step the resolution of t allows "
             "(h = %.3g); a relative tolerance of %.3g is below the rounding errors of the "
             "results compared, so it cannot be met: ask for %.0g or more",
             h, o->rel_tol, kRoundingTolerance);
  else
    snprintf(detail, sizeof detail,
             "the error test fails even for the shortest step the resolution of t allows "
             "(h = %.3g); the solution may be singular here",
             h);
  return sicm_ode_fail(o, SICM_ESTEP, t, y, "step size too small", detail);
}

static int qc_evolve(sicm_ode *o, double *t, double t1, double *y) {
  qc_state *b = o->backend;
  const qc_method *m = b->method;
  const size_t n = o->dim;
  const double weight = 1.0 / (ldexp(1.0, m->order) - 1); /* 1 / (2^p - 1) */
  if (o->h == 0) o->h = t1 - *t;
  int after_reject = 0, last_failure = SICM_SUCCESS;
  unsigned long steps = 0;
  while (*t != t1) {
    if (!b->f0_valid) {
      int s = sicm_ode_start_derivative(o, *t, y, b->f0);
      if (s != SICM_SUCCESS) return s;
      b->f0_valid = 1;
    }
    if (steps >= o->max_steps) return sicm_ode_fail_max_steps(o, *t, y);
    const int final = fabs(o->h) >= fabs(t1 - *t);
    const double h = final ? t1 - *t : o->h;
    const int shortened = final && fabs(h) < fabs(o->h);
    if (*t + h == *t || fabs(h) < 16 * DBL_EPSILON * fabs(*t))
      return qc_fail_step(o, *t, y, h, last_failure);

    int first_half;
    int s = qc_try(o, b, *t, y, h, &first_half);
    if (s == SICM_EUSER) return sicm_ode_fail_user(o, *t, y);
    const double err = s == SICM_SUCCESS ? qc_error(o, b->y2, b->y1, 1.0) : NAN;
    if (s != SICM_SUCCESS || !(err <= kAcceptable)) {
      o->stats.rejected_steps++;
      after_reject = 1;
      if (s == SICM_SUCCESS && isfinite(err)) {
        last_failure = SICM_SUCCESS;
        o->h = qc_adjust(m, h, err);
      } else {
        last_failure = s == SICM_SUCCESS ? SICM_EBADFUNC : s;
        o->h = h * (first_half && s != SICM_SUCCESS ? kFirstHalfReduction : kReduction);
      }
      continue;
    }

    for (size_t i = 0; i < n; i++)
      y[i] = b->y2[i] + (b->y2[i] - b->y1[i]) * weight;
    *t = final ? t1 : *t + h;
    b->f0_valid = 0;
    steps++;
    o->stats.steps++;
    if (!(shortened && !after_reject)) o->h = qc_adjust(m, h, err);
    after_reject = 0;
    s = sicm_ode_watch_stiffness(o, *t, y, h, t1, m->stability);
    if (s != SICM_SUCCESS) return s;
  }
  return SICM_SUCCESS;
}

const sicm_ode_step_type sicm_ode_qcrk4_type = {"qcrk4", qc_init, qc_evolve, qc_reset,
                                                qc_free, &kRk4,   NULL};
const sicm_ode_step_type sicm_ode_qcctrap2_type = {"qcctrap2", qc_init,     qc_evolve, qc_reset,
                                                   qc_free,    &kTrapezoid, NULL};
