/* Taylor series: high-order steps from generated Taylor coefficients, order and step from the
 * tolerance.
 *
 * Approach. The coefficient function (sicm_ode_set_taylor; the compiler
 * generates it from the system derivative's DAG, codegen/emit_taylor.hpp)
 * gives the normalized Taylor coefficients c_0 = y, c_1, ..., c_p of the
 * solution through the current state, and the step is the polynomial
 * y(t + h) = sum_k c_k h^k, evaluated by Horner's rule. Order and step
 * follow Jorba and Zou ("A software package for the numerical integration
 * of ODEs by means of high-order Taylor methods", Experimental Mathematics
 * 14, 2005, section 3.2): for a tolerance eps the optimal order is about
 * -ln(eps)/2 + 1, fixed for the whole integration, and the step is chosen
 * so that the last two terms of the series are below eps,
 *
 *     h = min( (1/rho_{p-1})^(1/(p-1)), (1/rho_p)^(1/p) ) exp(-0.7/(p-1))
 *
 * where rho_k = max_i |c_k,i| / (abs_tol + rel_tol |y_i|) weighs each
 * coefficient as the other methods weigh errors, and the last factor is
 * Jorba and Zou's safety factor. eps for the order is the smaller non-zero
 * tolerance. There is no error estimate and so no rejected step: the terms
 * left out are bounded by the last ones kept as long as the series converges
 * geometrically, which holds when h stays well inside its radius of
 * convergence, which these h estimate.
 *
 * Each step costs one expansion, O(p^2) operations per operation of the
 * derivative, counted as one rhs evaluation in the statistics. Steps are as
 * long as the series allows up to the caller's horizon; a t1 inside a step
 * is answered from its polynomial (dense output), so a monitor called every
 * dt costs no extra steps (ode_taylor_method.h).
 *
 * Precision. taylor works in double; taylor-extended in long double (64-bit
 * significand on x86: rounding 5e-20), from a coefficient function
 * generated in long double (sicm_ode_set_taylor_extended). Its own state
 * stays in long double between the caller's stops. long double rather than
 * __float128: the x87 unit does it in hardware. Measured on the Kepler
 * problem's coefficients at order 22 (7000 expansions): double 5.3 ms, long
 * double 24 ms (4.6x), __float128 through libquadmath's software arithmetic
 * 360 ms (70x). long double reaches 1e-18 relative, what a reference for the
 * double methods needs.
 *
 * Errors. Non-finite coefficients (the state is at a singularity of the
 * equations) fail with SICM_EBADFUNC, a step that would not move t with
 * SICM_ESTEP, a non-finite new state with SICM_EBADFUNC.
 *
 * Limits. Explicit: on stiff problems the step is held by the radius of
 * convergence and the work explodes; there is no stiffness watch. The
 * coefficients must not depend on the integrator's t (autonomous systems,
 * time a component of the state, as in SICM's states). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ode_internal.h"

int sicm_ode_taylor_order(double abs_tol, double rel_tol) {
  double eps = abs_tol;
  if (eps == 0 || (rel_tol > 0 && rel_tol < eps)) eps = rel_tol;
  int p = (int)ceil(-log(eps) / 2) + 1;
  if (p < 2) p = 2;
  if (p > SICM_ODE_TAYLOR_MAX_ORDER) p = SICM_ODE_TAYLOR_MAX_ORDER;
  return p;
}

static int taylor_order(const sicm_ode *o) {
  return sicm_ode_taylor_order(o->abs_tol, o->rel_tol);
}

#define REAL double
#define NAME(x) taylor_##x
#define COEFFICIENTS o->taylor
#define FABS fabs
#define TAYLOR_METHOD_NAME "taylor"
#define SET_COEFFICIENTS "sicm_ode_set_taylor"
#include "ode_taylor_method.h"
#undef REAL
#undef NAME
#undef COEFFICIENTS
#undef FABS
#undef TAYLOR_METHOD_NAME
#undef SET_COEFFICIENTS

#define REAL long double
#define NAME(x) taylor_ext_##x
#define COEFFICIENTS o->taylor_extended
#define FABS fabsl
#define TAYLOR_METHOD_NAME "taylor-extended"
#define SET_COEFFICIENTS "sicm_ode_set_taylor_extended"
#include "ode_taylor_method.h"
#undef REAL
#undef NAME
#undef COEFFICIENTS
#undef FABS
#undef TAYLOR_METHOD_NAME
#undef SET_COEFFICIENTS

const sicm_ode_step_type sicm_ode_taylor_type = {
    "taylor", taylor_init, taylor_evolve, taylor_reset, taylor_free, NULL, taylor_dense};
const sicm_ode_step_type sicm_ode_taylor_extended_type = {
    "taylor-extended", taylor_ext_init, taylor_ext_evolve, taylor_ext_reset, taylor_ext_free, NULL,
    taylor_ext_dense};
