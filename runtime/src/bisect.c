/* scmutils' bisect (see sicm_root_bisect in sicm/root.h): the one
 * implementation, which the interpreter's primitive and built programs'
 * driver both call, so that they take the same steps. */
#include <float.h>
#include <math.h>

#include "sicm/runtime.h"

/* scmutils' close-enuf?: |x - y| <= tol/2 (|x| + |y| + 2), tol at least the
 * machine epsilon. */
static int close_enough(double x, double y, double tol) {
  return fabs(x - y) <= 0.5 * fmax(tol, DBL_EPSILON) * (fabs(x) + fabs(y) + 2);
}

static int sign_of(double v) {
  return v > 0 ? 1 : v < 0 ? -1 : 0;
}

int sicm_root_bisect(double (*f)(double, void *), void *params, double x0, double x1, double eps,
                     long n_break, long max_iter, double *root, double bracket[2],
                     double values[2]) {
  double f0 = f(x0, params), f1 = f(x1, params);
  int status = SICM_SUCCESS;
  for (long iter = 0;; ++iter) {
    if (f0 == 0 || f1 == 0) {
      *root = f0 == 0 ? x0 : x1;
      break;
    }
    if (sign_of(f0) * sign_of(f1) > 0 || isnan(f0) || isnan(f1)) {
      status = SICM_EBRACKET;
      break;
    }
    double xm = iter < n_break ? (x0 + x1) / 2 : (f1 * x0 - f0 * x1) / (f1 - f0);
    if (close_enough(x0, x1, eps)) {
      *root = xm;
      break;
    }
    if (iter >= max_iter) {
      status = SICM_EMAXITER;
      break;
    }
    double fm = f(xm, params);
    if (sign_of(f1) * sign_of(fm) < 0) {
      x0 = xm;
      f0 = fm;
    } else {
      x1 = xm;
      f1 = fm;
    }
  }
  bracket[0] = x0, bracket[1] = x1;
  values[0] = f0, values[1] = f1;
  return status;
}
