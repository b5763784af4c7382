/* Events located inside the integrator: sign changes of functions of the solution, bracketed on
 * each step's Hermite interpolant and placed on the solution itself by Brent's method (see
 * sicm_ode_set_events in sicm/ode.h). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "ode_internal.h"

/* Brent's method converges only linearly on a root of odd multiplicity
 * above 1 ((t - 1)^3): from a sample's interval to a few ulps takes it
 * some 150 iterations. On the interpolant they cost little; on the
 * solution each is an integration, and its bracket is narrow already. */
enum {
  kSamples = SICM_ODE_EVENT_SAMPLES,
  kMaxBrentIterations = 100,
  kMaxBrentIterationsInterpolant = 400,
  kGrowth = 4
};
static const double kDenseShare = 0.9;

/* A located crossing waiting to be placed: event k changes sign between
 * samples lo and hi of the step, in direction dir; tau is its time on the
 * interpolant. */
typedef struct {
  size_t k;
  int lo, hi, dir;
  double tau;
  double s; /* tau - ta, as found: late in a long run tau rounds to an ulp of t */
} candidate;

/* One step's data, and the trial points of the crossing being placed. */
typedef struct {
  sicm_ode *o;
  double ta, tb;
  const double *ya, *fa, *yb, *fb;
  size_t k;        /* the event being placed */
  double *y_trial; /* the solution at the last trial time, s_trial, if have_trial */
  double s_trial;
  int have_trial;
  int located;    /* an event was located in this step */
  int dense;      /* the method's own continuous output spans the step */
  double *y_best; /* at the trial where |g| was smallest */
  double s_best, g_best;
  int have_best;
  int status;        /* the first failure of a trial integration */
  double cache_s[2]; /* the bracket's ends, already evaluated */
  double cache_g[2];
  int cached;
} step_data;

/* Scratch in o->event_work: ya, fa, fb, y_interp, y_trial, y_best, f_mid (dim each), the
 * interpolant's coefficients (kSlotsCoefficients * dim); g at the samples
 * (event_count * (kSamples + 1)); candidates after them. */
enum { kSlotMid = 6, kSlotCoefficients = 7, kCoefficients = 6, kSlots = 13 };
static double *work_slot(sicm_ode *o, int slot) {
  return o->event_work + (size_t)slot * o->dim;
}
static double *sample_values(sicm_ode *o) {
  return o->event_work + kSlots * o->dim;
}
static candidate *candidates(sicm_ode *o) {
  return (candidate *)(void *)(sample_values(o) + o->event_count * (kSamples + 1));
}

void sicm_ode_free_events(sicm_ode *o) {
  free(o->events);
  free(o->event_sign);
  free(o->event_sign_scratch);
  free(o->event_y_last);
  free(o->event_work);
  sicm_ode_free(o->event_solver);
  o->events = NULL;
  o->event_sign = NULL;
  o->event_sign_scratch = NULL;
  o->event_y_last = NULL;
  o->event_work = NULL;
  o->event_solver = NULL;
  o->event_count = 0;
  o->have_event_last = 0;
}

int sicm_ode_set_events(sicm_ode *o, const sicm_ode_event *events, size_t n,
                        sicm_ode_event_handler handler, void *data) {
  for (size_t k = 0; k < n; k++)
    if (!events[k].g || events[k].direction < SICM_ODE_EVENT_UP ||
        events[k].direction > SICM_ODE_EVENT_BOTH)
      return sicm_error(SICM_EINVAL, "sicm_ode_set_events (%s): event %zu has %s", o->type->name, k,
                        events[k].g ? "no valid direction" : "no function");
  sicm_ode_free_events(o);
  o->event_handler = handler;
  o->event_data = data;
  if (n == 0) return SICM_SUCCESS;
  const size_t doubles = kSlots * o->dim + n * (kSamples + 1);
  o->events = malloc(n * sizeof *o->events);
  o->event_sign = calloc(n, sizeof *o->event_sign);
  o->event_sign_scratch = calloc(n, sizeof *o->event_sign_scratch);
  o->event_y_last = malloc(o->dim * sizeof *o->event_y_last);
  o->event_work = malloc(doubles * sizeof(double) + n * kSamples * sizeof(candidate));
  if (!o->events || !o->event_sign || !o->event_sign_scratch || !o->event_y_last ||
      !o->event_work) {
    sicm_ode_free_events(o);
    return sicm_error(SICM_ENOMEM, "sicm_ode_set_events (%s): out of memory", o->type->name);
  }
  memcpy(o->events, events, n * sizeof *events);
  o->event_count = n;
  return SICM_SUCCESS;
}

