/* Plot files: every frame becomes NAME.tsv (the raw points, written as the
 * run goes) and NAME.svg (axes, ticks, labels, points, a legend; drawn by
 * plot_svg.c), finished when the frame is closed, at exit, or on
 * SIGINT/SIGTERM. Marks belong to series, found here by name.
 *
 * Nothing is lost on interruption: points are kept in memory and appended to
 * the TSV file as they arrive (flushed at least every kFlushEvery points and
 * on close); the SVG is written to NAME.svg.tmp and renamed over NAME.svg, so
 * a crash never leaves a half-written picture where the last good one was.
 *
 * Signals. A signal may arrive while a mark is being added (on this thread
 * or, in the interpreter, on the evaluating thread while the handler runs on
 * another). One atomic state word orders the two without locks:
 *   IDLE -> BUSY      a plot operation starts (and IDLE again when it ends);
 *   IDLE -> CLOSING   the handler finishes every plot and exits;
 *   BUSY -> PENDING   the handler defers: the operation, on ending, sees
 *                     PENDING and finishes the plots and exits itself;
 *   CLOSING          an operation that finds it waits for the exit. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plot_internal.h"
#include "sicm/runtime.h"

enum { kFlushEvery = 4096, kMaxOpenPlots = 256 };

static sicm_plot *open_plots[kMaxOpenPlots];
static int handlers_installed;

enum { kIdle, kBusy, kClosing, kPending };
static atomic_int plot_state = kIdle;
static volatile sig_atomic_t pending_signal;

static void finish_and_exit(int sig) {
  sicm_plot_close_all();
  _exit(128 + sig);
}

/* Enter a plot operation; if the plots are being closed, wait for the exit. */
static void enter_operation(void) {
  int expected = kIdle;
  while (!atomic_compare_exchange_weak(&plot_state, &expected, kBusy)) {
    if (expected == kClosing || expected == kPending)
      for (;;)
        pause();
    expected = kIdle;
  }
}

static void leave_operation(void) {
  int expected = kBusy;
  if (!atomic_compare_exchange_strong(&plot_state, &expected, kIdle)) {
    atomic_store(&plot_state, kClosing); /* a signal came meanwhile: act on it */
    finish_and_exit(pending_signal);
  }
}

static void remember(sicm_plot *p) {
  for (int i = 0; i < kMaxOpenPlots; ++i)
    if (!open_plots[i]) {
      open_plots[i] = p;
      return;
    }
}

static void forget(sicm_plot *p) {
  for (int i = 0; i < kMaxOpenPlots; ++i)
    if (open_plots[i] == p) open_plots[i] = NULL;
}

static void on_signal(int sig) {
  /* Finishing the files uses stdio, which is not formally async-signal-safe;
   * the state word guarantees no plot operation is half done, and losing
   * the picture of an hours-long run would be worse. */
  pending_signal = sig;
  int expected = kIdle;
  if (atomic_compare_exchange_strong(&plot_state, &expected, kClosing)) finish_and_exit(sig);
  expected = kBusy;
  if (atomic_compare_exchange_strong(&plot_state, &expected, kPending)) return;
  for (;;)
    pause(); /* closing already: the exit is on its way */
}

static void on_exit_finish(void) {
  sicm_plot_close_all();
}

