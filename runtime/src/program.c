/* What built programs call: options, printing, plots and the numerical
 * primitives' drivers (see sicm/program.h).
 *
 * Each driver mirrors the interpreter's primitive of the same name
 * (compiler/builtins/numerics.cpp): the same defaults, the same way of
 * restarting integrators and of placing monitor times, the same relaxation
 * of an integral's tolerance. Kernels are adapted to the runtime's callback
 * types by the small functions below; the runtime's error hook records the
 * last failure message so the driver can quote it.
 *
 * Members of a parallel sweep (parallel.c) call all of this from several
 * threads at once: what they print, plot or fail with goes to their logs
 * (sicm_parallel_log_*), the last failure message is per thread, and the
 * rest of the state here is written only by sicm_program_init and by frames,
 * which members never make (the compiler runs such members serially). */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_errno.h>

#include "parallel_internal.h"
#include "sicm/runtime.h"

/* ---- options and failure --------------------------------------------------------- */

static const char *plot_dir = ".";
/* Per thread: members on the sweep's threads fail and quote their own. */
static _Thread_local char last_reason[1024];
/* An MPI rank other than 0 (see parallel_internal.h). */
static int quiet;

void sicm_program_set_quiet(int on) {
  quiet = on;
}

int sicm_program_quiet(void) {
  return quiet;
}

static void record_reason(const char *reason, int status) {
  (void)status;
  snprintf(last_reason, sizeof last_reason, "%s", reason);
}

/* The runtime's message without its "sicm_function_name: " prefix. */
static const char *reason_text(void) {
  const char *colon = strstr(last_reason, ": ");
  if (strncmp(last_reason, "sicm_", 5) == 0 && colon) return colon + 2;
  return last_reason[0] ? last_reason : "failed";
}

enum { kMaxParams = 64 };
static const char *param_names[kMaxParams];
static double param_values[kMaxParams];
static int nparams;

static void usage(FILE *f, const char *argv0, const char *const *parameters) {
  if (quiet) return;
  fprintf(f, "usage: %s [--plot-dir DIR] [--threads N] [--stats]", argv0);
  for (const char *const *p = parameters; *p; ++p)
    fprintf(f, " [--param %s=VALUE]", *p);
  fputc('\n', f);
}

/* Record --param NAME=VALUE; 0 if NAME is not declared or VALUE is not a number. */
static int set_param(const char *assignment, const char *const *parameters) {
  const char *eq = strchr(assignment, '=');
  if (!eq || eq == assignment) return 0;
  size_t len = (size_t)(eq - assignment);
  for (const char *const *p = parameters; *p; ++p) {
    if (strlen(*p) != len || strncmp(*p, assignment, len) != 0) continue;
    char *end;
    double x = strtod(eq + 1, &end);
    if (eq[1] == '\0' || *end != '\0' || nparams == kMaxParams) return 0;
    param_names[nparams] = *p;
    param_values[nparams++] = x;
    return 1;
  }
  return 0;
}

/* --threads N: a whole number from 1 to 65536; 0 for anything else. */
static int thread_count(const char *text) {
  char *end;
  errno = 0;
  long n = strtol(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0' || n < 1 || n > 65536) return 0;
  return (int)n;
}

/* --stats: after the run (or a failure), what each integration site cost. */
static void print_stats(void) {
  if (quiet) return;
  fflush(stdout);
  sicm_stats_print(stderr);
}

void sicm_program_init(int argc, char **argv, const char *program_name,
                       const char *const *parameters) {
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--plot-dir") == 0 && i + 1 < argc) {
      plot_dir = argv[++i];
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      int n = thread_count(argv[++i]);
      if (n == 0) {
        if (!quiet)
          fprintf(stderr, "%s: --threads %s: not a whole number of threads from 1 to 65536\n",
                  argv[0], argv[i]);
        usage(stderr, argv[0], parameters);
        exit(64);
      }
      sicm_parallel_set_threads(n);
    } else if (strcmp(argv[i], "--stats") == 0) {
      if (!sicm_stats_enabled()) atexit(print_stats);
      sicm_stats_enable();
    } else if (strcmp(argv[i], "--param") == 0 && i + 1 < argc) {
      if (!set_param(argv[++i], parameters)) {
        if (!quiet)
          fprintf(stderr, "%s: --param %s: not NAME=NUMBER for a parameter of the program\n",
                  argv[0], argv[i]);
        usage(stderr, argv[0], parameters);
        exit(64);
      }
    } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage(stdout, argv[0], parameters);
      if (!quiet)
        printf("  a program compiled by sicm build from %s; plots go to DIR (default .);\n"
               "  --threads N runs the members of parallel-map and parallel-for-each on N\n"
               "  threads (default: the cores this process may run on);\n"
               "  --stats prints what each integration cost on stderr after the run\n",
               program_name);
      exit(0);
    } else {
      usage(stderr, argv[0], parameters);
      exit(64);
    }
  }
  sicm_set_error_handler(record_reason);
  /* The runtime switches GSL's handler off and back around each call; from
   * several threads that would hand back GSL's aborting default while
   * another thread is inside GSL, unless it is off from the start. */
  gsl_set_error_handler_off();
}