long sicm_ode_stopping_event(const sicm_ode *o) {
  return o->stopping_event;
}

const sicm_ode_event_stats *sicm_ode_get_event_stats(const sicm_ode *o) {
  return &o->event_stats;
}

/* ---- the solver that places events ------------------------------------ */

/* It integrates from a step's start in time relative to it, s = t - ta, so
 * that a crossing is placed to the resolution of s, not of t (at t = 1e4 an
 * ulp of t is 2e-12, and the state would miss the crossing by that times its
 * speed). The system sees t = ta + s. */
static int shifted_rhs(double s, const double *y, double *dydt, void *params) {
  sicm_ode *o = params;
  return o->f(o->event_t0 + s, y, dydt, o->params);
}

static int shifted_jacobian(double s, const double *y, double *dfdy, double *dfdt, void *params) {
  sicm_ode *o = params;
  return o->jac(o->event_t0 + s, y, dfdy, dfdt, o->params);
}

static int make_solver(sicm_ode *o) {
  if (o->event_solver) return SICM_SUCCESS;
  sicm_ode *s = sicm_ode_alloc(o->type, o->dim, shifted_rhs, o, o->abs_tol, o->rel_tol);
  if (!s) return SICM_ENOMEM;
  if (o->jac) sicm_ode_set_jacobian(s, shifted_jacobian);
  if (o->taylor) sicm_ode_set_taylor(s, o->taylor, o->taylor_params);
  if (o->taylor_extended) sicm_ode_set_taylor_extended(s, o->taylor_extended, o->taylor_params);
  s->max_steps = o->max_steps;
  o->event_solver = s;
  return SICM_SUCCESS;
}

/* y_trial becomes the solution at ta + s, integrated from the step's start
 * or from the last trial time, whichever is nearer (d->s_trial, when
 * d->have_trial): the trials of Brent's method close in on the crossing,
 * and from the last of them the next is a short integration, a few
 * evaluations of the system rather than a step's worth. The first step is
 * as long as the main integration's step (the method shortens it to the
 * span). */
static int solve_at(step_data *d, double s) {
  sicm_ode *o = d->o, *solver = o->event_solver;
  double t = 0;
  if (d->have_trial && fabs(s - d->s_trial) < fabs(s)) {
    t = d->s_trial;
  } else {
    memcpy(d->y_trial, d->ya, o->dim * sizeof *d->ya);
  }
  d->have_trial = 0;
  if (s == t) return SICM_SUCCESS;
  sicm_ode_reset(solver);
  solver->h = d->tb - d->ta;
  const unsigned long rhs0 = solver->stats.rhs_evals;
  o->event_stats.iterations++;
  int status = sicm_ode_evolve_plain(solver, &t, s, d->y_trial);
  o->stats.rhs_evals += solver->stats.rhs_evals - rhs0;
  if (status == SICM_EUSER) o->user_status = solver->user_status;
  if (status == SICM_SUCCESS) d->have_trial = 1, d->s_trial = s;
  return status;
}

static int sign_of(double g) {
  return g > 0 ? 1 : g < 0 ? -1 : 0;
}

static double event_value(sicm_ode *o, size_t k, double t, const double *y) {
  return o->events[k].g(t, y, o->events[k].params);
}

/* g of the event being placed on the solution at ta + s (NaN after a
 * failure, kept in d->status); the trial with the smallest |g| is kept. */
