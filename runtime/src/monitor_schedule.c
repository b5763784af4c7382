/* The times at which evolve calls its monitor (sicm/ode.h): walked by sicm
 * run's evolve and by built programs' sicm_drive_evolve alike, so that the
 * two integrate over the same intervals and print the same bits. */
#include <math.h>

#include "sicm/runtime.h"

const char *sicm_monitor_schedule_start(sicm_monitor_schedule *s, double t0, double dt,
                                        double t_final) {
  if (dt == 0 && t_final != t0) return "the step between monitor calls is 0";
  s->t0 = t0;
  s->t_final = t_final;
  /* The sign of dt is not the direction: evolve goes towards t_final. */
  s->step = fabs(dt) * (t_final >= t0 ? 1.0 : -1.0);
  /* A last interval shorter than this is merged into the one before it, so
   * that rounding in t0 + k * step never leaves a sliver of a step. */
  s->near_end = 1e-9 * fabs(s->step);
  s->k = 0;
  return NULL;
}

int sicm_monitor_schedule_next(sicm_monitor_schedule *s, double t, double *tk) {
  if (!(fabs(s->t_final - t) > 0)) return 0;
  ++s->k;
  /* t0 + k * step, not a running sum: no accumulated rounding. */
  double next = s->t0 + (double)s->k * s->step;
  if ((s->step > 0 ? s->t_final - next : next - s->t_final) <= s->near_end) next = s->t_final;
  *tk = next;
  return 1;
}