double sicm_program_param(const char *name, double fallback) {
  for (int i = nparams - 1; i >= 0; --i)
    if (strcmp(param_names[i], name) == 0) return param_values[i];
  return fallback;
}

/* The failure's whole message, as it goes to stderr: "WHERE: error: WHO:
 * REASON", the source line and a caret under the call. malloc'd; NULL if
 * memory runs out. */
static char *failure_text(const sicm_site *site, const char *who, const char *reason) {
  char *text = NULL;
  size_t size = 0;
  FILE *f = open_memstream(&text, &size);
  if (!f) return NULL;
  if (who)
    fprintf(f, "%s: error: %s: %s\n", site->where, who, reason);
  else
    fprintf(f, "%s: error: %s\n", site->where, reason);
  if (site->line && site->line[0]) {
    fprintf(f, "    %s\n    ", site->line); /* as the compiler's messages (base/error.cpp) */
    for (int i = 1; i < site->col; ++i)
      fputc(site->line[i - 1] == '\t' ? '\t' : ' ', f);
    fputs("^\n", f);
  }
  if (fclose(f) != 0) {
    free(text);
    return NULL;
  }
  return text;
}

/* The end of every failure: the plots finished, then status 70. */
_Noreturn static void exit_failed(void) {
  sicm_plot_close_all();
  sicm_parallel_failing();
  exit(70);
}

void sicm_program_fail_message(const char *message) {
  fflush(stdout);
  if (!quiet) fputs(message ? message : "error: out of memory\n", stderr);
  exit_failed();
}

void sicm_program_fail(const sicm_site *site, const char *who, const char *reason) {
  char *message = failure_text(site, who, reason);
  sicm_parallel_member_failed(message); /* in a member: its log takes it, and no return */
  if (!message) {
    /* No memory for the text: write it piece by piece. */
    fflush(stdout);
    if (!quiet) fprintf(stderr, "%s: error: %s: %s\n", site->where, who ? who : "", reason);
    exit_failed();
  }
  sicm_program_fail_message(message);
}

void sicm_program_fail_diagnostic(const char *diagnostic) {
  sicm_program_fail_message(diagnostic);
}

/* The message being printed by sicm_program_fail_capture's caller, or NULL. */
static FILE *capture;
static char *captured;
static size_t captured_size;

void sicm_program_fail_capture(void) {
  fflush(stdout);
  if (!capture) capture = open_memstream(&captured, &captured_size);
}

void sicm_program_fail_captured(void) {
  char *message = NULL;
  if (capture && fclose(capture) == 0) message = captured;
  capture = NULL;
  sicm_program_fail_message(message); /* NULL: "out of memory" */
}

/* ---- printing --------------------------------------------------------------------- */

void sicm_program_write(const char *s, size_t len) {
  if (!quiet) fwrite(s, 1, len, stdout);
}

/* Every print: into a failure's message, to the running member's log, or to
 * stdout. */
static void print(const char *s, size_t len) {
  if (capture) {
    fwrite(s, 1, len, capture);
    return;
  }
  if (!sicm_parallel_log_text(s, len)) sicm_program_write(s, len);
}