static void install_handlers(void) {
  if (handlers_installed) return;
  handlers_installed = 1;
  atexit(on_exit_finish);
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

static char *dup_string(const char *s) {
  size_t n = strlen(s) + 1;
  char *d = malloc(n);
  if (d) memcpy(d, s, n);
  return d;
}

/* mkdir -p: every missing directory of path, made in turn. 0, or -1 with
 * errno from the mkdir that failed (EEXIST is not a failure). */
static int make_directories(const char *path) {
  char buf[4096];
  size_t n = strlen(path);
  if (n == 0 || n >= sizeof buf) return n == 0 ? 0 : (errno = ENAMETOOLONG, -1);
  memcpy(buf, path, n + 1);
  for (size_t i = 1; i <= n; ++i) {
    if (buf[i] != '/' && buf[i] != '\0') continue;
    char c = buf[i];
    buf[i] = '\0';
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    buf[i] = c;
  }
  struct stat st;
  if (stat(path, &st) != 0) return -1;
  if (!S_ISDIR(st.st_mode)) return errno = ENOTDIR, -1;
  return 0;
}

sicm_plot *sicm_plot_open(const char *dir, const char *name, const char *title, double xmin,
                          double xmax, double ymin, double ymax) {
  if (!(xmax > xmin) || !(ymax > ymin)) {
    errno = EINVAL;
    return NULL;
  }
  /* --plot-dir names a directory that need not exist yet. */
  if (dir && make_directories(dir) != 0) return NULL;
  sicm_plot *p = calloc(1, sizeof *p);
  if (!p) return NULL;
  size_t len = strlen(dir ? dir : ".") + strlen(name) + 2;
  p->path = malloc(len);
  p->title = dup_string(title ? title : name);
  if (!p->path || !p->title) {
    free(p->path);
    free(p->title);
    free(p);
    return NULL;
  }
  snprintf(p->path, len, "%s/%s", dir ? dir : ".", name);
  p->marker_size = -1;
  p->xmin = xmin;
  p->xmax = xmax;
  p->ymin = ymin;
  p->ymax = ymax;
  char tsv_path[4096];
  snprintf(tsv_path, sizeof tsv_path, "%s.tsv", p->path);
  p->tsv = fopen(tsv_path, "w");
  if (!p->tsv) {
    free(p->path);
    free(p->title);
    free(p);
    return NULL;
  }
  fprintf(p->tsv, "# %s\n# x\ty\n", p->title);
  fflush(p->tsv);
  install_handlers();
  enter_operation();
  remember(p);
  leave_operation();
  return p;
}

/* A silent plot has no path and no TSV; add_point, add_line and finish_plot
 * see its flag and only keep track of whether it is finished. */
sicm_plot *sicm_plot_open_silent(const char *name) {
  sicm_plot *p = calloc(1, sizeof *p);
  if (!p) return NULL;
  p->title = dup_string(name);
  if (!p->title) {
    free(p);
    return NULL;
  }
  p->silent = 1;
  p->marker_size = -1;
  return p;
}

int sicm_plot_set_labels(sicm_plot *p, const char *x_label, const char *y_label) {
  char *x = x_label ? dup_string(x_label) : NULL, *y = y_label ? dup_string(y_label) : NULL;
  if ((x_label && !x) || (y_label && !y)) {
    free(x);
    free(y);
    errno = ENOMEM;
    return -1;
  }
  free(p->x_label);
  free(p->y_label);
  p->x_label = x;
  p->y_label = y;
  return 0;
}

/* The index of the series named `name` (NULL: the unnamed one, index 0),
 * made if it is new; SIZE_MAX if memory runs out. Plots have a few series, and marks come in runs
 * of one series, so the last one found is tried first. */
static size_t find_series(sicm_plot *p, const char *name) {
  if (p->n_series == 0) { /* the unnamed series is index 0 from the start */
    p->series = calloc(4, sizeof *p->series);
    if (!p->series) return SIZE_MAX;
    p->series_cap = 4;
    p->series[0] = (sicm_plot_series_info){NULL, -1, -1, 0, 0};
    p->n_series = 1;
  }
  if (!name) return 0;
  const size_t last = p->last_series;
  if (last < p->n_series && p->series[last].name && strcmp(p->series[last].name, name) == 0)
    return last;
  for (size_t i = 1; i < p->n_series; ++i)
    if (strcmp(p->series[i].name, name) == 0) return p->last_series = i;
  if (p->n_series == p->series_cap) {
    sicm_plot_series_info *grown = realloc(p->series, 2 * p->series_cap * sizeof *grown);
    if (!grown) return SIZE_MAX;
    p->series = grown;
    p->series_cap *= 2;
  }
  char *copy = dup_string(name);
  if (!copy) return SIZE_MAX;
  p->series[p->n_series] = (sicm_plot_series_info){copy, -1, -1, 0, 0};
  return p->last_series = p->n_series++;
}

static int add_mark(sicm_plot *p, sicm_plot_mark m) {
  if (p->closed) {
    errno = EINVAL;
    return -1;
  }
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 1024;
    sicm_plot_mark *grown = realloc(p->marks, cap * sizeof *grown);
    if (!grown) return -1;
    p->marks = grown;
    p->cap = cap;
  }
  sicm_plot_series_info *s = &p->series[m.series];
  if (s->name && s->rank < 0) s->rank = p->ranked++; /* its colour and legend row */
  if (isnan(m.x1)) {
    ++s->points;
    ++p->points;
  }
  p->marks[p->n++] = m;
  return 0;
}

static int add_mark_in(sicm_plot *p, const char *series, const double *xs, size_t count);

static void write_tsv_number(FILE *f, double x) {
  char buf[SICM_DOUBLE_BUFSIZE];
  /* The TSV holds plain C numbers (0.5, not MIT's .5) so any tool reads it. */
  snprintf(buf, sizeof buf, "%.17g", x);
  fputs(buf, f);
}

/* A series name as the TSV's last column: one field on one line. */
static void write_tsv_name(FILE *f, const char *name) {
  fputc('\t', f);
  for (; *name; ++name)
    fputc(*name == '\t' || *name == '\n' || *name == '\r' ? ' ' : *name, f);
}

static void after_write(sicm_plot *p) {
  if (++p->unflushed >= kFlushEvery) {
    fflush(p->tsv);
    p->unflushed = 0;
  }
}

