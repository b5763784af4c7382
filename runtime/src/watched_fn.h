/* Private to the runtime: a user's function of one variable, watched for
 * non-finite values, so minimizers, root finders and quadrature can report
 * where the function broke instead of a later, vaguer failure. */
#ifndef SICM_WATCHED_FN_H
#define SICM_WATCHED_FN_H

#include <math.h>

#include "sicm/runtime.h"

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

/* Report the first non-finite value in the words sicm run uses (numbers
 * as the compiler prints them: "the function is +inf.0 at .1, not a finite
 * number"), so that a built program says what the interpreter says. */
static inline int fn1_nonfinite(const char *who, const fn1 *w) {
  char value[SICM_DOUBLE_BUFSIZE], at[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(value, w->bad_value);
  sicm_format_double(at, w->bad_x);
  return sicm_error(SICM_EBADFUNC, "%s: the function is %s at %s, not a finite number", who, value,
                    at);
}

#endif /* SICM_WATCHED_FN_H */
