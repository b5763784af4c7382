/* Minimization in one dimension: Brent's method, over GSL (Nelder-Mead, in
 * several, is nelder_mead.c). */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>

#include "sicm/runtime.h"
#include "watched_fn.h"

enum { kBrentMaxIter = 1000, kGridPoints = 64, kStallLimit = 4 };

static int bad_value1(const char *who, const fn1 *w) {
  return fn1_nonfinite(who, w);
}

/* Find an interior point m of [a, b] with f(m) below f at the ends of a
 * bracket [*lo, *hi] around it: the golden-section point if it will do,
 * otherwise the best point of a uniform grid with its grid neighbours.
 * Returns 0 if no sampled interior point is below both ends. */
static int find_bracket(fn1 *w, double a, double fa, double b, double fb, double *lo, double *flo,
                        double *m, double *fm, double *hi, double *fhi) {
  const double golden = 0.3819660112501051; /* (3 - sqrt 5) / 2 */
  double x = a + golden * (b - a), fx = call1(x, w);
  if (w->bad) return 0;
  if (fx < fa && fx < fb) {
    *lo = a, *flo = fa, *m = x, *fm = fx, *hi = b, *fhi = fb;
    return 1;
  }
  double xs[kGridPoints + 2], fs[kGridPoints + 2];
  xs[0] = a, fs[0] = fa, xs[kGridPoints + 1] = b, fs[kGridPoints + 1] = fb;
  int best = 0;
  for (int i = 1; i <= kGridPoints + 1; i++) {
    if (i <= kGridPoints) {
      xs[i] = a + (b - a) * i / (kGridPoints + 1);
      fs[i] = call1(xs[i], w);
      if (w->bad) return 0;
    }
    if (fs[i] < fs[best]) best = i;
  }
  if (best == 0 || best == kGridPoints + 1) return 0;
  *lo = xs[best - 1], *flo = fs[best - 1], *m = xs[best], *fm = fs[best];
  *hi = xs[best + 1], *fhi = fs[best + 1];
  /* A tie with a neighbour is not a strict bracket; widen to the interval. */
  if (!(*fm < *flo && *fm < *fhi)) *lo = a, *flo = fa, *hi = b, *fhi = fb;
  return *fm < *flo && *fm < *fhi;
}

int sicm_min_brent(double (*f)(double, void *), void *params, double a, double b, double tol,
                   double *xmin, double *fmin, int *iterations) {
  static const char who[] = "sicm_min_brent";
  if (!(a < b) || !isfinite(a) || !isfinite(b))
    return sicm_error(SICM_EINVAL, "%s: the interval [%g, %g] is not a finite interval a < b", who,
                      a, b);
  if (!(tol > 0) || !isfinite(tol))
    return sicm_error(SICM_EINVAL, "%s: the tolerance %g must be positive and finite", who, tol);
  fn1 w = {f, params, 0, 0, 0};
  double fa = call1(a, &w), fb = call1(b, &w);
  if (w.bad) return bad_value1(who, &w);
  double lo, flo, m, fm, hi, fhi;
  int iter = 0, status = SICM_SUCCESS;
  double x, fx;
  if (!find_bracket(&w, a, fa, b, fb, &lo, &flo, &m, &fm, &hi, &fhi)) {
    if (w.bad) return bad_value1(who, &w);
    /* f is lowest at an end among all samples: take that end. */
    x = fa <= fb ? a : b;
    fx = fa <= fb ? fa : fb;
  } else {
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    gsl_min_fminimizer *s = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    gsl_function F = {call1, &w};
    if (!s) {
      gsl_set_error_handler(old);
      return sicm_error(SICM_ENOMEM, "%s: out of memory", who);
    }
    int gs = gsl_min_fminimizer_set_with_values(s, &F, m, fm, lo, flo, hi, fhi), stalled = 0;
    while (gs == GSL_SUCCESS) {
      if (iter >= kBrentMaxIter) {
        gs = GSL_EMAXITER;
        break;
      }
      iter++;
      const double l0 = gsl_min_fminimizer_x_lower(s), u0 = gsl_min_fminimizer_x_upper(s);
      gs = gsl_min_fminimizer_iterate(s);
      if (w.bad) break;
      if (gs != GSL_SUCCESS) break;
      double l = gsl_min_fminimizer_x_lower(s), u = gsl_min_fminimizer_x_upper(s);
      /* GSL never places trial points closer than sqrt(eps) |x| to the best
       * one, so the bracket cannot shrink below about 2 sqrt(eps) |x|; when
       * it stops shrinking altogether the minimum is as located as it gets. */
      if (gsl_min_test_interval(l, u, tol, 3 * sqrt(DBL_EPSILON)) == GSL_SUCCESS) break;
      stalled = l == l0 && u == u0 ? stalled + 1 : 0;
      if (stalled >= kStallLimit) break;
    }
    x = gsl_min_fminimizer_x_minimum(s);
    fx = gsl_min_fminimizer_f_minimum(s);
    gsl_min_fminimizer_free(s);
    gsl_set_error_handler(old);
    if (w.bad) {
      status = bad_value1(who, &w);
    } else if (gs == GSL_EMAXITER) {
      status = sicm_error(SICM_EMAXITER,
                          "%s: no convergence to tolerance %g in %d iterations; best point "
                          "x = %.17g, f = %.17g",
                          who, tol, kBrentMaxIter, x, fx);
    } else if (gs != GSL_SUCCESS) {
      status = sicm_error(SICM_EFAILED, "%s: GSL: %s (best point x = %.17g, f = %.17g)", who,
                          gsl_strerror(gs), x, fx);
    }
  }
  if (xmin) *xmin = x;
  if (fmin) *fmin = fx;
  if (iterations) *iterations = iter;
  return status;
}
