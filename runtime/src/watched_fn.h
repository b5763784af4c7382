/* Private to the runtime: a user's function of one variable, watched for
 * non-finite values, so minimizers, root finders and quadrature can report
 * where the function broke instead of a later, vaguer failure. */
#ifndef SICM_WATCHED_FN_H
#define SICM_WATCHED_FN_H

#include <math.h>

typedef struct {
  double (*f)(double, void *);
  void *params;
  int bad;                 /* a non-finite value was seen */
  double bad_x, bad_value; /* the first one */
} fn1;

/* The GSL-shaped callback: data is a fn1. */
static inline double call1(double x, void *data) {
  fn1 *w = data;
  double v = w->f(x, w->params);
  if (!isfinite(v) && !w->bad) {
    w->bad = 1;
    w->bad_x = x;
    w->bad_value = v;
  }
  return v;
}

#endif /* SICM_WATCHED_FN_H */