void sicm_print_text(const char *s) {
  print(s, strlen(s));
}

void sicm_print_real(double x) {
  char buf[SICM_DOUBLE_BUFSIZE];
  print(buf, sicm_format_double(buf, x));
}

void sicm_print_integer(double x) {
  /* An integral double has at most 309 digits and a sign. */
  char buf[320];
  int len = snprintf(buf, sizeof buf, "%.0f", x);
  print(buf, len < 0 ? 0 : (size_t)len < sizeof buf ? (size_t)len : sizeof buf - 1);
}

void sicm_print_boolean(double x) {
  print(x != 0 ? "#t" : "#f", 2);
}

double sicm_real_time(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

double sicm_run_time(void) {
  return (double)clock() / CLOCKS_PER_SEC;
}

/* ---- plots ------------------------------------------------------------------------- */

/* Every frame made, in order (see sicm_program_frame_number). */
static sicm_plot **frames;
static size_t nframes, frames_cap;

static void remember_frame(const sicm_site *site, sicm_plot *p) {
  if (nframes == frames_cap) {
    size_t cap = frames_cap ? 2 * frames_cap : 16;
    sicm_plot **grown = realloc(frames, cap * sizeof *grown);
    if (!grown) sicm_program_fail(site, "frame", "out of memory");
    frames = grown;
    frames_cap = cap;
  }
  frames[nframes++] = p;
}

size_t sicm_program_frame_number(const sicm_plot *plot) {
  for (size_t i = nframes; i-- > 0;) /* the latest frames are the likeliest */
    if (frames[i] == plot) return i;
  return SIZE_MAX;
}

sicm_plot *sicm_program_frame_at(size_t number) {
  return number < nframes ? frames[number] : NULL;
}

sicm_plot *sicm_program_frame(const sicm_site *site, const char *name, const char *title,
                              double xmin, double xmax, double ymin, double ymax) {
  /* Under MPI rank 0 writes the files and the other ranks' frames only take
   * the calls; when rank 0 cannot create its files, every rank fails, as
   * rank 0 does, rather than going on alone. */
  sicm_plot *p = quiet ? sicm_plot_open_silent(name)
                       : sicm_plot_open(plot_dir, name, title, xmin, xmax, ymin, ymax);
  const int error = errno;
  if (!sicm_parallel_rank0_value(p != NULL) || !p) {
    char reason[512];
    snprintf(reason, sizeof reason, "cannot create the plot file %s/%s.tsv: %s", plot_dir, name,
             strerror(error));
    sicm_program_fail(site, "frame", reason);
  }
  remember_frame(site, p);
  return p;
}

void sicm_program_plot_labels(const sicm_site *site, sicm_plot *plot, const char *x_label,
                              const char *y_label) {
  if (sicm_plot_set_labels(plot, x_label, y_label) != 0)
    sicm_program_fail(site, "frame", "out of memory");
}

/* A mark on a finished plot fails in the member, where the serial run fails
 * (in the interpreter's words, which cover both causes). */
static const char mark_refused[] = "the plot is closed or memory is exhausted";

static void check_open(const sicm_site *site, const sicm_plot *plot, const char *who) {
  if (sicm_plot_is_finished(plot)) sicm_program_fail(site, who, mark_refused);
}

void sicm_program_plot_options(const sicm_site *site, sicm_plot *plot, int equal_aspect,
                               double marker_size, int legend) {
  sicm_plot_set_equal_aspect(plot, equal_aspect);
  sicm_plot_set_marker_size(plot, marker_size);
  if (sicm_plot_set_legend(plot, (sicm_plot_legend)legend) != 0)
    sicm_program_fail(site, "frame", "no such legend position");
}

void sicm_program_plot_style(const sicm_site *site, sicm_plot *plot, const char *series,
                             double marker_size, int connect) {
  if (sicm_plot_style_series(plot, series, marker_size, connect) != 0)
    sicm_program_fail(site, "plot-series", "out of memory");
}

void sicm_program_plot_clear(const sicm_site *site, sicm_plot *plot) {
  check_open(site, plot, "graphics-clear");
  if (sicm_parallel_log_clear(plot)) return;
  if (sicm_plot_clear(plot) != 0) sicm_program_fail(site, "graphics-clear", mark_refused);
}

void sicm_program_plot_point(const sicm_site *site, sicm_plot *plot, double x, double y) {
  sicm_program_plot_series_point(site, plot, NULL, x, y);
}

void sicm_program_plot_line(const sicm_site *site, sicm_plot *plot, double x0, double y0, double x1,
                            double y1) {
  sicm_program_plot_series_line(site, plot, NULL, x0, y0, x1, y1);
}

void sicm_program_plot_series_point(const sicm_site *site, sicm_plot *plot, const char *series,
                                    double x, double y) {
  check_open(site, plot, "plot-point");
  if (sicm_parallel_log_point(plot, series, x, y)) return;
  if (sicm_plot_series_point(plot, series, x, y) != 0)
    sicm_program_fail(site, "plot-point", mark_refused);
}

void sicm_program_plot_series_line(const sicm_site *site, sicm_plot *plot, const char *series,
                                   double x0, double y0, double x1, double y1) {
  check_open(site, plot, "plot-line");
  if (sicm_parallel_log_line(plot, series, x0, y0, x1, y1)) return;
  if (sicm_plot_series_line(plot, series, x0, y0, x1, y1) != 0)
    sicm_program_fail(site, "plot-line", mark_refused);
}

/* ---- kernels as the runtime's callbacks -------------------------------------------- */

static double scalar_of(double x, void *c) {
  const sicm_closure *k = c;
  double out;
  k->fn(&x, &out, k->p);
  return out;
}

static double abs_scalar_of(double x, void *c) {
  return fabs(scalar_of(x, c));
}

static double vector_of(const double *x, void *c) {
  const sicm_closure *k = c;
  double out;
  k->fn(x, &out, k->p);
  return out;
}

static void fail_with_status(const sicm_site *site, const char *who) {
  sicm_program_fail(site, who, reason_text());
}

/* ---- quadrature, minimization, roots ------------------------------------------------- */

double sicm_drive_integral(const sicm_site *site, sicm_closure f, double a, double b, double tol) {
  static const char who[] = "definite-integral";
  if (a == b) return 0.0;
  double result = 0;
  int status = sicm_quad_integrate(scalar_of, &f, a, b, tol, &result);
  if (status == SICM_ETOL) {
    /* As the interpreter: a relative test cannot be met when the integral is
     * much smaller than the integral of |f| (cancellation); then take the
     * tolerance relative to the latter and integrate again. */
    char message[sizeof last_reason];
    memcpy(message, last_reason, sizeof message);
    double magnitude = 0;
    int s2 = sicm_quad_integrate(abs_scalar_of, &f, a, b, 1e-3, &magnitude);
    if (s2 == SICM_SUCCESS && magnitude > 2 * fabs(result)) {
      if (result == 0) return 0.0;
      double relaxed = tol * magnitude / fabs(result);
      status = sicm_quad_integrate(scalar_of, &f, a, b, relaxed, &result);
      if (status == SICM_SUCCESS) return result;
    }
    memcpy(last_reason, message, sizeof message);
  }
  if (status != SICM_SUCCESS) fail_with_status(site, who);
  return result;
}

void sicm_drive_minimize(const sicm_site *site, sicm_closure f, double a, double b, double tol,
                         double out[3]) {
  if (a == b) sicm_program_fail(site, "minimize", "the interval is empty");
  if (a > b) {
    double t = a;
    a = b;
    b = t;
  }
  double x = 0, fx = 0;
  int iterations = 0;
  if (sicm_min_brent(scalar_of, &f, a, b, tol, &x, &fx, &iterations) != SICM_SUCCESS)
    fail_with_status(site, "minimize");
  out[0] = x;
  out[1] = fx;
  out[2] = iterations;
}

void sicm_drive_multimin(const sicm_site *site, sicm_closure f, size_t n, double *x, double tol,
                         int as_list) {
  enum { kMaxIterations = 20000 }; /* the interpreter's 20 * nelder-maxiter */
  const double start_step = 0.01;  /* nelder-start-step */
  double fmin = 0;
  int iterations = 0;
  int status = sicm_min_nelder_mead(vector_of, &f, n, x, start_step, tol, kMaxIterations, &fmin,
                                    &iterations);
  if (status == SICM_EMAXITER) {
    char reason[SICM_MIN_FAILURE_BUFSIZE];
    sicm_min_nelder_mead_failure(reason, iterations, n, x, fmin, as_list);
    sicm_program_fail(site, "multidimensional-minimize", reason);
  }
  if (status != SICM_SUCCESS) fail_with_status(site, "multidimensional-minimize");
}

double sicm_drive_find_root(const sicm_site *site, sicm_closure f, double a, double b, double tol) {
  static const char who[] = "find-root";
  if (a > b) {
    double t = a;
    a = b;
    b = t;
  }
  if (a == b) sicm_program_fail(site, who, "the interval is empty");
  double fa = scalar_of(a, &f), fb = scalar_of(b, &f);
  if (fa == 0) return a;
  if (fb == 0) return b;
  if (isfinite(fa) && isfinite(fb) && (fa > 0) == (fb > 0)) {
    char reason[256], sa[SICM_DOUBLE_BUFSIZE], sb[SICM_DOUBLE_BUFSIZE];
    char xa[SICM_DOUBLE_BUFSIZE], xb[SICM_DOUBLE_BUFSIZE];
    sicm_format_double(sa, fa);
    sicm_format_double(sb, fb);
    sicm_format_double(xa, a);
    sicm_format_double(xb, b);
    snprintf(reason, sizeof reason,
             "the function is %s at %s and %s at %s: the interval does not bracket a root", sa, xa,
             sb, xb);
    sicm_program_fail(site, who, reason);
  }
  double root = 0;
  if (sicm_root_brent(scalar_of, &f, a, b, tol, &root) != SICM_SUCCESS) fail_with_status(site, who);
  return root;
}

double sicm_drive_bisect(const sicm_site *site, sicm_closure f, double x0, double x1, double eps,
                         long n_break) {
  static const char who[] = "bisect";
  enum { kMaxIterations = 10000 };
  double root = 0, bracket[2], values[2];
  int status =
      sicm_root_bisect(scalar_of, &f, x0, x1, eps, n_break, kMaxIterations, &root, bracket, values);
  if (status == SICM_SUCCESS) return root;
  char reason[256], a[SICM_DOUBLE_BUFSIZE], b[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(a, bracket[0]);
  sicm_format_double(b, bracket[1]);
  if (status == SICM_EBRACKET) {
    char fa[SICM_DOUBLE_BUFSIZE], fb[SICM_DOUBLE_BUFSIZE];
    sicm_format_double(fa, values[0]);
    sicm_format_double(fb, values[1]);
    snprintf(reason, sizeof reason, "root not bounded: the function is %s at %s and %s at %s", fa,
             a, fb, b);
  } else {
    snprintf(reason, sizeof reason,
             "no convergence in %d iterations; the root is between %s and %s", (int)kMaxIterations,
             a, b);
  }
  sicm_program_fail(site, who, reason);
}

/* ---- ordinary differential equations ------------------------------------------------- */

typedef struct {
  sicm_ode *o;
  sicm_closure sysder;
  sicm_closure jacobian;
  size_t dim;
  double *jac_out; /* dim * dim, the kernel's column-major Jacobian */
  /* For --stats: the call's site and primitive, its tolerance, and the
   * seconds spent in the integrator (monitors not counted). */
  const sicm_site *site;
  const char *who;
  double tol, seconds;
} integrator;

/* The runtime's Jacobian callback from a kernel of (D sysder) (see
 * sicm_drive_ode); the rhs does not depend on the integrator's time. */
static int jacobian_of(double t, const double *y, double *dfdy, double *dfdt, void *c) {
  (void)t;
  const integrator *it = c;
  size_t n = it->dim;
  it->jacobian.fn(y, it->jac_out, it->jacobian.p);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j)
      dfdy[i * n + j] = it->jac_out[j * n + i];
    dfdt[i] = 0.0;
  }
  return 0;
}

