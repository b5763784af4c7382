/* ODE integrator objects: the common driver, failure messages, and the GSL odeiv2 steppers. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "ode_internal.h"

enum { kDefaultMaxSteps = 500000, kMaxStateShown = 16 };

/* An interval of at most this many machine epsilons relative to t is taken
 * in one Runge-Kutta step (sicm_ode_evolve). */
enum { kTinyInterval = 1024 };

/* ---- helpers shared by the backends ----------------------------------- */

int sicm_ode_finite(size_t n, const double *v) {
  for (size_t i = 0; i < n; i++)
    if (!isfinite(v[i])) return 0;
  return 1;
}

/* The singularity probe's buffers (see sicm_ode_set_singularity_probe). */
static double *probe_y_start(sicm_ode *o) {
  return o->probe_work;
}
static double *probe_y_bad(sicm_ode *o) {
  return o->probe_work + o->dim;
}
static double *probe_values(sicm_ode *o) {
  return o->probe_work + 2 * o->dim;
}

static void remember_bad_state(sicm_ode *o, double t, const double *y) {
  if (!o->probe) return;
  memcpy(probe_y_bad(o), y, o->dim * sizeof *y);
  o->t_bad = t;
  o->have_bad = 1;
}

int sicm_ode_call_rhs(sicm_ode *o, double t, const double *y, double *dydt) {
  /* A trial state can be non-finite when a step was far too long; refusing
   * it (instead of calling the user's code with NaNs) lets the backend
   * retry with a shorter step. */
  if (!sicm_ode_finite(o->dim, y)) return SICM_EBADFUNC;
  o->stats.rhs_evals++;
  int s = o->f(t, y, dydt, o->params);
  if (s != 0) {
    o->user_status = s;
    return SICM_EUSER;
  }
  if (sicm_ode_finite(o->dim, dydt)) return SICM_SUCCESS;
  remember_bad_state(o, t, y);
  /* A singular matrix is a property of the state, not of the step: no
   * shorter step would help, so it stops the integration like a user
   * function's refusal (sicm_ode_fail_user names it). */
  for (size_t i = 0; i < o->dim; i++)
    if (sicm_is_singular_nan(dydt[i])) {
      o->user_status = SICM_ESINGULAR;
      return SICM_EUSER;
    }
  for (size_t i = 0; i < o->dim; i++)
    if (!isfinite(dydt[i])) {
      o->bad_component = (long)i;
      o->bad_value = dydt[i];
      break;
    }
  return SICM_EBADFUNC;
}

int sicm_ode_call_jacobian(sicm_ode *o, double t, const double *y, double *dfdy, double *dfdt,
                           double *work) {
  const size_t n = o->dim;
  if (!sicm_ode_finite(n, y)) return SICM_EBADFUNC;
  o->stats.jacobian_evals++;
  if (o->jac) {
    int s = o->jac(t, y, dfdy, dfdt, o->params);
    if (s != 0) {
      o->user_status = s;
      return SICM_EUSER;
    }
    return sicm_ode_finite(n * n, dfdy) && sicm_ode_finite(n, dfdt) ? SICM_SUCCESS : SICM_EBADFUNC;
  }
  /* Forward differences, one rhs call per column. The increment is
   * sqrt(eps) relative to the component, or to the scale abs_tol/rel_tol
   * below which the tolerances treat a component as zero; it is rounded so
   * that y_j + d - y_j == d exactly. */
  double *f0 = work, *yt = work + n, *f1 = work + 2 * n;
  const double root_eps = sqrt(DBL_EPSILON);
  const double floor = o->rel_tol > 0 ? o->abs_tol / o->rel_tol : 1.0;
  int s = sicm_ode_call_rhs(o, t, y, f0);
  if (s != SICM_SUCCESS) return s;
  memcpy(yt, y, n * sizeof *yt);
  for (size_t j = 0; j < n; j++) {
    double d = root_eps * fmax(fabs(y[j]), floor);
    if (d == 0) d = root_eps;
    yt[j] = y[j] + d;
    d = yt[j] - y[j];
    s = sicm_ode_call_rhs(o, t, yt, f1);
    if (s != SICM_SUCCESS) return s;
    for (size_t i = 0; i < n; i++)
      dfdy[i * n + j] = (f1[i] - f0[i]) / d;
    yt[j] = y[j];
  }
  double dt = root_eps * fmax(fabs(t), 1.0);
  dt = (t + dt) - t;
  s = sicm_ode_call_rhs(o, t + dt, y, f1);
  if (s != SICM_SUCCESS) return s;
  for (size_t i = 0; i < n; i++)
    dfdt[i] = (f1[i] - f0[i]) / dt;
  return SICM_SUCCESS;
}

