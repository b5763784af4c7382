/* sicm runtime: minimization of functions of one variable (Brent) and of several (Nelder-Mead). */
#ifndef SICM_MIN_H
#define SICM_MIN_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* sicm_min_brent finds a minimum of f on [a, b] (a < b) by Brent's method
 * (golden-section search accelerated by parabolic interpolation, GSL's
 * gsl_min_fminimizer_brent) and stores its argument in *xmin, the value
 * there in *fmin and the number of Brent iterations in *iterations (any of
 * the three pointers may be NULL).
 *
 * Brent's method needs a point inside the interval lower than both ends. It
 * tries the golden-section point first, then a uniform grid of 64 interior
 * points; if no interior point beats the ends, f is taken to decrease towards
 * the better end and that end is returned (with *iterations = 0). Like every
 * local method it finds one local minimum, the one whose basin holds the
 * best point sampled.
 *
 * The search stops when the bracket around the minimum is narrower than
 * tol + 3 sqrt(DBL_EPSILON) |x|, or when Brent's method cannot narrow it any
 * more: a minimum cannot be located more finely than about sqrt(DBL_EPSILON)
 * |x| in double precision, because f is flat there (f(x + d) - f(x) is of
 * order d^2, lost in rounding for smaller d). For a smooth f the returned
 * *xmin is usually much closer than the bracket, since the last steps are
 * parabolic interpolation, and *fmin is accurate to rounding. tol must be
 * positive.
 *
 * Returns SICM_SUCCESS; SICM_EINVAL for a bad interval or tolerance;
 * SICM_EBADFUNC if f returns a non-finite value; SICM_EMAXITER if 1000
 * iterations do not suffice (*xmin, *fmin then hold the best point found). */
int sicm_min_brent(double (*f)(double, void *), void *params, double a, double b, double tol,
                   double *xmin, double *fmin, int *iterations);

/* sicm_min_nelder_mead minimizes f over R^n (n >= 1) by the Nelder-Mead
 * downhill simplex method (runtime/src/nelder_mead.c).
 *
 * x[0..n-1] is the starting point on entry and the best point found on
 * return; step (> 0) is the size of the initial simplex along each axis.
 * The search stops when the simplex size (the mean distance of its vertices
 * from their centre) is below tol (>= 0), or, as scmutils' nelder-mead
 * does, when the values at its vertices agree to tol relative to their size
 * (f_worst - f_best <= tol (|f_best| + |f_worst|) / 2), and fails with
 * SICM_EMAXITER after max_iter (> 0) iterations, or earlier when the
 * simplex runs off to infinity (f has no minimum near the start). The minimum's value is stored in
 * *fmin and the number of iterations in *iterations (both may be NULL).
 *
 * Nelder-Mead needs no derivatives and tolerates noise, but it converges
 * slowly and can stall on a non-minimum in rare cases; restarting from the
 * result is a cheap check.
 *
 * Returns SICM_SUCCESS; SICM_EINVAL for bad arguments; SICM_ENOMEM;
 * SICM_EBADFUNC if f returns a non-finite value at the starting simplex;
 * SICM_EMAXITER (x then holds the best point so far). */
int sicm_min_nelder_mead(double (*f)(const double *x, void *), void *params, size_t n, double *x,
                         double step, double tol, int max_iter, double *fmin, int *iterations);

/* sicm_min_nelder_mead_failure writes into buf (SICM_MIN_FAILURE_BUFSIZE
 * bytes) why a minimization ended without converging, as
 * multidimensional-minimize says it in sicm run and in built programs
 * alike: "the minimizer did not converge in N iterations (best point
 * (x0 x1 ...), value f)", the point a list, or a vector "#(x0 x1 ...)" when
 * as_list is 0 (a point too long for the buffer ends in "..."). Returns buf. */
#define SICM_MIN_FAILURE_BUFSIZE 4096
char *sicm_min_nelder_mead_failure(char *buf, int iterations, size_t n, const double *x,
                                   double fmin, int as_list);

#ifdef __cplusplus
}
#endif

#endif /* SICM_MIN_H */