static int rhs_of_integrator(double t, const double *y, double *dydt, void *c) {
  (void)t;
  const integrator *it = c;
  it->sysder.fn(y, dydt, it->sysder.p);
  return 0;
}

static void open_integrator(const sicm_site *site, const char *who, const sicm_drive_ode *ode,
                            integrator *it) {
  it->sysder = ode->sysder;
  it->jacobian = ode->jacobian;
  it->dim = ode->dim;
  it->jac_out = NULL;
  it->site = site;
  it->who = who;
  it->tol = ode->tol;
  it->seconds = 0;
  it->o = sicm_ode_alloc(ode->method, ode->dim, rhs_of_integrator, it, ode->tol, ode->tol);
  if (!it->o) fail_with_status(site, who);
  if (ode->probe.fn && sicm_ode_set_singularity_probe(it->o, ode->probe.fn, ode->probe.p,
                                                      ode->probe_count, ode->probe_texts))
    fail_with_status(site, who);
  if (ode->max_steps && sicm_ode_set_max_steps(it->o, ode->max_steps)) fail_with_status(site, who);
  if (ode->taylor) sicm_ode_set_taylor(it->o, ode->taylor, ode->sysder.p);
  if (ode->taylor_extended)
    sicm_ode_set_taylor_extended(it->o, ode->taylor_extended, ode->sysder.p);
  if (it->jacobian.fn) {
    it->jac_out = malloc(ode->dim * ode->dim * sizeof *it->jac_out);
    if (!it->jac_out) sicm_program_fail(site, who, "out of memory");
    sicm_ode_set_jacobian(it->o, jacobian_of);
  }
}