static double solution_value(double s, void *params) {
  step_data *d = params;
  for (int i = 0; i < d->cached; i++)
    if (d->cache_s[i] == s) return d->cache_g[i];
  if (d->status != SICM_SUCCESS) return NAN;
  d->status = solve_at(d, s);
  if (d->status != SICM_SUCCESS) return NAN;
  const double g = event_value(d->o, d->k, d->ta + s, d->y_trial);
  if (!isfinite(g)) {
    d->status = SICM_EBADFUNC;
    return NAN;
  }
  if (!d->have_best || fabs(g) < fabs(d->g_best)) {
    d->have_best = 1;
    d->s_best = s;
    d->g_best = g;
    memcpy(d->y_best, d->y_trial, d->o->dim * sizeof *d->y_trial);
  }
  return g;
}

/* ---- the interpolant ----------------------------------------------------- */

/* The step's interpolant: the quintic through the states at the step's
 * start, middle and end with the derivatives there (the middle state
 * integrated from the start, as a trial is), in Newton's form over the
 * nodes 0, 0, 1/2, 1/2, 1, 1 of theta = s / h. Its error is O(h^6): a
 * cubic through the ends alone, O(h^4), is off by 1e-3 of a Bulirsch-Stoer
 * step of half a time unit, enough to misplace a crossing by a sample. */
static int fit_interpolant(step_data *d) {
  sicm_ode *o = d->o;
  const double h = d->tb - d->ta;
  double *fm = work_slot(o, kSlotMid), *c = work_slot(o, kSlotCoefficients);
  int status = solve_at(d, 0.5 * h);
  if (status != SICM_SUCCESS) return status;
  status = sicm_ode_call_rhs(o, d->ta + 0.5 * h, d->y_trial, fm);
  if (status == SICM_EUSER) return status;
  if (status != SICM_SUCCESS) return SICM_EBADFUNC;
  static const double z[kCoefficients] = {0, 0, 0.5, 0.5, 1, 1};
  for (size_t i = 0; i < o->dim; i++) {
    double q[kCoefficients];
    q[0] = d->ya[i], q[1] = d->ya[i], q[2] = d->y_trial[i], q[3] = d->y_trial[i];
    q[4] = d->yb[i], q[5] = d->yb[i];
    /* First divided differences: derivatives at repeated nodes. */
    const double slope[kCoefficients] = {0,         h * d->fa[i],        (q[2] - q[1]) / 0.5,
                                         h * fm[i], (q[4] - q[3]) / 0.5, h * d->fb[i]};
    double col[kCoefficients];
    for (int j = 1; j < kCoefficients; j++)
      col[j] = slope[j];
    c[i * kCoefficients + 0] = q[0];
    c[i * kCoefficients + 1] = col[1];
    for (int order = 2; order < kCoefficients; order++) {
      for (int j = kCoefficients - 1; j >= order; j--)
        col[j] = (col[j] - col[j - 1]) / (z[j] - z[j - order]);
      c[i * kCoefficients + order] = col[order];
    }
  }
  return SICM_SUCCESS;
}

/* ---- the screen: steps far from every event ----------------------------------- */

/* The cubic Hermite interpolant of the step's ends (states and derivatives,
 * which the step has computed already) at theta = s / h into y, and its
 * derivative in t into dy (unless NULL). */
static void cubic(const step_data *d, double theta, double *y, double *dy) {
  const double h = d->tb - d->ta, u = 1 - theta;
  const double h00 = (1 + 2 * theta) * u * u, h10 = theta * u * u,
               h01 = theta * theta * (3 - 2 * theta), h11 = -theta * theta * u;
  const double d00 = -6 * theta * u, d10 = u * (1 - 3 * theta), d11 = theta * (3 * theta - 2);
  for (size_t i = 0; i < d->o->dim; i++) {
    y[i] = h00 * d->ya[i] + h10 * h * d->fa[i] + h01 * d->yb[i] + h11 * h * d->fb[i];
    if (dy) dy[i] = d00 * (d->ya[i] - d->yb[i]) / h + d10 * d->fa[i] + d11 * d->fb[i];
  }
}

