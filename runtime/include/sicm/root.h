/* sicm runtime: roots of functions of one variable (Brent; scmutils' bisect). */
#ifndef SICM_ROOT_H
#define SICM_ROOT_H

#ifdef __cplusplus
extern "C" {
#endif

/* sicm_root_brent finds a root of f in [a, b] by Brent's method (bisection
 * combined with inverse quadratic interpolation, GSL's
 * gsl_root_fsolver_brent) and stores it in *root.
 *
 * f(a) and f(b) must differ in sign (if one of them is zero, that end is the
 * root). The search stops when the bracket is narrower than
 * tol + 4 DBL_EPSILON |x| (tol >= 0; tol = 0 asks for full precision) or f
 * is exactly zero at the current estimate.
 *
 * Returns SICM_SUCCESS; SICM_EINVAL for a bad interval or tolerance;
 * SICM_EBRACKET if f(a) and f(b) have the same sign; SICM_EBADFUNC if f
 * returns a non-finite value; SICM_EMAXITER after 1000 iterations (*root
 * then holds the best estimate). */
int sicm_root_brent(double (*f)(double, void *), void *params, double a, double b, double tol,
                    double *root);

/* sicm_root_bisect is scmutils' bisect: a root of f between x0 and x1,
 * halving the bracket for its first n_break steps and then stepping by false
 * position, until the bracket's ends are close (|x0 - x1| <= eps/2 (|x0| +
 * |x1| + 2), eps at least DBL_EPSILON; *root is then the next point), or f is
 * exactly zero at an end (*root is that end). The last bracket and f's
 * values there are stored in bracket[] and values[], for the caller's
 * messages.
 *
 * Returns SICM_SUCCESS; SICM_EBRACKET if f has the same sign, or is NaN, at
 * the ends of a bracket; SICM_EMAXITER after max_iter steps. Reports nothing
 * through sicm_error: its callers (the bisect primitive, sicm_drive_bisect)
 * word the failure in Scheme's terms. */
int sicm_root_bisect(double (*f)(double, void *), void *params, double x0, double x1, double eps,
                     long n_break, long max_iter, double *root, double bracket[2],
                     double values[2]);

#ifdef __cplusplus
}
#endif

#endif /* SICM_ROOT_H */
