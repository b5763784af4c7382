/* Work-precision sweep of the runtime's adaptive ODE integrators on the Kepler problem.
 *
 * For each integrator and each tolerance 1e-4, 1e-5, ..., 1e-13 (passed as both abs_tol and
 * rel_tol, as the interpreter does), integrate a Kepler orbit of eccentricity 0.5 over ten
 * periods and print the global error (the orbit returns exactly to its start after each
 * period), the rhs evaluations, the accepted and rejected steps and the CPU time, as a TSV
 * table on stdout. Not part of `make`; build and run from the repository root with
 *
 *   make build/libsicmrt.a
 *   cc -std=c11 -O2 -Iruntime/include bench/ode_work_precision.c build/libsicmrt.a \
 *      -lsundials_cvode -lsundials_nvecserial -lgsl -lgslcblas -lm -o build/ode-work-precision
 *   build/ode-work-precision [eccentricity]
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "sicm/runtime.h"

static const double kPi = 3.14159265358979323846;

/* y = (x, y, vx, vy), GM = 1. */
static int kepler(double t, const double *y, double *dy, void *params) {
  (void)t, (void)params;
  const double r2 = y[0] * y[0] + y[1] * y[1], r3 = r2 * sqrt(r2);
  dy[0] = y[2];
  dy[1] = y[3];
  dy[2] = -y[0] / r3;
  dy[3] = -y[1] / r3;
  return 0;
}

static double seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void quiet(const char *reason, int status) {
  (void)reason, (void)status;
}

int main(int argc, char **argv) {
  const double e = argc > 1 ? atof(argv[1]) : 0.5;
  if (!(e >= 0 && e < 1)) {
    fprintf(stderr, "usage: %s [eccentricity in [0, 1)]\n", argv[0]);
    return 2;
  }
  const sicm_ode_step_type *types[] = {
      sicm_ode_step_rk8pd, sicm_ode_step_rkf45,       sicm_ode_step_rkck,     sicm_ode_step_bs,
      sicm_ode_step_msbdf, sicm_ode_step_cvode_adams, sicm_ode_step_cvode_bdf};
  const double y0[4] = {1 - e, 0, 0, sqrt((1 + e) / (1 - e))}, t1 = 10 * 2 * kPi;
  sicm_set_error_handler(quiet);
  printf("method\ttolerance\terror\trhs_evals\tsteps\trejected\tseconds\n");
  for (size_t m = 0; m < sizeof types / sizeof *types; m++) {
    for (int k = 4; k <= 13; k++) {
      const double tol = pow(10.0, -k);
      sicm_ode *o = sicm_ode_alloc(types[m], 4, kepler, NULL, tol, tol);
      double t = 0, y[4] = {y0[0], y0[1], y0[2], y0[3]};
      const double start = seconds();
      int status = sicm_ode_evolve(o, &t, t1, y);
      const double elapsed = seconds() - start;
      double err = 0;
      for (int i = 0; i < 4; i++)
        err = fmax(err, fabs(y[i] - y0[i]));
      const sicm_ode_stats *st = sicm_ode_get_stats(o);
      if (status == SICM_SUCCESS)
        printf("%s\t%.0e\t%.3e\t%lu\t%lu\t%lu\t%.4f\n", sicm_ode_name(o), tol, err, st->rhs_evals,
               st->steps, st->rejected_steps, elapsed);
      else
        printf("%s\t%.0e\tfailed: %s\n", sicm_ode_name(o), tol, sicm_ode_last_error(o));
      sicm_ode_free(o);
    }
  }
  return 0;
}