double sicm_ode_error_norm(const sicm_ode *o, const double *err, const double *y) {
  double m = 0;
  for (size_t i = 0; i < o->dim; i++) {
    double r = fabs(err[i]) / (o->abs_tol + o->rel_tol * fabs(y[i]));
    if (!(r <= m)) m = r; /* a NaN error wins: the step must be rejected */
  }
  return m;
}

double sicm_ode_rms_scaled(const sicm_ode *o, const double *v, const double *y) {
  double s = 0;
  for (size_t i = 0; i < o->dim; i++) {
    double r = v[i] / (o->abs_tol + o->rel_tol * fabs(y[i]));
    s += r * r;
  }
  return sqrt(s / (double)o->dim);
}

double sicm_ode_initial_step(sicm_ode *o, double t, const double *y, const double *f0, double t1,
                             int order, double *work, int *status) {
  const size_t n = o->dim;
  const double dir = t1 > t ? 1.0 : -1.0;
  double d0 = sicm_ode_rms_scaled(o, y, y), d1 = sicm_ode_rms_scaled(o, f0, y);
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = fmin(h0, fabs(t1 - t));
  double *y1 = work, *f1 = work + n;
  for (size_t i = 0; i < n; i++)
    y1[i] = y[i] + dir * h0 * f0[i];
  *status = sicm_ode_call_rhs(o, t + dir * h0, y1, f1);
  if (*status == SICM_EBADFUNC) { /* too far already: start small, let control grow it */
    *status = SICM_SUCCESS;
    return dir * h0 * 1e-3;
  }
  if (*status != SICM_SUCCESS) return 0;
  for (size_t i = 0; i < n; i++)
    f1[i] -= f0[i];
  double d2 = sicm_ode_rms_scaled(o, f1, y) / h0;
  double dmax = fmax(d1, d2);
  double h1 = dmax <= 1e-15 ? fmax(1e-6, h0 * 1e-3) : pow(0.01 / dmax, 1.0 / (order + 1));
  return dir * fmin(100 * h0, h1);
}

/* Append "[y0, y1, ...]" to buf (at most kMaxStateShown components). */
static void format_state(char *buf, size_t size, size_t n, const double *y) {
  size_t len = strlen(buf);
  char num[SICM_DOUBLE_BUFSIZE];
  for (size_t i = 0; i < n && i < kMaxStateShown && len + 1 < size; i++) {
    sicm_format_double(num, y[i]);
    snprintf(buf + len, size - len, "%s%s", i == 0 ? "[" : ", ", num);
    len = strlen(buf);
  }
  if (n > kMaxStateShown && len + 1 < size)
    snprintf(buf + len, size - len, ", ... (%zu components)", n);
  len = strlen(buf);
  if (len + 1 < size) snprintf(buf + len, size - len, "]");
}

/* A shrink by this factor, from where the evolve call began, marks the
 * quantity that went to zero: far below the variation of a regular motion
 * over one call, far above the shrink a collision or a coordinate
 * singularity shows at a failed step (1e-8 and less in the tests). */
static const double kSingularShrink = 1e-3;

/* Appends to the message the probe's quantity that has gone to zero at the
 * failure, if one has. */
