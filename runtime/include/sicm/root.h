/* sicm runtime: roots of functions of one variable (Brent). */
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

#ifdef __cplusplus
}
#endif

#endif /* SICM_ROOT_H */