/* Is the step clearly free of events, so that the quintic (an integration
 * to the step's middle: about one step more) is not needed? The cubic
 * through the ends is off the solution by e(theta) = y^(4) h^4 theta^2
 * (1 - theta)^2 / 24, and its defect (the system's derivative at the cubic
 * less the cubic's derivative) at theta = 1/4 is e'(1/4) / h = y^(4) h^3
 * (3/16) / 24: three times the largest error (at theta = 1/2, h^4 y^(4) / 384)
 * over h. So h |defect(1/4)| / 3 estimates the cubic's error, for one
 * evaluation of the system. The step is free when every event has the
 * sign it had, not 0, at the 8 sample points of the cubic after the start,
 * by a margin of what 8 times that error vector moves the event at the
 * middle, but for changes of sign in a direction not asked for (then the
 * solution changes sign there too, and that is all). Else the step is
 * searched on the quintic, as every step was before this screen.
 * Of the Henon-Heiles section's steps (rk8pd at 1e-14) some 97% are
 * free: the events cost 1.1 times the plain integration instead of 2.4. */
static int step_is_free(step_data *d) {
  sicm_ode *o = d->o;
  const size_t n = o->event_count;
  const double h = d->tb - d->ta;
  double *y = work_slot(o, 3), *moved = work_slot(o, 4), *f = work_slot(o, kSlotMid);
  for (size_t k = 0; k < n; k++)
    if (o->event_sign[k] == 0) return 0;
  cubic(d, 0.25, y, moved);
  if (sicm_ode_call_rhs(o, d->ta + 0.25 * h, y, f) != SICM_SUCCESS) return 0;
  for (size_t i = 0; i < o->dim; i++)
    f[i] = 8 * fabs(h) * (f[i] - moved[i]) / 3; /* 8 times the error, in the defect's direction */
  cubic(d, 0.5, y, NULL);
  for (size_t i = 0; i < o->dim; i++)
    moved[i] = y[i] + f[i];
  /* Each event's margin, then each sample of the cubic once for all the
   * events (the samples' slots are free until the search). */
  int *last = o->event_sign_scratch;
  double *margin = sample_values(o);
  const double tm = d->ta + 0.5 * h;
  for (size_t k = 0; k < n; k++) {
    margin[k] = fabs(event_value(o, k, tm, moved) - event_value(o, k, tm, y));
    if (!isfinite(margin[k])) return 0;
    last[k] = o->event_sign[k];
  }
  for (int j = 1; j <= kSamples; j++) {
    const double *yj = d->yb;
    double tj = d->tb;
    if (j < kSamples) {
      cubic(d, (double)j / kSamples, y, NULL);
      yj = y;
      tj = d->ta + j * h / kSamples;
    }
    for (size_t k = 0; k < n; k++) {
      const double g = event_value(o, k, tj, yj);
      if (!isfinite(g) || fabs(g) <= margin[k]) return 0;
      /* A change of sign in the direction asked for needs the search; one
       * the other way only changes the sign the next step starts from. */
      if (sign_of(g) != last[k] &&
          (o->events[k].direction & (g > 0 ? SICM_ODE_EVENT_UP : SICM_ODE_EVENT_DOWN)))
        return 0;
      last[k] = sign_of(g);
    }
  }
  memcpy(o->event_sign, last, n * sizeof *last);
  return 1;
}

/* The interpolant of the step at ta + s into y. */
static void interpolate(const step_data *d, double s, double *y) {
  const double h = d->tb - d->ta, theta = s / h;
  if (s == 0 || s == h) {
    memcpy(y, s == 0 ? d->ya : d->yb, d->o->dim * sizeof *y);
    return;
  }
  if (d->dense) {
    d->o->type->dense(d->o, d->ta, d->tb, s, y);
    return;
  }
  const double *c = work_slot(d->o, kSlotCoefficients);
  static const double z[kCoefficients] = {0, 0, 0.5, 0.5, 1, 1};
  for (size_t i = 0; i < d->o->dim; i++) {
    const double *ci = c + i * kCoefficients;
    double v = ci[kCoefficients - 1];
    for (int j = kCoefficients - 2; j >= 0; j--)
      v = ci[j] + (theta - z[j]) * v;
    y[i] = v;
  }
}

static double interpolant_value(double s, void *params) {
  step_data *d = params;
  double *y = work_slot(d->o, 3);
  interpolate(d, s, y);
  return event_value(d->o, d->k, d->ta + s, y);
}

