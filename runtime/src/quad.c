/* Quadrature: adaptive Gauss-Kronrod (finite and infinite intervals) and Romberg, over GSL. */
#include <float.h>
#include <math.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>

#include "sicm/runtime.h"
#include "watched_fn.h"

enum { kMaxIntervals = 1000, kRombergLevels = 20 };

static int bad_value(const char *who, const fn1 *w) {
  return fn1_nonfinite(who, w);
}

/* Why GSL's adaptive routines stopped short, in words. */
static const char *qag_reason(int gs) {
  switch (gs) {
  case GSL_EMAXITER: return "the maximum number of subintervals was reached";
  case GSL_EROUND: return "round-off error prevents further progress";
  case GSL_ESING: return "the integrand behaves badly (a singularity?) inside the interval";
  case GSL_EDIVERGE: return "the integral seems to diverge or converges too slowly";
  }
  return gsl_strerror(gs);
}

int sicm_quad_integrate(double (*f)(double, void *), void *params, double a, double b,
                        double rel_tol, double *result) {
  static const char who[] = "sicm_quad_integrate";
  if (isnan(a) || isnan(b) || (isinf(a) && a == b))
    return sicm_error(SICM_EINVAL, "%s: invalid limits %g and %g", who, a, b);
  if (!(rel_tol > 0) || !isfinite(rel_tol))
    return sicm_error(SICM_EINVAL, "%s: the relative tolerance %g must be positive", who, rel_tol);
  if (a == b) {
    *result = 0;
    return SICM_SUCCESS;
  }
  const double sign = a < b ? 1.0 : -1.0, lo = a < b ? a : b, hi = a < b ? b : a;
  const double tol = fmax(rel_tol, 50 * DBL_EPSILON);
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  gsl_integration_workspace *ws = gsl_integration_workspace_alloc(kMaxIntervals);
  if (!ws) {
    gsl_set_error_handler(old);
    return sicm_error(SICM_ENOMEM, "%s: out of memory", who);
  }
  fn1 w = {f, params, 0, 0, 0};
  gsl_function F = {call1, &w};
  double r = 0, abserr = 0;
  int gs;
  if (isinf(lo) && isinf(hi))
    gs = gsl_integration_qagi(&F, 0, tol, kMaxIntervals, ws, &r, &abserr);
  else if (isinf(hi))
    gs = gsl_integration_qagiu(&F, lo, 0, tol, kMaxIntervals, ws, &r, &abserr);
  else if (isinf(lo))
    gs = gsl_integration_qagil(&F, hi, 0, tol, kMaxIntervals, ws, &r, &abserr);
  else
    gs = gsl_integration_qag(&F, lo, hi, 0, tol, kMaxIntervals, GSL_INTEG_GAUSS21, ws, &r, &abserr);
  gsl_integration_workspace_free(ws);
  gsl_set_error_handler(old);
  *result = sign * r;
  if (w.bad) return bad_value(who, &w);
  if (gs != GSL_SUCCESS)
    return sicm_error(SICM_ETOL,
                      "%s: cannot reach relative tolerance %g for the integral from %g to %g: %s; "
                      "best estimate %.17g with estimated error %.3g",
                      who, tol, a, b, qag_reason(gs), *result, abserr);
  return SICM_SUCCESS;
}

int sicm_quad_romberg(double (*f)(double, void *), void *params, double a, double b, double rel_tol,
                      double *result) {
  static const char who[] = "sicm_quad_romberg";
  if (!isfinite(a) || !isfinite(b))
    return sicm_error(SICM_EINVAL, "%s: the limits %g and %g must be finite", who, a, b);
  if (!(rel_tol > 0) || !isfinite(rel_tol))
    return sicm_error(SICM_EINVAL, "%s: the relative tolerance %g must be positive", who, rel_tol);
  if (a == b) {
    *result = 0;
    return SICM_SUCCESS;
  }
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  gsl_integration_romberg_workspace *ws = gsl_integration_romberg_alloc(kRombergLevels);
  if (!ws) {
    gsl_set_error_handler(old);
    return sicm_error(SICM_ENOMEM, "%s: out of memory", who);
  }
  fn1 w = {f, params, 0, 0, 0};
  gsl_function F = {call1, &w};
  size_t neval = 0;
  int gs = gsl_integration_romberg(&F, a, b, 0, rel_tol, result, &neval, ws);
  gsl_integration_romberg_free(ws);
  gsl_set_error_handler(old);
  if (w.bad) return bad_value(who, &w);
  if (gs == GSL_EMAXITER)
    return sicm_error(SICM_ETOL,
                      "%s: no convergence to relative tolerance %g for the integral from %g to "
                      "%g after %zu evaluations; last estimate %.17g",
                      who, rel_tol, a, b, neval, *result);
  if (gs != GSL_SUCCESS) return sicm_error(SICM_EFAILED, "%s: GSL: %s", who, gsl_strerror(gs));
  return SICM_SUCCESS;
}