static void close_integrator(integrator *it) {
  sicm_stats_add(it->site->where, it->who, sicm_ode_name(it->o), it->tol, sicm_ode_get_stats(it->o),
                 it->seconds);
  sicm_stats_add_events(it->site->where, it->who, sicm_ode_name(it->o), it->tol,
                        sicm_ode_get_event_stats(it->o));
  sicm_ode_free(it->o);
  free(it->jac_out);
}

static void evolve_to(const sicm_site *site, const char *who, integrator *it, double *t, double t1,
                      double *y) {
  const int timed = sicm_stats_enabled(); /* the clock only for --stats */
  const double start = timed ? sicm_stats_clock() : 0;
  const int status = sicm_ode_evolve(it->o, t, t1, y);
  if (timed) it->seconds += sicm_stats_clock() - start;
  if (status != SICM_SUCCESS) {
    snprintf(last_reason, sizeof last_reason, "%s", sicm_ode_last_error(it->o));
    close_integrator(it);
    fail_with_status(site, who);
  }
}

static double start_time(const sicm_drive_ode *ode, const double *y) {
  return ode->time_first && isfinite(y[0]) ? y[0] : 0.0;
}

/* The events of an evolve or a state advance, and whether one stopped it. */
typedef struct {
  const sicm_drive_event *events;
  int stopped;
} event_sink;

