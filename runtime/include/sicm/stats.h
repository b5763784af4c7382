/* sicm runtime: what each integration cost (--stats of sicm run and of built programs). */
#ifndef SICM_STATS_H
#define SICM_STATS_H

#include <stdio.h>

#include "sicm/ode.h"

#ifdef __cplusplus
extern "C" {
#endif

/* sicm_stats_enable turns the record on (--stats); until then
 * sicm_stats_add does nothing, so a program that does not ask pays nothing
 * but the clock readings. */
void sicm_stats_enable(void);
int sicm_stats_enabled(void);

/* Seconds on a monotonic clock, to time integrations with. */
double sicm_stats_clock(void);

/* sicm_stats_add adds one integration's work to the line of its site:
 * where ("file:line:col" of the call), who ("evolve", "state-advancer"),
 * the method's name and the tolerance (the step size for the fixed-step
 * methods) make a line; work holds the steps, rejected steps and rhs
 * evaluations it took, seconds the time spent integrating (not in
 * monitors). Lines are kept in the order their sites were first met. */
void sicm_stats_add(const char *where, const char *who, const char *method, double tolerance,
                    const sicm_ode_stats *work, double seconds);

/* sicm_stats_add_events adds to the same line the events one integration
 * located (crossings) and the trial integrations their placement on the
 * solution cost; a line that has any says so. */
void sicm_stats_add_events(const char *where, const char *who, const char *method,
                           double tolerance, const sicm_ode_event_stats *events);

/* sicm_stats_print writes a header and one line per site to f, as
 *   FILE:LINE:COL: evolve, bulirsch-stoer, tolerance 1e-13: 2 calls, 1234 steps
 *   (56 rejected), 45678 rhs evaluations, .0123 s
 * and, where events were located, ", 12 events located (340 placement
 * integrations)" after the rhs evaluations
 * (on one line; numbers as the compiler prints them); nothing if no
 * integration was recorded. */
void sicm_stats_print(FILE *f);

#ifdef __cplusplus
}
#endif

#endif /* SICM_STATS_H */