/* Brent's method on f over [lo, hi] (f(lo), f(hi) of opposite signs) to a
 * bracket of a few ulps of s; returns its last estimate. */
static double brent(double (*f)(double, void *), void *params, double lo, double hi, double h,
                    int iterations, const int *failed) {
  gsl_root_fsolver *solver = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  if (!solver) return 0.5 * (lo + hi);
  gsl_function F = {f, params};
  double root = 0.5 * (lo + hi);
  if (gsl_root_fsolver_set(solver, &F, fmin(lo, hi), fmax(lo, hi)) == GSL_SUCCESS) {
    for (int i = 0; i < iterations && !(failed && *failed); i++) {
      if (gsl_root_fsolver_iterate(solver) != GSL_SUCCESS) break;
      root = gsl_root_fsolver_root(solver);
      const double a = gsl_root_fsolver_x_lower(solver), b = gsl_root_fsolver_x_upper(solver);
      if (gsl_root_test_interval(a, b, 1e-3 * DBL_EPSILON * fabs(h), 2 * DBL_EPSILON) ==
          GSL_SUCCESS)
        break;
    }
  }
  gsl_root_fsolver_free(solver);
  return root;
}

/* Places candidate c on the solution: d->s_best and d->y_best. The
 * interpolant's root tau starts the search; a Newton step from it on the
 * interpolant's slope usually gives, with tau, a bracket a few ulps wide on
 * the solution; else the samples' bracket does; and if the solution does
 * not change sign between the samples (the interpolant was off), the
 * solution at tau is taken. */
/* The direction of the crossing between values g_a at s_a and g_b at s_b
 * of opposite signs: later is further from the step's start, whichever way
 * the integration runs (s has the sign of the step). */
static int direction_between(double s_a, double g_a, double s_b, double g_b) {
  const double later = fabs(s_b) > fabs(s_a) ? g_b : g_a;
  return later > 0 ? SICM_ODE_EVENT_UP : SICM_ODE_EVENT_DOWN;
}

/* When the solution does not change sign where the interpolant does: the
 * change of sign of the solution in the candidate's direction nearest to
 * tau among the step's sample times, in [*lo, *hi] with their values;
 * 0 if there is none (the interpolant's crossing was an artefact of its
 * error: a graze, which the solution does not make). */
static int scan_solution(step_data *d, const candidate *c, double s0, double *lo, double *g_lo,
                         double *hi, double *g_hi) {
  const double h = d->tb - d->ta;
  const double *g = sample_values(d->o) + c->k * (kSamples + 1);
  double s_prev = 0, g_prev = g[0], best = INFINITY;
  int found = 0;
  for (int j = 1; j <= kSamples; j++) {
    const double sj = j == kSamples ? h : j * h / kSamples;
    const double gj = j == kSamples ? g[kSamples] : solution_value(sj, d);
    if (d->status != SICM_SUCCESS) return 0;
    if (gj == 0) continue;
    if (g_prev != 0 && sign_of(gj) != sign_of(g_prev) &&
        direction_between(s_prev, g_prev, sj, gj) == c->dir &&
        fabs(0.5 * (s_prev + sj) - s0) < best) {
      best = fabs(0.5 * (s_prev + sj) - s0);
      *lo = s_prev, *g_lo = g_prev, *hi = sj, *g_hi = gj;
      found = 1;
    }
    s_prev = sj, g_prev = gj;
  }
  return found;
}

/* Places candidate c on the solution: d->s_best and d->y_best; returns the
 * status, or kNoCrossing. The interpolant's root tau starts the search; a
 * Newton step from it on the interpolant's slope usually gives, with tau, a
 * bracket a few ulps wide on the solution; else the samples' bracket does;
 * else the solution is sampled itself (scan_solution). */
