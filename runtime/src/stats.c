/* Per-site integration statistics for --stats (see sicm/stats.h).
 *
 * The members of a parallel sweep integrate on several threads at once, so
 * the record is behind a mutex; sicm_stats_enable is called before any
 * sweep (by sicm_program_init), so the flag itself needs none. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime, strdup */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sicm/runtime.h"

typedef struct {
  char *where, *who, *method;
  double tolerance;
  unsigned long calls;
  sicm_ode_stats work;
  double seconds;
  sicm_ode_event_stats events;
} site_line;

static int enabled;
static site_line *lines;
static size_t nlines, capacity;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

void sicm_stats_enable(void) {
  enabled = 1;
}

int sicm_stats_enabled(void) {
  return enabled;
}

double sicm_stats_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static site_line *line_of(const char *where, const char *who, const char *method,
                          double tolerance) {
  for (size_t i = 0; i < nlines; i++)
    if (strcmp(lines[i].where, where) == 0 && strcmp(lines[i].who, who) == 0 &&
        strcmp(lines[i].method, method) == 0 && lines[i].tolerance == tolerance)
      return &lines[i];
  if (nlines == capacity) {
    size_t more = capacity ? 2 * capacity : 16;
    site_line *grown = realloc(lines, more * sizeof *grown);
    if (!grown) return NULL;
    lines = grown;
    capacity = more;
  }
  site_line *l = &lines[nlines];
  *l = (site_line){strdup(where), strdup(who), strdup(method), tolerance, 0,
                   {0, 0, 0, 0},  0,           {0, 0, 0}};
  if (!l->where || !l->who || !l->method) {
    free(l->where), free(l->who), free(l->method);
    return NULL;
  }
  nlines++;
  return l;
}

void sicm_stats_add(const char *where, const char *who, const char *method, double tolerance,
                    const sicm_ode_stats *work, double seconds) {
  if (!enabled) return;
  pthread_mutex_lock(&lock);
  site_line *l = line_of(where ? where : "?", who ? who : "?", method ? method : "?", tolerance);
  if (l) { /* out of memory, nothing: the statistics are a convenience */
    l->calls++;
    l->work.steps += work->steps;
    l->work.rejected_steps += work->rejected_steps;
    l->work.rhs_evals += work->rhs_evals;
    l->work.jacobian_evals += work->jacobian_evals;
    l->seconds += seconds;
  }
  pthread_mutex_unlock(&lock);
}

void sicm_stats_add_events(const char *where, const char *who, const char *method, double tolerance,
                           const sicm_ode_event_stats *events) {
  if (!enabled || !events || events->located == 0) return;
  pthread_mutex_lock(&lock);
  site_line *l = line_of(where ? where : "?", who ? who : "?", method ? method : "?", tolerance);
  if (l) {
    l->events.located += events->located;
    l->events.iterations += events->iterations;
    l->events.screened += events->screened;
  }
  pthread_mutex_unlock(&lock);
}

static void print_lines(FILE *f) {
  if (nlines == 0) return;
  fputs("integration statistics (--stats), one line per site, method and tolerance:\n", f);
  for (size_t i = 0; i < nlines; i++) {
    const site_line *l = &lines[i];
    char tol[SICM_DOUBLE_BUFSIZE], secs[SICM_DOUBLE_BUFSIZE];
    sicm_format_tolerance(tol, l->tolerance);
    /* Seconds to 3 significant digits: the clock is not more repeatable. */
    char rounded[32];
    snprintf(rounded, sizeof rounded, "%.3g", l->seconds);
    sicm_format_double(secs, strtod(rounded, NULL));
    char events[160] = "";
    if (l->events.located > 0)
      snprintf(events, sizeof events,
               ", %lu event%s located (%lu placement integrations; %lu steps screened free of "
               "events)",
               l->events.located, l->events.located == 1 ? "" : "s", l->events.iterations,
               l->events.screened);
    fprintf(f,
            "%s: %s, %s, tolerance %s: %lu call%s, %lu steps (%lu rejected), %lu rhs "
            "evaluations%s, %s s\n",
            l->where, l->who, l->method, tol, l->calls, l->calls == 1 ? "" : "s", l->work.steps,
            l->work.rejected_steps, l->work.rhs_evals, events, secs);
  }
}

void sicm_stats_print(FILE *f) {
  pthread_mutex_lock(&lock);
  print_lines(f);
  pthread_mutex_unlock(&lock);
}
