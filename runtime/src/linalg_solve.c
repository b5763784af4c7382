/* Linear solves in the interpreter's order of operations (see sicm/linalg.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sicm/runtime.h"

int sicm_linalg_solve_as_interpreted(size_t n, const double *a, const double *b, double *x) {
  const size_t w = 2 * n; /* [A | I], row-major */
  double *d = malloc(n * w * sizeof *d);
  if (!d) return SICM_ENOMEM;
  for (size_t i = 0; i < n; i++)
    for (size_t j = 0; j < w; j++)
      d[i * w + j] = j < n ? a[i * n + j] : (j - n == i ? 1.0 : 0.0);
  int status = SICM_SUCCESS;
  for (size_t c = 0; c < n && status == SICM_SUCCESS; c++) {
    size_t p = n; /* the nonzero entry of largest magnitude at or below the diagonal */
    for (size_t r = c; r < n; r++)
      if (d[r * w + c] != 0 && (p == n || fabs(d[r * w + c]) > fabs(d[p * w + c]))) p = r;
    if (p == n) {
      status = SICM_ESINGULAR;
      break;
    }
    for (size_t j = 0; j < w; j++) {
      double t = d[p * w + j];
      d[p * w + j] = d[c * w + j];
      d[c * w + j] = t;
    }
    double pivot = d[c * w + c];
    for (size_t j = c; j < w; j++)
      d[c * w + j] /= pivot;
    for (size_t r = 0; r < n; r++) {
      double f = d[r * w + c];
      if (r == c || f == 0) continue;
      for (size_t j = c; j < w; j++)
        d[r * w + j] -= f * d[c * w + j];
    }
  }
  for (size_t i = 0; i < n; i++) {
    if (status != SICM_SUCCESS) {
      x[i] = NAN;
      continue;
    }
    double sum = d[i * w + n] * b[0];
    for (size_t k = 1; k < n; k++)
      sum += d[i * w + n + k] * b[k];
    x[i] = sum;
  }
  free(d);
  return status;
}