/* An event's value: its closure (c) of the state, one number out; the
 * runtime's event function for evolve's, a state advance's and crossings'. */
static double closure_event_value(double t, const double *y, void *c) {
  (void)t;
  const sicm_closure *event = c;
  double out;
  event->fn(y, &out, event->p);
  return out;
}

static int on_drive_event(size_t i, double t, const double *y, void *c) {
  (void)t;
  event_sink *sink = c;
  const sicm_drive_event *e = &sink->events[i];
  if (!e->action.fn) {
    sink->stopped = 1;
    return 1; /* non-zero: stop here */
  }
  e->action.fn(y, NULL, e->action.p);
  return 0;
}

/* Give the integrator its events (none: it integrates as without). */
static void set_drive_events(const sicm_site *site, const char *who, integrator *it,
                             const sicm_drive_event *events, size_t n, event_sink *sink) {
  sink->events = events;
  sink->stopped = 0;
  if (n == 0) return;
  sicm_ode_event *table = malloc(n * sizeof *table);
  if (!table) sicm_program_fail(site, who, "out of memory");
  for (size_t i = 0; i < n; ++i)
    table[i] =
        (sicm_ode_event){closure_event_value, (void *)&events[i].event, events[i].direction, 0};
  const int status = sicm_ode_set_events(it->o, table, n, on_drive_event, sink);
  free(table); /* sicm_ode_set_events copied it */
  if (status) fail_with_status(site, who);
}

