/* The integration the hand-written programs of bench/scale share: GSL's rk8pd, as sicm's runtime
 * drives it.
 *
 * Included at the end of hand_chain.c and hand_nbody.c (so that each hand-written program is one
 * translation unit, compiled by one cc command as sicm's generated C is), after they define
 *   DIM                       the number of state components (without the time)
 *   hand_deriv(y, dydt)       the derivative of the state y[0..DIM-1]
 *   hand_energy(y)            the conserved energy, to report its drift
 *   hand_watch(y)             optional (define HAND_WATCH): called after every accepted step
 * and params.h has given N, TOL, T_FINAL and y_initial[DIM].
 *
 * The error control is sicm's for a state-advancer tolerance TOL (runtime/src/program.c passes
 * it as both abs_tol and rel_tol; runtime/src/ode.c drives GSL with the standard control,
 * a_y = 1, a_dydt = 0): a step is accepted when |err_i| <= TOL + TOL |y_i| for every component.
 * Two differences from sicm's runtime, neither of which changes what is integrated: sicm carries
 * the time as the state's first component (its derivative is 1 and its error estimate 0, so it
 * never limits a step), and chooses the first step by Hairer's rule where this starts at
 * h = 1e-6, as GSL's driver does, and lets the control grow it (at most 5x a step).
 *
 * Prints the final state on stdout, the time first as sicm's state has it, %.17g separated by
 * spaces; on stderr one line "steps S rhs R energy-drift D [closest C]". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

static unsigned long hand_rhs_calls;

static int hand_gsl_rhs(double t, const double *y, double *dydt, void *params) {
  (void)t;
  (void)params;
  hand_rhs_calls++;
  hand_deriv(y, dydt);
  return GSL_SUCCESS;
}

int main(void) {
  double y[DIM];
  memcpy(y, y_initial, sizeof y);
  const double e0 = hand_energy(y);
  gsl_odeiv2_system sys = {hand_gsl_rhs, NULL, DIM, NULL};
  gsl_odeiv2_step *step = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, DIM);
  gsl_odeiv2_control *control = gsl_odeiv2_control_standard_new(TOL, TOL, 1.0, 0.0);
  gsl_odeiv2_evolve *evolve = gsl_odeiv2_evolve_alloc(DIM);
  double t = 0.0, h = 1e-6;
  unsigned long steps = 0;
  while (t < T_FINAL) {
    int status = gsl_odeiv2_evolve_apply(evolve, control, step, &sys, &t, T_FINAL, &h, y);
    if (status != GSL_SUCCESS) {
      fprintf(stderr, "rk8pd failed at t = %.17g: %s\n", t, gsl_strerror(status));
      return 1;
    }
    steps++;
#ifdef HAND_WATCH
    hand_watch(y);
#endif
  }
  printf("%.17g", T_FINAL);
  for (int i = 0; i < DIM; i++)
    printf(" %.17g", y[i]);
  printf("\n");
  fprintf(stderr, "steps %lu rhs %lu energy-drift %.3g", steps, hand_rhs_calls,
          fabs(hand_energy(y) - e0) / fmax(1.0, fabs(e0)));
#ifdef HAND_WATCH
  fprintf(stderr, " closest %.3g", hand_closest);
#endif
  fprintf(stderr, "\n");
  gsl_odeiv2_evolve_free(evolve);
  gsl_odeiv2_control_free(control);
  gsl_odeiv2_step_free(step);
  return 0;
}