/* A silent plot keeps nothing but refuses marks once finished, as a real one. */
static int silent_mark(const sicm_plot *p) {
  if (!p->closed) return 0;
  errno = EINVAL;
  return -1;
}

int sicm_plot_point(sicm_plot *p, double x, double y) {
  return sicm_plot_series_point(p, NULL, x, y);
}

int sicm_plot_line(sicm_plot *p, double x0, double y0, double x1, double y1) {
  return sicm_plot_series_line(p, NULL, x0, y0, x1, y1);
}

int sicm_plot_series_point(sicm_plot *p, const char *series, double x, double y) {
  const double xs[2] = {x, y};
  enter_operation();
  int status = add_mark_in(p, series, xs, 2);
  leave_operation();
  return status;
}

int sicm_plot_series_line(sicm_plot *p, const char *series, double x0, double y0, double x1,
                          double y1) {
  const double xs[4] = {x0, y0, x1, y1};
  enter_operation();
  int status = add_mark_in(p, series, xs, 4);
  leave_operation();
  return status;
}

/* Add a point (count 2) or a segment (count 4) to `series` and the TSV. */
static int add_mark_in(sicm_plot *p, const char *series, const double *xs, size_t count) {
  if (p->silent) return silent_mark(p);
  if (series && !*series) series = NULL; /* "" names no series */
  const size_t index = find_series(p, series);
  if (index == SIZE_MAX) return errno = ENOMEM, -1;
  sicm_plot_mark m = {xs[0], xs[1], count == 4 ? xs[2] : NAN, count == 4 ? xs[3] : NAN, index};
  if (add_mark(p, m) != 0) return -1;
  for (size_t i = 0; i < count; ++i) {
    if (i) fputc('\t', p->tsv);
    write_tsv_number(p->tsv, xs[i]);
  }
  if (series) write_tsv_name(p->tsv, series);
  fputc('\n', p->tsv);
  after_write(p);
  return 0;
}

int sicm_plot_style_series(sicm_plot *p, const char *series, double marker_size, int connect) {
  if (p->silent) return 0;
  if (series && !*series) series = NULL;
  enter_operation();
  const size_t index = find_series(p, series);
  if (index != SIZE_MAX) {
    p->series[index].marker_size = marker_size;
    p->series[index].connect = connect != 0;
  }
  leave_operation();
  return index == SIZE_MAX ? (errno = ENOMEM, -1) : 0;
}

int sicm_plot_set_marker_size(sicm_plot *p, double marker_size) {
  p->marker_size = marker_size;
  return 0;
}

int sicm_plot_set_equal_aspect(sicm_plot *p, int equal) {
  p->equal_aspect = equal != 0;
  return 0;
}

int sicm_plot_set_legend(sicm_plot *p, sicm_plot_legend where) {
  if ((int)where < 0 || where > SICM_PLOT_LEGEND_NONE) return errno = EINVAL, -1;
  p->legend = where;
  return 0;
}

static int finish_plot(sicm_plot *p) {
  if (p->closed) return 0;
  p->closed = 1;
  if (p->silent) return 0;
  int status = 0;
  if (fclose(p->tsv) != 0) status = -1;
  p->tsv = NULL;
  if (sicm_plot_write_svg(p) != 0) status = -1;
  return status;
}

int sicm_plot_clear(sicm_plot *p) {
  if (p->closed) {
    errno = EINVAL;
    return -1;
  }
  enter_operation();
  p->n = 0;
  p->points = 0;
  p->ranked = 0;
  for (size_t i = 0; i < p->n_series; ++i) {
    p->series[i].points = 0;
    if (p->series[i].name) p->series[i].rank = -1;
  }
  if (p->tsv) {
    fputs("# cleared\n", p->tsv);
    after_write(p);
  }
  leave_operation();
  return 0;
}

int sicm_plot_finish(sicm_plot *p) {
  enter_operation();
  int status = finish_plot(p);
  leave_operation();
  return status;
}

void sicm_plot_free(sicm_plot *p) {
  if (!p) return;
  enter_operation();
  finish_plot(p);
  forget(p);
  leave_operation();
  free(p->marks);
  for (size_t i = 0; i < p->n_series; ++i)
    free(p->series[i].name);
  free(p->series);
  free(p->path);
  free(p->title);
  free(p->x_label);
  free(p->y_label);
  free(p);
}

/* Called by the exit and signal paths, which own the plots by then. */
void sicm_plot_close_all(void) {
  for (int i = 0; i < kMaxOpenPlots; ++i)
    if (open_plots[i]) finish_plot(open_plots[i]);
}

int sicm_plot_is_finished(const sicm_plot *p) {
  return p->closed;
}

size_t sicm_plot_count(const sicm_plot *p) {
  return p->n;
}
