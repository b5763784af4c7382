/* sicm runtime: numerical quadrature (adaptive Gauss-Kronrod and Romberg). */
#ifndef SICM_QUAD_H
#define SICM_QUAD_H

#ifdef __cplusplus
extern "C" {
#endif

/* sicm_quad_integrate computes the integral of f from a to b to the relative
 * tolerance rel_tol and stores it in *result.
 *
 * For finite a and b it uses GSL's gsl_integration_qag with the 21-point
 * Gauss-Kronrod rule: the interval is bisected adaptively, always splitting
 * the subinterval with the largest error estimate, until the total error
 * estimate is at most rel_tol |result| (up to 1000 subintervals). If a or b
 * is infinite the integral is mapped to (0, 1] by x = a + (1 - u)/u (or its
 * mirror image) and integrated with the 15-point rule (gsl_integration_qagi,
 * qagiu, qagil). b < a gives minus the integral from b to a.
 *
 * Relative tolerances below 50 DBL_EPSILON (about 1.1e-14) cannot be met in
 * double precision and are raised to that value. A purely relative test
 * cannot be met by an integral that is exactly zero (e.g. sin over a full
 * period); such calls report SICM_ETOL with the best estimate, which is then
 * close to zero in absolute terms.
 *
 * Returns SICM_SUCCESS; SICM_EINVAL for a bad tolerance or a NaN limit;
 * SICM_EBADFUNC if f returns a non-finite value; SICM_ETOL if the tolerance
 * cannot be met (maximum subdivision reached, roundoff detected, or a
 * non-integrable singularity), in which case *result still holds the best
 * estimate and the reported message gives the error estimate. */
int sicm_quad_integrate(double (*f)(double, void *), void *params, double a, double b,
                        double rel_tol, double *result);

/* sicm_quad_romberg computes the integral of f over the finite interval
 * [a, b] by Romberg integration: the trapezoidal rule with 1, 2, 4, ...
 * 2^19 panels, extrapolated to zero panel width by Richardson's method
 * (GSL's gsl_integration_romberg). It converges very fast for smooth
 * integrands and poorly for integrands with singular derivatives (such as
 * sqrt(x) at 0), where sicm_quad_integrate is the better choice. It stops
 * when two successive extrapolations agree to rel_tol |result|.
 *
 * Returns SICM_SUCCESS; SICM_EINVAL for bad limits or tolerance;
 * SICM_EBADFUNC if f returns a non-finite value; SICM_ETOL if 2^19 + 1
 * evaluations do not reach the tolerance (*result then holds the last
 * estimate). */
int sicm_quad_romberg(double (*f)(double, void *), void *params, double a, double b, double rel_tol,
                      double *result);

#ifdef __cplusplus
}
#endif

#endif /* SICM_QUAD_H */