void sicm_drive_advance(const sicm_site *site, const sicm_drive_ode *ode, double *y, double dt) {
  sicm_drive_advance_events(site, ode, y, dt, NULL, 0);
}

void sicm_drive_advance_events(const sicm_site *site, const sicm_drive_ode *ode, double *y,
                               double dt, const sicm_drive_event *events, size_t n) {
  static const char who[] = "state-advancer";
  integrator it;
  open_integrator(site, who, ode, &it);
  event_sink sink;
  set_drive_events(site, who, &it, events, n, &sink);
  double t = start_time(ode, y), t1 = t + dt;
  evolve_to(site, who, &it, &t, t1, y);
  if (ode->time_first && ode->rate_one && !sink.stopped) y[0] = t1;
  close_integrator(&it);
}

void sicm_drive_evolve(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure first,
                       sicm_closure monitor, double *y, double dt, double t_final) {
  sicm_drive_evolve_events(site, ode, first, monitor, y, dt, t_final, NULL, 0);
}

void sicm_drive_evolve_events(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure first,
                              sicm_closure monitor, double *y, double dt, double t_final,
                              const sicm_drive_event *events, size_t n) {
  static const char who[] = "evolve";
  const double t0 = start_time(ode, y);
  if (first.fn) first.fn(y, NULL, first.p);
  sicm_monitor_schedule schedule;
  const char *why_not = sicm_monitor_schedule_start(&schedule, t0, dt, t_final);
  if (why_not) sicm_program_fail(site, who, why_not);
  double *shown = malloc(ode->dim * sizeof *shown);
  if (!shown) sicm_program_fail(site, who, "out of memory");
  integrator it;
  open_integrator(site, who, ode, &it);
  sicm_ode_set_horizon(it.o, t_final);
  event_sink sink;
  set_drive_events(site, who, &it, events, n, &sink);
  double t = t0, tk;
  while (sicm_monitor_schedule_next(&schedule, t, &tk)) {
    evolve_to(site, who, &it, &t, tk, y);
    if (sink.stopped) break;
    if (monitor.fn) {
      memcpy(shown, y, ode->dim * sizeof *shown);
      if (ode->time_first && ode->rate_one) shown[0] = tk;
      monitor.fn(shown, NULL, monitor.p);
    }
  }
  if (ode->time_first && ode->rate_one && !sink.stopped) y[0] = t_final;
  close_integrator(&it);
  free(shown);
}

/* The event of crossings, and where its crossings go. */
typedef struct {
  sicm_closure event;
  const sicm_site *site;
  sicm_list *list;
  long count, found;
} crossing_sink;

static int push_crossing(size_t event, double t, const double *y, void *c) {
  (void)event;
  (void)t;
  crossing_sink *sink = c;
  sicm_list_push(sink->site, sink->list, y);
  return sink->count > 0 && ++sink->found >= sink->count; /* non-zero: stop here */
}

void sicm_drive_crossings(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure event,
                          int direction, long count, const double *y, double t_final,
                          sicm_list *list) {
  static const char who[] = "crossings";
  double *state = malloc(ode->dim * sizeof *state);
  if (!state) sicm_program_fail(site, who, "out of memory");
  memcpy(state, y, ode->dim * sizeof *state);
  integrator it;
  open_integrator(site, who, ode, &it);
  crossing_sink sink = {event, site, list, count, 0};
  const sicm_ode_event e = {closure_event_value, &sink.event, direction, 0};
  if (sicm_ode_set_events(it.o, &e, 1, push_crossing, &sink)) fail_with_status(site, who);
  double t = start_time(ode, state);
  evolve_to(site, who, &it, &t, t_final, state);
  close_integrator(&it);
  free(state);
}
