/* The Nelder-Mead downhill simplex method (see sicm_min_nelder_mead in
 * sicm/min.h), with the standard coefficients (reflection 1, expansion 2,
 * contraction 1/2, shrink 1/2; Lagarias, Reeds, Wright and Wright 1998).
 *
 * Ours rather than GSL's nmsimplex2 because of when it stops: as in
 * scmutils, also when the values at the simplex's vertices agree to the
 * tolerance. GSL stops only on the simplex's size, which a function
 * computed with rounding noise (an action computed by quadrature, as
 * find-path minimizes) may never bring below the tolerance: the simplex
 * wanders on the noise at the exact answer until the iteration limit. GSL
 * does not let a caller see the vertices' values. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sicm/runtime.h"

typedef struct {
  double (*f)(const double *, void *);
  void *params;
  size_t n;
  double *v;  /* (n + 1) vertices of n coordinates, row k at v + k n */
  double *fv; /* their values (+inf where f was not finite) */
  int bad;    /* f returned a non-finite value somewhere */
} simplex;

static double value_at(simplex *s, const double *x) {
  double y = s->f(x, s->params);
  if (isfinite(y)) return y;
  s->bad = 1;
  return INFINITY; /* loses every comparison */
}

static double *vertex(simplex *s, size_t k) {
  return s->v + k * s->n;
}

/* The indices of the best, the worst and the second worst vertex. */
static void rank_vertices(const simplex *s, size_t *best, size_t *worst, size_t *second) {
  *best = 0, *worst = 0;
  for (size_t k = 1; k <= s->n; k++) {
    if (s->fv[k] < s->fv[*best]) *best = k;
    if (s->fv[k] >= s->fv[*worst]) *worst = k;
  }
  *second = *best;
  for (size_t k = 0; k <= s->n; k++)
    if (k != *worst && s->fv[k] >= s->fv[*second]) *second = k;
}

/* The mean distance of the vertices from their centre. */
static double simplex_size(const simplex *s, double *centre) {
  size_t n = s->n;
  for (size_t i = 0; i < n; i++) {
    double sum = 0;
    for (size_t k = 0; k <= n; k++)
      sum += vertex((simplex *)s, k)[i];
    centre[i] = sum / (double)(n + 1);
  }
  double total = 0;
  for (size_t k = 0; k <= n; k++) {
    double d2 = 0;
    for (size_t i = 0; i < n; i++) {
      double d = vertex((simplex *)s, k)[i] - centre[i];
      d2 += d * d;
    }
    total += sqrt(d2);
  }
  return total / (double)(n + 1);
}

/* out = c + t (c - w): the point on the line from the worst vertex w through
 * the centroid c of the others, at parameter t (1 reflects, 2 expands, 1/2
 * and -1/2 contract outside and inside). 0 if a coordinate overflowed: the
 * simplex has run off to infinity, where its values would agree. */
static int along(size_t n, const double *c, const double *w, double t, double *out) {
  int finite = 1;
  for (size_t i = 0; i < n; i++) {
    out[i] = c[i] + t * (c[i] - w[i]);
    finite = finite && isfinite(out[i]);
  }
  return finite;
}