enum { kNoCrossing = -1 };
static int place(step_data *d, const candidate *c) {
  const double h = d->tb - d->ta;
  if (d->dense) {
    /* The method's own polynomial is its solution over the step: the
     * crossing is its root, tau, found already. */
    d->k = c->k;
    d->s_best = c->s;
    interpolate(d, d->s_best, d->y_best);
    d->have_best = 1;
    d->status = SICM_SUCCESS;
    return SICM_SUCCESS;
  }
  const double s_lo = (double)c->lo / kSamples * h,
               s_hi = c->hi == kSamples ? h : c->hi * h / kSamples;
  const double s0 = c->s;
  d->k = c->k;
  d->have_best = 0;
  d->cached = 0;
  d->status = SICM_SUCCESS;
  const double g0 = solution_value(s0, d);
  if (d->status != SICM_SUCCESS || g0 == 0) return d->status;
  /* The slope of g on the interpolant at tau. */
  const double e = 1e-7 * h;
  const double slope = (interpolant_value(s0 + e, d) - interpolant_value(s0 - e, d)) / (2 * e);
  double lo = s_lo, hi = s_hi, g_lo = NAN, g_hi = NAN;
  if (slope != 0 && isfinite(slope)) {
    const double s1 = fmin(fmax(s0 - 2 * g0 / slope, fmin(s_lo, s_hi)), fmax(s_lo, s_hi));
    const double g1 = solution_value(s1, d);
    if (d->status != SICM_SUCCESS || g1 == 0) return d->status;
    if (sign_of(g1) != sign_of(g0) && direction_between(s0, g0, s1, g1) == c->dir) {
      lo = s0, g_lo = g0, hi = s1, g_hi = g1;
    }
  }
  if (isnan(g_lo)) {
    g_lo = solution_value(s_lo, d);
    g_hi = solution_value(s_hi, d);
    if (d->status != SICM_SUCCESS) return d->status;
    if (g_lo == 0 || g_hi == 0) return SICM_SUCCESS; /* on a sample: the best trial */
    if (sign_of(g_lo) == sign_of(g_hi) || direction_between(s_lo, g_lo, s_hi, g_hi) != c->dir) {
      if (!scan_solution(d, c, s0, &lo, &g_lo, &hi, &g_hi))
        return d->status != SICM_SUCCESS ? d->status : kNoCrossing;
    } else if (sign_of(g0) == sign_of(g_lo)) {
      lo = s0, g_lo = g0;
    } else {
      hi = s0, g_hi = g0;
    }
  }
  d->have_best = 0; /* the crossing is in [lo, hi]: only trials there count */
  d->cache_s[0] = lo, d->cache_g[0] = g_lo;
  d->cache_s[1] = hi, d->cache_g[1] = g_hi;
  d->cached = 2;
  brent(solution_value, d, lo, hi, h, kMaxBrentIterations, &d->status);
  if (d->status == SICM_SUCCESS && !d->have_best) {
    /* Brent evaluated nothing new: the bracket was already tight; take
     * the end with the smaller |g|. */
    d->cached = 0;
    solution_value(fabs(g_lo) <= fabs(g_hi) ? lo : hi, d);
  }
  return d->status;
}

static int compare_candidates(const void *a, const void *b) {
  const candidate *x = a, *y = b;
  return x->tau < y->tau ? -1 : x->tau > y->tau ? 1 : x->k < y->k ? -1 : x->k > y->k;
}

static int fail_event(sicm_ode *o, double t, const double *y, size_t k) {
  char detail[120];
  snprintf(detail, sizeof detail, "event function %zu is NaN or infinite here", k);
  return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite event function", detail);
}

/* Looks for the events of the step [ta, tb] the integration has just taken
 * ((t, y) is its end): each is handled in time order; one that stops the
 * integration leaves its time and state in (*t, y) and sets
 * o->stopping_event. */