static void name_singularity(sicm_ode *o, double t, const double *y) {
  if (!o->probe || o->probe_count == 0) return;
  const size_t n = o->probe_count;
  double *at_start = probe_values(o), *there = at_start + n;
  const double *where = o->have_bad ? probe_y_bad(o) : y;
  const double t_where = o->have_bad ? o->t_bad : t;
  o->probe(probe_y_start(o), at_start, o->probe_params);
  o->probe(where, there, o->probe_params);
  size_t best = n;
  double best_shrink = kSingularShrink;
  for (size_t k = 0; k < n; k++) {
    double shrink = fabs(there[k]) / fabs(at_start[k]);
    if (at_start[k] != 0 && isfinite(at_start[k]) && isfinite(there[k]) && shrink <= best_shrink) {
      best = k;
      best_shrink = shrink;
    }
  }
  if (best == n) return;
  char was[SICM_DOUBLE_BUFSIZE], is[SICM_DOUBLE_BUFSIZE], t0[SICM_DOUBLE_BUFSIZE],
      t1[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(was, at_start[best]);
  sicm_format_double(is, there[best]);
  sicm_format_double(t0, o->t_start);
  sicm_format_double(t1, t_where);
  size_t len = strlen(o->message);
  snprintf(o->message + len, sizeof o->message - len,
           "; the system derivative divides by %.200s, which went from %s at t = %s to %s at "
           "t = %s: its equations are singular there (a collision, or coordinates that are "
           "singular at that state)",
           o->probe_texts[best], was, t0, is, t1);
}

int sicm_ode_fail(sicm_ode *o, int status, double t, const double *y, const char *what,
                  const char *detail) {
  char tbuf[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(tbuf, t);
  snprintf(o->message, sizeof o->message, "%s: %s at t = %s with state ", o->type->name, what,
           tbuf);
  format_state(o->message, sizeof o->message, o->dim, y);
  if (detail) {
    size_t len = strlen(o->message);
    snprintf(o->message + len, sizeof o->message - len, ": %s", detail);
  }
  if (status == SICM_EBADFUNC && o->bad_component >= 0 &&
      strcmp(what, "non-finite derivative") == 0) {
    char vbuf[SICM_DOUBLE_BUFSIZE];
    sicm_format_double(vbuf, o->bad_value);
    size_t len = strlen(o->message);
    snprintf(o->message + len, sizeof o->message - len,
             " (component %ld of the derivative, counting the time's as 0, was %s)",
             o->bad_component, vbuf);
  }
  if (status == SICM_ESTEP || status == SICM_EBADFUNC || status == SICM_ESINGULAR)
    name_singularity(o, t, y);
  return sicm_error(status, "%s", o->message);
}

int sicm_ode_fail_user(sicm_ode *o, double t, const double *y) {
  if (o->user_status == SICM_ESINGULAR)
    return sicm_ode_fail(o, SICM_ESINGULAR, t, y, "singular matrix in a linear solve",
                         "the system derivative divides by a matrix (a mass matrix?) that is "
                         "singular or not positive definite there");
  char detail[96];
  snprintf(detail, sizeof detail, "a user function returned %d", o->user_status);
  return sicm_ode_fail(o, SICM_EUSER, t, y, "stopped by the system", detail);
}

int sicm_ode_start_derivative(sicm_ode *o, double t, const double *y, double *f0) {
  int s = sicm_ode_call_rhs(o, t, y, f0);
  if (s == SICM_EUSER) return sicm_ode_fail_user(o, t, y);
  if (s != SICM_SUCCESS)
    return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite derivative",
                         "the right-hand side is NaN or infinite at this point");
  return SICM_SUCCESS;
}

int sicm_ode_fail_max_steps(sicm_ode *o, double t, const double *y) {
  char detail[400];
  snprintf(detail, sizeof detail,
           "%lu steps did not reach the next output time (the limit counts the steps between "
           "two calls of the monitor, or of one state advance); give a smaller monitor step, "
           "a larger limit (evolve's or state-advancer's max-steps argument, after the "
           "integrator), or, if the system is stiff, 'cvode-bdf",
           o->max_steps);
  return sicm_ode_fail(o, SICM_EMAXITER, t, y, "too many steps", detail);
}

/* ---- the GSL odeiv2 backend ------------------------------------------- */

/* GSL calls back with our object as params; user failures become
 * GSL_EBADFUNC (GSL stops at once), non-finite values GSL_FAILURE (GSL
 * halves the step and retries, down to the resolution of t). */
typedef struct {
  const gsl_odeiv2_step_type *const *step;
  sicm_ode_stability stability; /* {0, 0}: implicit (msbdf), not watched */
} gsl_method;

typedef struct {
  const gsl_method *method;
  gsl_odeiv2_system sys;
  gsl_odeiv2_driver *driver;
  double *save; /* y before the current step */
  double *work; /* 3*dim: finite-difference Jacobian */
  int saw_nonfinite;
} gsl_backend;

static int gsl_status(sicm_ode *o, int s) {
  if (s == SICM_SUCCESS) return GSL_SUCCESS;
  if (s == SICM_EUSER) return GSL_EBADFUNC;
  ((gsl_backend *)o->backend)->saw_nonfinite = 1;
  return GSL_FAILURE;
}

static int gsl_rhs(double t, const double y[], double dydt[], void *params) {
  sicm_ode *o = params;
  return gsl_status(o, sicm_ode_call_rhs(o, t, y, dydt));
}

static int gsl_jacobian(double t, const double y[], double *dfdy, double dfdt[], void *params) {
  sicm_ode *o = params;
  gsl_backend *b = o->backend;
  return gsl_status(o, sicm_ode_call_jacobian(o, t, y, dfdy, dfdt, b->work));
}

static int gsl_init(sicm_ode *o) {
  const gsl_method *method = o->type->data;
  const gsl_odeiv2_step_type *T = *method->step;
  gsl_backend *b = calloc(1, sizeof *b);
  if (!b) return SICM_ENOMEM;
  o->backend = b;
  b->method = method;
  b->sys = (gsl_odeiv2_system){gsl_rhs, gsl_jacobian, o->dim, o};
  b->save = malloc(o->dim * sizeof *b->save);
  b->work = malloc(3 * o->dim * sizeof *b->work);
  /* The driver owns step, control and evolve and links them (msbdf needs
   * the control through it); we call evolve_apply ourselves to keep the
   * step size between calls and to report failures in detail. The standard
   * control with a_y = 1, a_dydt = 0 is the test abs_tol + rel_tol |y_i|. */
  b->driver =
      gsl_odeiv2_driver_alloc_standard_new(&b->sys, T, 1e-6, o->abs_tol, o->rel_tol, 1.0, 0.0);
  return b->save && b->work && b->driver ? SICM_SUCCESS : SICM_ENOMEM;
}

static void gsl_free(sicm_ode *o) {
  gsl_backend *b = o->backend;
  if (!b) return;
  if (b->driver) gsl_odeiv2_driver_free(b->driver);
  free(b->save);
  free(b->work);
  free(b);
}

static void gsl_reset(sicm_ode *o) {
  gsl_backend *b = o->backend;
  gsl_odeiv2_driver_reset(b->driver);
}

static int gsl_evolve(sicm_ode *o, double *t, double t1, double *y) {
  gsl_backend *b = o->backend;
  gsl_odeiv2_driver *d = b->driver;
  const size_t n = o->dim;
  if (o->h == 0) {
    double *f0 = b->work, *work = b->work + n;
    int s = sicm_ode_call_rhs(o, *t, y, f0);
    if (s == SICM_EUSER) return sicm_ode_fail_user(o, *t, y);
    if (s != SICM_SUCCESS)
      return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite derivative",
                           "the right-hand side is NaN or infinite at the initial point");
    o->h = sicm_ode_initial_step(o, *t, y, f0, t1, (int)gsl_odeiv2_step_order(d->s), work, &s);
    if (s != SICM_SUCCESS) return sicm_ode_fail_user(o, *t, y);
  }
  for (unsigned long steps = 0; *t != t1; steps++) {
    if (steps >= o->max_steps) return sicm_ode_fail_max_steps(o, *t, y);
    const double t0 = *t;
    const unsigned long failed0 = d->e->failed_steps;
    memcpy(b->save, y, n * sizeof *y);
    b->saw_nonfinite = 0;
    double h = o->h;
    int s = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &b->sys, t, t1, &h, y);
    o->stats.rejected_steps += d->e->failed_steps - failed0;
    if (s == GSL_SUCCESS && !sicm_ode_finite(n, y)) {
      /* The step overflowed although every stage was finite; GSL's control
       * ignores NaN error estimates, so reject it here. */
      o->stats.rejected_steps++;
      *t = t0;
      memcpy(y, b->save, n * sizeof *y);
      o->h *= 0.25;
      if (t0 + o->h == t0)
        return sicm_ode_fail(o, SICM_EBADFUNC, t0, y, "non-finite state",
                             "every step, down to the resolution of t, overflows");
      gsl_odeiv2_step_reset(d->s);
      continue;
    }
    if (s != GSL_SUCCESS) {
      *t = t0;
      memcpy(y, b->save, n * sizeof *y);
      if (s == GSL_EBADFUNC) return sicm_ode_fail_user(o, t0, y);
      if (s == GSL_FAILURE && b->saw_nonfinite)
        return sicm_ode_fail(o, SICM_EBADFUNC, t0, y, "non-finite derivative",
                             "the right-hand side is NaN or infinite for every step size "
                             "down to the resolution of t");
      if (s == GSL_FAILURE) {
        char detail[200];
        snprintf(detail, sizeof detail,
                 "the error test fails even for the shortest step the resolution of t "
                 "allows (h = %.3g); the solution may be singular here",
                 h);
        return sicm_ode_fail(o, SICM_ESTEP, t0, y, "step size too small", detail);
      }
      return sicm_ode_fail(o, SICM_EFAILED, t0, y, "GSL failure", gsl_strerror(s));
    }
    o->stats.steps++;
    o->h = h; /* GSL leaves h alone after a step shortened to land on t1 */
    if (b->method->stability.real > 0) {
      s = sicm_ode_watch_stiffness(o, *t, y, *t - t0, t1, b->method->stability);
      if (s != SICM_SUCCESS) return s;
    }
  }
  return SICM_SUCCESS;
}

