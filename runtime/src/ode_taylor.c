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
 * derivative, counted as one rhs evaluation in the statistics. Steps end
 * exactly at t1: the last one is shortened.
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

typedef struct {
  int order;
  double *c;    /* (order + 1) * dim coefficients */
  double *comp; /* dim: the rounding error of y, carried (compensated summation) */
} taylor_state;

/* The order for tolerance eps (Jorba-Zou), within 2..SICM_ODE_TAYLOR_MAX_ORDER. */
static int order_for(const sicm_ode *o) {
  double eps = o->abs_tol;
  if (eps == 0 || (o->rel_tol > 0 && o->rel_tol < eps)) eps = o->rel_tol;
  int p = (int)ceil(-log(eps) / 2) + 1;
  if (p < 2) p = 2;
  if (p > SICM_ODE_TAYLOR_MAX_ORDER) p = SICM_ODE_TAYLOR_MAX_ORDER;
  return p;
}

static int taylor_init(sicm_ode *o) {
  taylor_state *s = calloc(1, sizeof *s);
  if (!s) return SICM_ENOMEM;
  s->order = order_for(o);
  s->c = malloc((size_t)(s->order + 1) * o->dim * sizeof *s->c);
  s->comp = calloc(o->dim, sizeof *s->comp);
  o->backend = s;
  return s->c && s->comp ? SICM_SUCCESS : SICM_ENOMEM;
}

static void taylor_reset(sicm_ode *o) {
  taylor_state *s = o->backend;
  memset(s->comp, 0, o->dim * sizeof *s->comp);
}

static void taylor_free(sicm_ode *o) {
  taylor_state *s = o->backend;
  free(s->c);
  free(s->comp);
  free(s);
}

/* rho_k: the size of coefficient k against the tolerances at y. */
static double scaled_size(const sicm_ode *o, const double *ck, const double *y) {
  double m = 0;
  for (size_t i = 0; i < o->dim; i++)
    m = fmax(m, fabs(ck[i]) / (o->abs_tol + o->rel_tol * fabs(y[i])));
  return m;
}

/* The step size the coefficients allow (positive; INFINITY when the series
 * ends before order p - 1, as for a polynomial solution). */
static double step_for(const sicm_ode *o, const taylor_state *s, const double *y) {
  const int p = s->order;
  const double safety = exp(-0.7 / (p - 1));
  double h = INFINITY;
  for (int k = p - 1; k <= p; k++) {
    double rho = scaled_size(o, s->c + (size_t)k * o->dim, y);
    if (rho > 0) h = fmin(h, pow(rho, -1.0 / k));
  }
  return h * safety;
}

static int taylor_evolve(sicm_ode *o, double *t, double t1, double *y) {
  taylor_state *s = o->backend;
  if (!o->taylor)
    return sicm_ode_fail(o, SICM_EINVAL, *t, y, "no Taylor coefficients",
                         "the taylor method needs a coefficient function (sicm_ode_set_taylor), "
                         "which the compiler makes from a compiled system derivative");
  const size_t dim = o->dim;
  const int p = s->order;
  const double dir = t1 > *t ? 1.0 : -1.0;
  unsigned long steps = 0;
  while (*t != t1) {
    if (steps >= o->max_steps) return sicm_ode_fail_max_steps(o, *t, y);
    o->taylor(y, p, s->c, o->taylor_params);
    o->stats.rhs_evals++;
    if (!sicm_ode_finite((size_t)(p + 1) * dim, s->c))
      return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite derivative",
                           "the Taylor coefficients of the solution are NaN or infinite here");
    double h = dir * step_for(o, s, y);
    int final = fabs(h) >= fabs(t1 - *t);
    if (final)
      h = t1 - *t;
    else
      o->h = h;
    /* The step the time will actually take: t + h rounds, and a state
     * advanced by the unrounded h would drift in phase from its time by an
     * ulp of t a step (3e-14 over ten periods of an oscillator). */
    if (!final) h = (*t + h) - *t;
    if (*t + h == *t) {
      char detail[160];
      snprintf(detail, sizeof detail,
               "the series allows only h = %.3g, below the resolution of t; the solution may be "
               "singular here",
               fabs(h));
      return sicm_ode_fail(o, SICM_ESTEP, *t, y, "step size too small", detail);
    }
    /* y += sum_{k>=1} c_k h^k by Horner, the increment added with Kahan's
     * compensation carried from step to step: the rounding of y, a few ulps
     * a step, would otherwise accumulate over the many steps of a long run. */
    for (size_t i = 0; i < dim; i++) {
      double v = s->c[(size_t)p * dim + i];
      for (int k = p - 1; k >= 1; k--)
        v = v * h + s->c[(size_t)k * dim + i];
      const double increment = v * h + s->comp[i];
      const double sum = y[i] + increment;
      s->comp[i] = (y[i] - sum) + increment;
      y[i] = sum;
    }
    if (!sicm_ode_finite(dim, y)) {
      memcpy(y, s->c, dim * sizeof *y); /* back to the last accepted point */
      taylor_reset(o);
      return sicm_ode_fail(o, SICM_EBADFUNC, *t, y, "non-finite state",
                           "a Taylor step gave NaN or infinite components");
    }
    *t = final ? t1 : *t + h;
    steps++;
    o->stats.steps++;
  }
  return SICM_SUCCESS;
}

const sicm_ode_step_type sicm_ode_taylor_type = {"taylor",     taylor_init, taylor_evolve,
                                                 taylor_reset, taylor_free, NULL};
