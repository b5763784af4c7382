/* Roots of functions of one variable: Brent's method over GSL. */
#include <float.h>
#include <math.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "sicm/runtime.h"
#include "watched_fn.h"

enum { kMaxIter = 1000 };

int sicm_root_brent(double (*f)(double, void *), void *params, double a, double b, double tol,
                    double *root) {
  static const char who[] = "sicm_root_brent";
  if (!(a < b) || !isfinite(a) || !isfinite(b))
    return sicm_error(SICM_EINVAL, "%s: [%g, %g] is not a finite interval a < b", who, a, b);
  if (!(tol >= 0) || !isfinite(tol))
    return sicm_error(SICM_EINVAL, "%s: the tolerance %g must be non-negative", who, tol);
  fn1 w = {f, params, 0, 0, 0};
  double fa = call1(a, &w), fb = call1(b, &w);
  if (w.bad) return fn1_nonfinite(who, &w);
  if (fa == 0 || fb == 0) {
    *root = fa == 0 ? a : b;
    return SICM_SUCCESS;
  }
  if ((fa < 0) == (fb < 0))
    return sicm_error(SICM_EBRACKET,
                      "%s: f(%.17g) = %.17g and f(%.17g) = %.17g have the same sign, so the "
                      "interval does not bracket a root",
                      who, a, fa, b, fb);
  gsl_error_handler_t *old = gsl_set_error_handler_off();
  gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
  if (!s) {
    gsl_set_error_handler(old);
    return sicm_error(SICM_ENOMEM, "%s: out of memory", who);
  }
  gsl_function F = {call1, &w};
  int gs = gsl_root_fsolver_set(s, &F, a, b), iter = 0;
  while (gs == GSL_SUCCESS) {
    if (iter++ >= kMaxIter) {
      gs = GSL_EMAXITER;
      break;
    }
    gs = gsl_root_fsolver_iterate(s);
    if (w.bad || gs != GSL_SUCCESS) break;
    double lo = gsl_root_fsolver_x_lower(s), hi = gsl_root_fsolver_x_upper(s);
    /* No double lies strictly inside [lo, hi] (Brent found f = 0 there, or
     * the bracket is two neighbours): nothing finer exists. GSL's relative
     * test alone never passes for a bracket around 0 at full precision. */
    if (!(nextafter(lo, hi) < hi)) break;
    if (gsl_root_test_interval(lo, hi, tol, 4 * DBL_EPSILON) == GSL_SUCCESS) break;
  }
  *root = gsl_root_fsolver_root(s);
  gsl_root_fsolver_free(s);
  gsl_set_error_handler(old);
  if (w.bad) return fn1_nonfinite(who, &w);
  if (gs == GSL_EMAXITER)
    return sicm_error(SICM_EMAXITER, "%s: no convergence in %d iterations; best estimate %.17g",
                      who, kMaxIter, *root);
  if (gs != GSL_SUCCESS)
    return sicm_error(SICM_EFAILED, "%s: GSL: %s (best estimate %.17g)", who, gsl_strerror(gs),
                      *root);
  return SICM_SUCCESS;
}