#define GSL_STEP_TYPE(var, label, gsl_type, real, imaginary)                                       \
  static const gsl_method var##_method = {&gsl_type, {real, imaginary}};                           \
  static const sicm_ode_step_type var##_type = {label,    gsl_init,      gsl_evolve, gsl_reset,    \
                                                gsl_free, &var##_method, NULL};                    \
  const sicm_ode_step_type *const sicm_ode_step_##var = &var##_type;

/* The stability boundaries of GSL's explicit steppers (sicm_ode_stability),
 * measured: one step of the stepper itself from y = 1 on y' = lambda y
 * (written as a real 2x2 system) gives |R(h lambda)| exactly; scanning
 * |h lambda| upwards in steps of 1e-3 along each axis, the boundary is where
 * |R| first exceeds 1 + 1e-3. On the negative real axis |R| <= 1 holds up to
 * there (5.17, 3.68, 3.73). On the imaginary axis rkf45 and rkck, which
 * advance with their 5th-order formulas, grow slightly for any step
 * (|R| - 1 is 1e-5 at 0.5 for rkf45); the slack of 1e-3 a step is what
 * their error control absorbs at a loose tolerance. As a
 * check, each controller integrating y' = lambda y, |lambda| = 1000, from a
 * tiny start at tolerances 1e-3 to 1e-13 holds h |lambda| at 5.20 and 3.70
 * (rk8pd), 3.69 and 3.52 (rkf45), 3.74 and 0.80 (rkck). */