int sicm_min_nelder_mead(double (*f)(const double *x, void *), void *params, size_t n, double *x,
                         double step, double tol, int max_iter, double *fmin, int *iterations) {
  static const char who[] = "sicm_min_nelder_mead";
  if (n == 0 || !(step > 0) || !isfinite(step) || !(tol >= 0) || !isfinite(tol) || max_iter <= 0)
    return sicm_error(SICM_EINVAL,
                      "%s: need n >= 1, a positive step, tol >= 0 and max_iter > 0 (n = %zu, "
                      "step = %g, tol = %g, max_iter = %d)",
                      who, n, step, tol, max_iter);
  for (size_t i = 0; i < n; i++)
    if (!isfinite(x[i]))
      return sicm_error(SICM_EINVAL, "%s: the starting point has a non-finite component x[%zu]",
                        who, i);
  simplex s = {f, params, n, malloc((n + 1) * n * sizeof(double)), malloc((n + 1) * sizeof(double)),
               0};
  double *work = malloc(4 * n * sizeof(double)); /* centroid, two trial points, centre */
  int status = SICM_SUCCESS, iter = 0;
  size_t best = 0, worst = 0, second = 0;
  if (!s.v || !s.fv || !work) {
    status = sicm_error(SICM_ENOMEM, "%s: out of memory", who);
    goto done;
  }
  double *c = work, *trial = work + n, *trial2 = work + 2 * n, *centre = work + 3 * n;
  for (size_t k = 0; k <= n; k++) {
    memcpy(vertex(&s, k), x, n * sizeof(double));
    if (k > 0) vertex(&s, k)[k - 1] += step;
    s.fv[k] = value_at(&s, vertex(&s, k));
  }
  if (s.bad) {
    status = sicm_error(SICM_EBADFUNC,
                        "%s: the function is not finite on the starting simplex (start and step "
                        "%g)",
                        who, step);
    goto done;
  }
  for (;;) {
    rank_vertices(&s, &best, &worst, &second);
    double fb = s.fv[best], fw = s.fv[worst];
    if (simplex_size(&s, centre) < tol || fw - fb <= tol * 0.5 * (fabs(fb) + fabs(fw))) break;
    if (iter >= max_iter) {
      status = sicm_error(SICM_EMAXITER,
                          "%s: simplex size %g and spread of values %g still above tolerance %g "
                          "after %d iterations; x holds the best point, f = %.17g",
                          who, simplex_size(&s, centre), fw - fb, tol, max_iter, fb);
      break;
    }
    iter++;
    const double *w = vertex(&s, worst);
    for (size_t i = 0; i < n; i++) {
      double sum = 0;
      for (size_t k = 0; k <= n; k++)
        if (k != worst) sum += vertex(&s, k)[i];
      c[i] = sum / (double)n;
    }
    if (!along(n, c, w, 1, trial) || !along(n, c, w, 2, trial2)) {
      status = sicm_error(SICM_EMAXITER,
                          "%s: the simplex ran off to infinity after %d iterations (no minimum "
                          "near the start?); x holds the best point, f = %.17g",
                          who, iter, fb);
      break;
    }
    double fr = value_at(&s, trial), fnew;
    const double *accepted = NULL;
    if (fr < fb) {
      double fe = value_at(&s, trial2);
      accepted = fe < fr ? trial2 : trial;
      fnew = fe < fr ? fe : fr;
    } else if (fr < s.fv[second]) {
      accepted = trial, fnew = fr;
    } else {
      int outside = fr < fw;
      along(n, c, w, outside ? 0.5 : -0.5, trial2);
      double fc = value_at(&s, trial2);
      if (outside ? fc <= fr : fc < fw) accepted = trial2, fnew = fc;
    }
    if (accepted) {
      memcpy(vertex(&s, worst), accepted, n * sizeof(double));
      s.fv[worst] = fnew;
      continue;
    }
    for (size_t k = 0; k <= n; k++) { /* shrink towards the best vertex */
      if (k == best) continue;
      for (size_t i = 0; i < n; i++)
        vertex(&s, k)[i] = vertex(&s, best)[i] + 0.5 * (vertex(&s, k)[i] - vertex(&s, best)[i]);
      s.fv[k] = value_at(&s, vertex(&s, k));
    }
  }
  rank_vertices(&s, &best, &worst, &second);
  if (status == SICM_SUCCESS && !isfinite(s.fv[best]))
    status = sicm_error(SICM_EBADFUNC, "%s: the function is not finite at the best point", who);
  memcpy(x, vertex(&s, best), n * sizeof(double));
  if (fmin) *fmin = s.fv[best];
done:
  if (iterations) *iterations = iter;
  free(s.v);
  free(s.fv);
  free(work);
  return status;
}

char *sicm_min_nelder_mead_failure(char *buf, int iterations, size_t n, const double *x,
                                   double fmin, int as_list) {
  const size_t size = SICM_MIN_FAILURE_BUFSIZE;
  /* Room kept for the "...", the value and the closing text. */
  const size_t point_room = size - 3 * SICM_DOUBLE_BUFSIZE;
  char number[SICM_DOUBLE_BUFSIZE];
  size_t used =
      (size_t)snprintf(buf, size, "the minimizer did not converge in %d iterations (best point %s",
                       iterations, as_list ? "(" : "#(");
  for (size_t i = 0; i < n; ++i) {
    sicm_format_double(number, x[i]);
    if (used + strlen(number) + 1 >= point_room) {
      used += (size_t)snprintf(buf + used, size - used, " ...");
      break;
    }
    used += (size_t)snprintf(buf + used, size - used, "%s%s", i ? " " : "", number);
  }
  sicm_format_double(number, fmin);
  snprintf(buf + used, size - used, "), value %s)", number);
  return buf;
}