static int events_of_step(step_data *d, double *t, double *y) {
  sicm_ode *o = d->o;
  const size_t n = o->event_count;
  const double h = d->tb - d->ta;
  double *g = sample_values(o);
  double *yi = work_slot(o, 3);
  d->have_trial = 0; /* y_trial is the screen's scratch, and the last step's */
  /* The Taylor methods' steps are polynomials: the events are found on
   * them, with no screen, interpolant or trial integration. */
  d->dense = o->type->dense && o->type->dense(o, d->ta, d->tb, 0, NULL) == SICM_SUCCESS;
  if (!d->dense) {
    if (step_is_free(d)) {
      o->event_stats.screened++;
      return SICM_SUCCESS;
    }
    int status = fit_interpolant(d);
    if (status == SICM_EUSER) return sicm_ode_fail_user(o, d->ta, d->ya);
    if (status != SICM_SUCCESS)
      return sicm_ode_fail(o, status, d->ta, d->ya, "cannot interpolate the step for its events",
                           sicm_ode_last_error(o->event_solver));
  }
  int status;
  for (int j = 0; j <= kSamples; j++) {
    const double s = j == kSamples ? h : j * h / kSamples;
    interpolate(d, s, yi);
    for (size_t k = 0; k < n; k++) {
      const double v = event_value(o, k, d->ta + s, yi);
      if (!isfinite(v)) return fail_event(o, d->ta + s, yi, k);
      g[k * (kSamples + 1) + j] = v;
    }
  }
  candidate *cs = candidates(o);
  size_t count = 0;
  for (size_t k = 0; k < n; k++) {
    const double *gk = g + k * (kSamples + 1);
    int sign = o->event_sign[k], last = 0;
    for (int j = 1; j <= kSamples; j++) {
      const int sj = sign_of(gk[j]);
      if (sj == 0) continue;
      if (sign != 0 && sj != sign) {
        const int dir = sj > 0 ? SICM_ODE_EVENT_UP : SICM_ODE_EVENT_DOWN;
        if (o->events[k].direction & dir) cs[count++] = (candidate){k, last, j, dir, 0, 0};
      }
      sign = sj;
      last = j;
    }
    o->event_sign[k] = sign;
  }
  for (size_t c = 0; c < count; c++) {
    d->k = cs[c].k;
    const double s_lo = cs[c].lo * h / kSamples,
                 s_hi = cs[c].hi == kSamples ? h : cs[c].hi * h / kSamples;
    cs[c].s = brent(interpolant_value, d, s_lo, s_hi, h, kMaxBrentIterationsInterpolant, NULL);
    cs[c].tau = d->ta + cs[c].s;
  }
  qsort(cs, count, sizeof *cs, compare_candidates);
  for (size_t c = 0; c < count; c++) {
    status = place(d, &cs[c]);
    if (status == kNoCrossing) continue;
    if (status == SICM_EBADFUNC && d->have_best)
      return fail_event(o, d->ta + d->s_best, d->y_trial, cs[c].k);
    if (status == SICM_EUSER) return sicm_ode_fail_user(o, d->ta, d->ya);
    if (status != SICM_SUCCESS)
      return sicm_ode_fail(o, status, d->ta, d->ya, "cannot place an event",
                           sicm_ode_last_error(o->event_solver));
    o->event_stats.located++;
    d->located = 1;
    const double te = d->ta + d->s_best;
    const int stop =
        o->events[cs[c].k].terminal ||
        (o->event_handler && o->event_handler(cs[c].k, te, d->y_best, o->event_data) != 0);
    if (stop) {
      *t = te;
      memcpy(y, d->y_best, o->dim * sizeof *y);
      o->stopping_event = (long)cs[c].k;
      /* The signs where the integration stops: the stopping event's is the
       * one it crossed to, whatever the rounding of g there; the others'
       * those of their later crossings in this step undone. */
      for (size_t k = 0; k < n; k++) {
        const int sk = sign_of(event_value(o, k, te, y));
        if (sk != 0) o->event_sign[k] = sk;
      }
      o->event_sign[cs[c].k] = cs[c].dir == SICM_ODE_EVENT_UP ? 1 : -1;
      return SICM_SUCCESS;
    }
  }
  return SICM_SUCCESS;
}

static int evolve_events(sicm_ode *o, double *t, double t1, double *y);

/* GSL's root solver reports a non-finite value of the function (an event
 * function that failed) through GSL's error handler, whose default aborts:
 * off while events are sought, the failure is this call's to report. */
int sicm_ode_evolve_events(sicm_ode *o, double *t, double t1, double *y) {
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  const int status = evolve_events(o, t, t1, y);
  gsl_set_error_handler(old);
  return status;
}