GSL_STEP_TYPE(rk8pd, "rk8pd", gsl_odeiv2_step_rk8pd, 5.17, 3.78)
GSL_STEP_TYPE(rkf45, "rkf45", gsl_odeiv2_step_rkf45, 3.68, 1.09)
GSL_STEP_TYPE(rkck, "rkck", gsl_odeiv2_step_rkck, 3.73, 1.25)
GSL_STEP_TYPE(msbdf, "msbdf", gsl_odeiv2_step_msbdf, 0, 0)

const sicm_ode_step_type *const sicm_ode_step_bs = &sicm_ode_bs_type;
const sicm_ode_step_type *const sicm_ode_step_cvode_adams = &sicm_ode_cvode_adams_type;
const sicm_ode_step_type *const sicm_ode_step_cvode_bdf = &sicm_ode_cvode_bdf_type;
const sicm_ode_step_type *const sicm_ode_step_taylor = &sicm_ode_taylor_type;
const sicm_ode_step_type *const sicm_ode_step_taylor_extended = &sicm_ode_taylor_extended_type;
const sicm_ode_step_type *const sicm_ode_step_qcrk4 = &sicm_ode_qcrk4_type;
const sicm_ode_step_type *const sicm_ode_step_qcctrap2 = &sicm_ode_qcctrap2_type;

/* ---- the public driver ------------------------------------------------ */

const char *sicm_ode_step_type_name(const sicm_ode_step_type *T) {
  return T ? T->name : "";
}

sicm_ode *sicm_ode_alloc(const sicm_ode_step_type *T, size_t dim, sicm_ode_rhs f, void *params,
                         double abs_tol, double rel_tol) {
  if (!T || !f || dim == 0) {
    sicm_error(SICM_EINVAL, "sicm_ode_alloc: %s",
               !T   ? "no step type"
               : !f ? "no right-hand side"
                    : "dimension is zero");
    return NULL;
  }
  if (!(abs_tol >= 0 && rel_tol >= 0 && isfinite(abs_tol) && isfinite(rel_tol)) ||
      abs_tol + rel_tol == 0) {
    sicm_error(SICM_EINVAL,
               "sicm_ode_alloc (%s): tolerances must be finite, non-negative and not both "
               "zero (abs_tol = %g, rel_tol = %g)",
               T->name, abs_tol, rel_tol);
    return NULL;
  }
  if (dim > SIZE_MAX / sizeof(double) / dim / 4) {
    sicm_error(SICM_EINVAL, "sicm_ode_alloc (%s): dimension %zu is too large", T->name, dim);
    return NULL;
  }
  sicm_ode *o = calloc(1, sizeof *o);
  if (o) {
    *o = (sicm_ode){.type = T,
                    .bad_component = -1,
                    .dim = dim,
                    .f = f,
                    .params = params,
                    .abs_tol = abs_tol,
                    .rel_tol = rel_tol,
                    .stopping_event = -1,
                    .max_steps = kDefaultMaxSteps};
    o->y_last = malloc(dim * sizeof *o->y_last);
  }
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int s = o && o->y_last ? T->init(o) : SICM_ENOMEM;
  gsl_set_error_handler(old);
  if (s != SICM_SUCCESS) {
    sicm_ode_free(o);
    sicm_error(s, "sicm_ode_alloc (%s): cannot allocate an integrator of dimension %zu", T->name,
               dim);
    return NULL;
  }
  return o;
}

void sicm_ode_free(sicm_ode *o) {
  if (!o) return;
  if (o->backend) o->type->free(o);
  sicm_ode_free_events(o);
  free(o->y_last);
  free(o->stiffness_work);
  free(o->probe_work);
  free(o);
}

int sicm_ode_set_jacobian(sicm_ode *o, sicm_ode_jacobian jac) {
  o->jac = jac;
  sicm_ode_reset(o);
  return SICM_SUCCESS;
}

int sicm_ode_set_max_steps(sicm_ode *o, unsigned long max_steps) {
  if (max_steps == 0)
    return sicm_error(SICM_EINVAL, "sicm_ode_set_max_steps (%s): the limit must be positive",
                      o->type->name);
  o->max_steps = max_steps;
  return SICM_SUCCESS;
}

void sicm_ode_reset(sicm_ode *o) {
  o->h = 0;
  o->have_last = 0;
  o->steps_since_check = 0;
  o->span_since_check = 0;
  o->stiff_streak = 0;
  o->have_vector = 0;
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  o->type->reset(o);
  gsl_set_error_handler(old);
}

/* One classical Runge-Kutta step from t over h, in place: for an interval
 * below the resolution of t (see sicm_ode_evolve) its error, O(h^5), is far
 * below the rounding of y. */
static int tiny_step(sicm_ode *o, double t, double h, double *y) {
  const size_t n = o->dim;
  double *k = malloc(5 * n * sizeof *k);
  if (!k) return sicm_ode_fail(o, SICM_ENOMEM, t, y, "out of memory", NULL);
  double *k1 = k, *k2 = k + n, *k3 = k + 2 * n, *k4 = k + 3 * n, *yt = k + 4 * n;
  const double c[3] = {0.5, 0.5, 1.0};
  double *stage[4] = {k1, k2, k3, k4};
  int s = sicm_ode_call_rhs(o, t, y, k1);
  for (int i = 1; i < 4 && s == SICM_SUCCESS; i++) {
    for (size_t j = 0; j < n; j++)
      yt[j] = y[j] + c[i - 1] * h * stage[i - 1][j];
    s = sicm_ode_call_rhs(o, t + c[i - 1] * h, yt, stage[i]);
  }
  if (s == SICM_SUCCESS)
    for (size_t j = 0; j < n; j++)
      y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
  free(k);
  if (s == SICM_EUSER) return sicm_ode_fail_user(o, t, y);
  if (s != SICM_SUCCESS)
    return sicm_ode_fail(o, SICM_EBADFUNC, t, y, "non-finite derivative",
                         "in the one step of an interval below the resolution of t");
  return SICM_SUCCESS;
}