static int evolve_events(sicm_ode *o, double *t, double t1, double *y) {
  const size_t dim = o->dim, n = o->event_count;
  if (!isfinite(*t) || !isfinite(t1) || !sicm_ode_finite(dim, y) || *t == t1)
    return sicm_ode_evolve_plain(o, t, t1, y); /* its checks and messages */
  int status = make_solver(o);
  if (status != SICM_SUCCESS)
    return sicm_ode_fail(o, status, *t, y, "out of memory", "for the events' integrator");
  /* An integration that resumes where the last one ended keeps the signs it
   * had reached (so an event it stopped at is not found again); a new one
   * takes them from its start. */
  const int resumed = o->have_event_last && *t == o->event_t_last &&
                      memcmp(y, o->event_y_last, dim * sizeof *y) == 0;
  if (!resumed)
    for (size_t k = 0; k < n; k++) {
      const double g = event_value(o, k, *t, y);
      if (!isfinite(g)) return fail_event(o, *t, y, k);
      o->event_sign[k] = sign_of(g);
    }
  o->have_event_last = 0;
  double *ya = work_slot(o, 0), *fa = work_slot(o, 1), *fb = work_slot(o, 2);
  step_data d = {.o = o, .ya = ya, .fa = fa, .yb = y, .fb = fb};
  d.y_trial = work_slot(o, 4);
  d.y_best = work_slot(o, 5);
  status = sicm_ode_start_derivative(o, *t, y, fa);
  if (status != SICM_SUCCESS) return status;
  double last_step = 0;
  /* The limit on steps counts those between two events located, as it
   * counts those between two calls of a monitor. */
  for (unsigned long steps = 0; *t != t1; steps = d.located ? 0 : steps + 1) {
    if (steps >= o->max_steps) return sicm_ode_fail_max_steps(o, *t, y);
    d.located = 0;
    d.ta = *t;
    memcpy(ya, y, dim * sizeof *y);
    /* One step of the method: the one its controller proposes, or, for the
     * methods that keep their step to themselves, the first step of a
     * method of order 8 from here; at most kGrowth times the last step, as
     * a controller's proposal may be far longer than the step it will take
     * (qcrk4 proposes and rejects steps a thousand times too long). */
    double h = o->h;
    if (h == 0 || h * (t1 - d.ta) < 0) {
      double *scratch = work_slot(o, 3); /* 2 * dim: y_interp and y_trial */
      h = sicm_ode_initial_step(o, d.ta, ya, fa, t1, 8, scratch, &status);
      if (status != SICM_SUCCESS) return sicm_ode_fail_user(o, d.ta, ya);
    }
    if (last_step != 0 && fabs(h) > kGrowth * last_step) h = copysign(kGrowth * last_step, h);
    /* A method with its own continuous output (Taylor) is asked for a
     * little less than its last step, so that it takes one step and the
     * events are found on that step's polynomial (two steps would leave
     * only the second's). */
    if (o->type->dense) h *= kDenseShare;
    const double tb = fabs(h) >= fabs(t1 - d.ta) ? t1 : d.ta + h;
    const unsigned long steps0 = o->stats.steps;
    status = sicm_ode_evolve_plain(o, t, tb, y);
    if (status != SICM_SUCCESS) return status;
    /* The steps the method took: usually one. */
    const unsigned long taken = o->stats.steps - steps0;
    last_step = fabs(tb - d.ta) / (double)(taken > 1 ? taken : 1);
    d.tb = tb;
    o->event_t0 = d.ta;
    status = sicm_ode_start_derivative(o, tb, y, fb);
    if (status != SICM_SUCCESS) return status;
    status = events_of_step(&d, t, y);
    if (status != SICM_SUCCESS) return status;
    if (o->stopping_event >= 0) {
      /* The method's state is at tb, past the event: the next evolve,
       * from the event, starts it afresh. */
      sicm_ode_reset(o);
      break;
    }
    memcpy(fa, fb, dim * sizeof *fa);
  }
  o->have_event_last = 1;
  o->event_t_last = *t;
  memcpy(o->event_y_last, y, dim * sizeof *y);
  return SICM_SUCCESS;
}