int sicm_ode_evolve(sicm_ode *o, double *t, double t1, double *y) {
  o->stopping_event = -1;
  return o->event_count ? sicm_ode_evolve_events(o, t, t1, y) : sicm_ode_evolve_plain(o, t, t1, y);
}

int sicm_ode_evolve_plain(sicm_ode *o, double *t, double t1, double *y) {
  if (!isfinite(*t) || !isfinite(t1)) {
    char detail[120];
    snprintf(detail, sizeof detail, "the end time t1 = %g is not finite", t1);
    return sicm_ode_fail(o, SICM_EINVAL, *t, y, "invalid time",
                         isfinite(*t) ? detail : "the start time is not finite");
  }
  if (!sicm_ode_finite(o->dim, y))
    return sicm_ode_fail(o, SICM_EINVAL, *t, y, "non-finite state",
                         "the initial state has NaN or infinite components");
  if (*t == t1) return SICM_SUCCESS;
  o->bad_component = -1;
  if (o->probe) {
    memcpy(probe_y_start(o), y, o->dim * sizeof *y);
    o->t_start = *t;
    o->have_bad = 0;
  }
  /* Restart the method if the caller moved the state or reversed direction:
   * multistep history and the step size belong to the old trajectory. */
  if ((o->have_last && (*t != o->t_last || memcmp(y, o->y_last, o->dim * sizeof *y) != 0)) ||
      o->h * (t1 - *t) < 0)
    sicm_ode_reset(o);
  /* An interval this short is below what the adaptive methods can resolve
   * in t (their shortest step is a few ulps of t): take it in one step, as
   * scmutils does, instead of failing with "step size too small" (a
   * Poincare-section refinement halves its step until it gets here). */
  int tiny = fabs(t1 - *t) <= kTinyInterval * DBL_EPSILON * fmax(fabs(*t), fabs(t1));
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  int s = tiny ? tiny_step(o, *t, t1 - *t, y) : o->type->evolve(o, t, t1, y);
  gsl_set_error_handler(old);
  if (s != SICM_SUCCESS) {
    sicm_ode_reset(o);
    return s;
  }
  *t = t1;
  o->have_last = 1;
  o->t_last = t1;
  memcpy(o->y_last, y, o->dim * sizeof *y);
  return SICM_SUCCESS;
}

int sicm_ode_set_singularity_probe(sicm_ode *o, sicm_ode_probe probe, const double *params,
                                   size_t n, const char *const *texts) {
  free(o->probe_work);
  o->probe = NULL;
  o->probe_work = NULL;
  if (!probe || n == 0 || !texts) return SICM_SUCCESS;
  o->probe_work = malloc((2 * o->dim + 2 * n) * sizeof *o->probe_work);
  if (!o->probe_work)
    return sicm_error(SICM_ENOMEM, "sicm_ode_set_singularity_probe (%s): out of memory",
                      o->type->name);
  o->probe = probe;
  o->probe_params = params;
  o->probe_count = n;
  o->probe_texts = texts;
  return SICM_SUCCESS;
}

int sicm_ode_set_taylor(sicm_ode *o, sicm_ode_taylor_coefficients coefficients,
                        const double *params) {
  o->taylor = coefficients;
  o->taylor_params = params;
  sicm_ode_reset(o);
  return SICM_SUCCESS;
}

int sicm_ode_set_taylor_extended(sicm_ode *o, sicm_ode_taylor_extended_coefficients coefficients,
                                 const double *params) {
  o->taylor_extended = coefficients;
  o->taylor_params = params;
  sicm_ode_reset(o);
  return SICM_SUCCESS;
}

void sicm_ode_set_horizon(sicm_ode *o, double t_end) {
  o->horizon_set = isfinite(t_end);
  o->horizon = t_end;
}

const sicm_ode_stats *sicm_ode_get_stats(const sicm_ode *o) {
  return &o->stats;
}

const char *sicm_ode_last_error(const sicm_ode *o) {
  return o->message;
}

const char *sicm_ode_name(const sicm_ode *o) {
  return o->type->name;
}
