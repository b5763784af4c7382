/* sicm runtime: what the executables made by `sicm build` call.
 *
 * `sicm build` turns a program into C: the values known at compile time are
 * printed from constants, the procedures handed to numerical primitives
 * become kernels (functions with the kernel ABI below), and each call of a
 * numerical primitive becomes one call of a sicm_drive_* function here. The
 * drivers give the primitives the same meaning as the interpreter gives them
 * (the same defaults, integrator restarts, monitor times, tolerance
 * relaxation), so a built program prints what `sicm run` prints.
 *
 * Failures do not return: a driver that cannot do its job prints the error
 * in the compiler's style, naming the source position of the call, the
 * primitive and the reason, finishes every plot (so no point is lost) and
 * exits with status 70, as `sicm run` does. */
#ifndef SICM_PROGRAM_H
#define SICM_PROGRAM_H

#include <stddef.h>

#include "sicm/ode.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sicm_plot sicm_plot; /* runtime.h */

/* The kernel ABI: in[] the arguments' scalar leaves, out[] the result's
 * leaves, p[] values the kernel captures from the code that calls it (run-time
 * values of the enclosing procedure). A kernel with no result may be given a
 * NULL out. */
typedef void (*sicm_kernel_fn)(const double *in, double *out, const double *p);

/* A kernel with its captured values. */
typedef struct {
  sicm_kernel_fn fn;
  const double *p;
} sicm_closure;

/* Where a primitive was called in the source: "FILE:LINE:COL", the text of
 * that line and the column (1-based) of the call, for error messages. */
typedef struct {
  const char *where;
  const char *line;
  int col;
} sicm_site;

/* sicm_program_init reads the executable's options (--plot-dir DIR,
 * --param NAME=VALUE for each NAME of the NULL-terminated `parameters`,
 * --threads N for sweeps, a whole number from 1 to 65536, --stats, --help),
 * exiting with status 64 and a usage line for anything else, and arranges
 * for plots to be finished at exit and on SIGINT/SIGTERM. Call first (after
 * sicm_mpi_start in an MPI program). */
void sicm_program_init(int argc, char **argv, const char *program_name,
                       const char *const *parameters);

/* (parameter 'name default): the value given with --param NAME=VALUE, or
 * the default. */
double sicm_program_param(const char *name, double fallback);

/* sicm_program_fail prints "WHERE: error: WHO: REASON" ("WHERE: error:
 * REASON" when WHO is NULL), the source line and
 * a caret on stderr, finishes every plot and exits with status 70. Inside a
 * member of a parallel sweep it ends the member instead, and the sweep
 * reports it in its turn (see sicm_parallel_map). */
void sicm_program_fail(const sicm_site *site, const char *who, const char *reason)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

/* sicm_program_fail_diagnostic prints diagnostic (a whole message, source
 * line and caret, as the compiler formats its own: an error sicm build met
 * at the program's top level, which sicm run raises at that point) on
 * stderr, finishes every plot and exits with status 70. */
void sicm_program_fail_diagnostic(const char *diagnostic)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

/* A failure whose message holds numbers computed at run time (an object of
 * the wrong kind that holds them: "The object (up 1. .5 -.25), passed as
 * the first argument to car, ..."): after sicm_program_fail_capture, what
 * the sicm_print_* functions print goes into the message, and
 * sicm_program_fail_captured fails with it as sicm_program_fail_diagnostic
 * does. */
void sicm_program_fail_capture(void);
void sicm_program_fail_captured(void)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

/* The operations of the program's own arithmetic (not of kernels) that
 * sicm run would not answer with a real number: they fail at `site` as the
 * interpreter does where it raises an error (division by zero: "Division by
 * zero signalled by WHO.") and say that the result is complex where the
 * interpreter leaves the reals (sqrt and log of a negative number, asin and
 * acos outside [-1, 1], a negative number to a non-integer power), since
 * compiled code computes with real numbers. Otherwise they are a / b,
 * sqrt(x), log(x), asin(x), acos(x) and pow(x, y). `who` names the procedure
 * ("/" or "expt"). */
double sicm_checked_quotient(const sicm_site *site, const char *who, double a, double b);
double sicm_checked_sqrt(const sicm_site *site, double x);
double sicm_checked_log(const sicm_site *site, double x);
double sicm_checked_asin(const sicm_site *site, double x);
double sicm_checked_acos(const sicm_site *site, double x);
double sicm_checked_pow(const sicm_site *site, double x, double y);

/* Printing, as the compiler prints: text as it is, a real in MIT Scheme's
 * shortest round-trip form ("435.", ".5", "-1.5e-14"), an integer (given as
 * a double with an integral value) in decimal, a boolean (0 or not) as #f or
 * #t. */
void sicm_print_text(const char *s);
void sicm_print_real(double x);
void sicm_print_integer(double x);
void sicm_print_boolean(double x);

/* (real-time): milliseconds since the epoch; (runtime): processor seconds. */
double sicm_real_time(void);
double sicm_run_time(void);

/* (frame xmin xmax ymin ymax [title [x-label y-label]] option ...) and the marks added
 * to it; a plot file that cannot be created or written is a failure at
 * `site`, with the system's reason. NAME is the file name without
 * extension, TITLE may be NULL; the plot directory (--plot-dir) is created
 * if it does not exist. sicm_program_plot_labels labels the axes (y_label
 * may be NULL). */
sicm_plot *sicm_program_frame(const sicm_site *site, const char *name, const char *title,
                              double xmin, double xmax, double ymin, double ymax);
void sicm_program_plot_labels(const sicm_site *site, sicm_plot *plot, const char *x_label,
                              const char *y_label);
void sicm_program_plot_point(const sicm_site *site, sicm_plot *plot, double x, double y);
/* (graphics-clear window): sicm_plot_clear; in a member of a sweep, in its
 * place among the member's marks. */
void sicm_program_plot_clear(const sicm_site *site, sicm_plot *plot);
void sicm_program_plot_line(const sicm_site *site, sicm_plot *plot, double x0, double y0, double x1,
                            double y1);
/* The frame's options ('aspect 'equal, 'marker-size, 'legend: see
 * sicm_plot_set_equal_aspect, sicm_plot_set_marker_size and
 * sicm_plot_set_legend in runtime.h; legend is a sicm_plot_legend). */
void sicm_program_plot_options(const sicm_site *site, sicm_plot *plot, int equal_aspect,
                               double marker_size, int legend);
/* (plot-series window series option ...): how a series is drawn
 * (sicm_plot_style_series). */
void sicm_program_plot_style(const sicm_site *site, sicm_plot *plot, const char *series,
                             double marker_size, int connect);
/* (plot-point window x y series), (plot-line window x0 y0 x1 y1 series):
 * marks of a named series (NULL: the unnamed one). */
void sicm_program_plot_series_point(const sicm_site *site, sicm_plot *plot, const char *series,
                                    double x, double y);
void sicm_program_plot_series_line(const sicm_site *site, sicm_plot *plot, const char *series,
                                   double x0, double y0, double x1, double y1);

/* (definite-integral f a b tol): f's integral over [a, b] to the relative
 * tolerance tol, by adaptive Gauss-Kronrod; when a purely relative tolerance
 * cannot be met because the integral is much smaller than the integral of
 * |f|, the tolerance is taken relative to the latter (as the interpreter
 * does). Infinite limits are allowed. */
double sicm_drive_integral(const sicm_site *site, sicm_closure f, double a, double b, double tol);

/* (minimize f a b tol): Brent's method; out = {argument, value, iterations}. */
void sicm_drive_minimize(const sicm_site *site, sicm_closure f, double a, double b, double tol,
                         double out[3]);

/* (multidimensional-minimize f x tol): Nelder-Mead from x (n values), which
 * receives the minimizing point. The kernel takes the n coordinates. */
void sicm_drive_multimin(const sicm_site *site, sicm_closure f, size_t n, double *x, double tol,
                         int as_list);

/* (find-root f a b tol): a root of f in [a, b] by Brent's method; the ends
 * must bracket a root. */
double sicm_drive_find_root(const sicm_site *site, sicm_closure f, double a, double b, double tol);

/* (bisect f x0 x1 eps n-break): a root of f between x0 and x1 by bisection
 * (then, after n_break halvings, by false position) until the ends are
 * close to eps in scmutils' close-enuf? sense. */
double sicm_drive_bisect(const sicm_site *site, sicm_closure f, double x0, double x1, double eps,
                         long n_break);

/* An ODE problem: the system derivative maps a state of dim leaves to its
 * derivative. time_first: the state's first leaf is the time; rate_one: its
 * derivative is exactly 1, so the state reported at output time t carries
 * exactly t. */
typedef struct {
  const sicm_ode_step_type *method;
  sicm_closure sysder;
  size_t dim;
  int time_first;
  int rate_one;
  double tol;
  /* For implicit methods, a kernel of (D sysder): d f_i / d y_j at
   * out[j * dim + i]; NULL fn for finite differences. */
  sicm_closure jacobian;
  /* What sysder divides by: a kernel of the state computing probe_count
   * values, probe_texts[k] saying what value k is ("(sin (ref state 1 0))");
   * NULL fn for none. See sicm_ode_set_singularity_probe. */
  sicm_closure probe;
  size_t probe_count;
  const char *const *probe_texts;
  /* For the taylor methods: the Taylor coefficients of the solution, in
   * double (taylor) or long double (taylor-extended), generated from
   * sysder's code and given sysder's p; NULL otherwise. */
  sicm_ode_taylor_coefficients taylor;
  sicm_ode_taylor_extended_coefficients taylor_extended;
  /* The most steps the integrator may take to reach one output time (the
   * next monitor call, or the advancer's end): evolve's and state-advancer's
   * max-steps argument; 0 for the runtime's default. */
  unsigned long max_steps;
} sicm_drive_ode;

/* ((state-advancer ...) state dt tol): y (dim leaves) becomes the state dt
 * later. */
void sicm_drive_advance(const sicm_site *site, const sicm_drive_ode *ode, double *y, double dt);

/* An event of evolve or state-advancer, (on-crossing event direction
 * procedure) or (stop-on-crossing event direction): event, a kernel of the
 * state giving one number, crosses 0 in direction (SICM_ODE_EVENT_UP, _DOWN
 * or _BOTH of sicm/ode.h), located as crossings locates it; at each
 * crossing action, a kernel of the state with no outputs, is called with
 * the state there, or, when action's fn is NULL, the integration stops
 * there. */
typedef struct {
  sicm_closure event;
  int direction;
  sicm_closure action;
} sicm_drive_event;

/* sicm_drive_advance with n events (sicm_drive_advance is this with none):
 * their actions are called in time order on the way; y becomes the state dt
 * later, or the state at the crossing of an event that stops the
 * integration (its time, the first leaf when the state has one, tells
 * which). */
void sicm_drive_advance_events(const sicm_site *site, const sicm_drive_ode *ode, double *y,
                               double dt, const sicm_drive_event *events, size_t n);

/* ((evolve ...) state monitor dt t-final tol): calls first (a kernel of
 * the state, NULL fn for none) at the initial state, then monitor every dt
 * until t-final (the last interval shortened to end there:
 * sicm_monitor_schedule); y becomes the final state. first is monitor
 * itself, or, when the program wrote the initial state with exact numbers,
 * the monitor compiled for that state (so they print as exact, as in sicm
 * run). */
void sicm_drive_evolve(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure first,
                       sicm_closure monitor, double *y, double dt, double t_final);

/* sicm_drive_evolve with n events (sicm_drive_evolve is this with none):
 * their actions are called in time order among the monitor's calls; an
 * event that stops the integration leaves y at its crossing, and the
 * monitor is called no more. */
void sicm_drive_evolve_events(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure first,
                              sicm_closure monitor, double *y, double dt, double t_final,
                              const sicm_drive_event *events, size_t n);

/* ---- parallel-map and parallel-for-each (parallel.c) ----
 *
 * sicm_parallel_map runs n members; member i calls
 *   fns[nfns == 1 ? 0 : i].fn(in + i * in_width, out + i * out_width, fns[...].p)
 * (a NULL in when in_width is 0, a NULL out when out_width is 0). Members
 * run on the program's threads (--threads N, default: the cores this process
 * may run on) and, in a program built with --mpi and started under mpirun,
 * across ranks (member i on rank i % size); the outputs of all members end
 * up in out[] on every rank. What a member prints (sicm_print_*) and the
 * marks it plots (sicm_program_plot_point, sicm_program_plot_line) are kept
 * per member and emitted in member order after the members have run, so
 * stdout and the plot files are byte-identical to a serial run whatever the
 * threads and ranks.
 *
 * serial != 0: the members run one after another on the calling thread,
 * unbuffered (the compiler says so when members touch the program's
 * globals: cells, run-time lists, frames). So do the members of a sweep on
 * one thread and one rank, which is a serial run.
 *
 * A member that fails (sicm_program_fail) stops the sweep: members after it
 * are not started, what the members before it printed and plotted is
 * emitted, then what it did itself, then its error is reported as
 * sicm_program_fail reports it, exit status 70 (on every rank).
 *
 * Called inside a member (a nested sweep), the members run in order on the
 * member's thread, into the member's log.
 *
 * On a terminal, a sweep that has run for more than a second shows
 * "parallel-map: K/N members" on stderr (rank 0, K of its N members done),
 * erased when it ends. */
void sicm_parallel_map(const sicm_site *site, const sicm_closure *fns, size_t nfns, size_t n,
                       const double *in, size_t in_width, double *out, size_t out_width,
                       int serial);

/* The number of threads sweeps use (--threads; n below 1 means 1), and the
 * number in force (the cores this process may run on until set). */
void sicm_parallel_set_threads(int n);
int sicm_parallel_threads(void);

/* Programs built with --mpi call this first, before sicm_program_init.
 * Started without an MPI launcher (no rank in the environment: mpirun,
 * mpiexec, srun set one), it does nothing and the program runs as one
 * process. Under one: MPI_Init (MPI_Init_thread, funneled: only the calling
 * thread calls MPI),
 * MPI_Finalize at exit (a normal exit and a failure's exit 70 alike), and
 * every rank but 0 stays quiet: it prints nothing, writes no plot file and,
 * on a failure, exits with the same status without a message. Defined only
 * in libsicmrt_mpi.a (runtime/mpi/), linked before libsicmrt.a. */
void sicm_mpi_start(int *argc, char ***argv);

/* ---- lists whose length is known only at run time (list.c) ----
 *
 * A list the program builds at run time (a monitor consing each state onto a
 * global, a map over such a list) whose elements all have one shape: each
 * element is `width` doubles (the leaves of a number, a pair or an up/down
 * structure of numbers). Elements are kept in the order they were added:
 * data[i * width + leaf] is leaf `leaf` of the i-th element added. A Scheme
 * list built by consing onto the front is the array read from the end; the
 * compiler turns car, cdr, reverse, list-ref and length into positions in
 * the array (a list value is a range [lo, hi) read forward or backward), so
 * the runtime only stores and fetches. Positions are passed as doubles with
 * integral values, as every run-time number is. */
typedef struct {
  double *data;
  size_t len;   /* elements */
  size_t cap;   /* elements allocated */
  size_t width; /* doubles per element */
} sicm_list;

/* Empty the list (keeping its memory) for elements of `width` doubles. */
void sicm_list_reset(sicm_list *list, size_t width);

/* Add an element (width doubles) after the last; out of memory is a failure
 * at `site`. */
void sicm_list_push(const sicm_site *site, sicm_list *list, const double *element);

/* Reset the list for elements of `width` doubles and add the `len` elements
 * of `data` (a constant table: a list known at compile time that a loop
 * walks at run time); out of memory is a failure at `site`. */
void sicm_list_assign(const sicm_site *site, sicm_list *list, size_t width, const double *data,
                      size_t len);

/* ((crossings ...) state event direction t-final tol [integrator [count]]):
 * the states, from y (dim leaves) to t_final, at which event (a kernel of
 * the state giving one number) crosses 0 in direction (SICM_ODE_EVENT_UP,
 * _DOWN or _BOTH of sicm/ode.h), added in time order to list (which the
 * caller has emptied for elements of dim doubles); the first count of them
 * only, the integration stopping at the last, when count > 0. */
void sicm_drive_crossings(const sicm_site *site, const sicm_drive_ode *ode, sicm_closure event,
                          int direction, long count, const double *y, double t_final,
                          sicm_list *list);

/* The number of elements added since the last reset. */
double sicm_list_length(const sicm_list *list);

/* Leaf `leaf` of the element at `index`, which must lie in the range [lo, hi)
 * the list value covers: otherwise a failure at `site` (WHO: the list is
 * empty, or the index is out of range), as the interpreter's car or
 * list-ref of a too short list is an error. */
double sicm_list_ref(const sicm_site *site, const char *who, const sicm_list *list, double index,
                     double lo, double hi, size_t leaf);

/* (apply min l), (apply max l), (apply + l), (apply * l) of the numbers
 * (width-1 elements) at positions [lo, hi), taken from hi - 1 down when
 * `backward` (the order of a list built by consing), so that sums round as
 * the interpreter's do: MIT's min and max (a NaN anywhere gives NaN); min or
 * max of no number is a failure at `site`. */
typedef enum { SICM_LIST_MIN, SICM_LIST_MAX, SICM_LIST_SUM, SICM_LIST_PRODUCT } sicm_list_fold_op;
double sicm_list_fold(const sicm_site *site, const sicm_list *list, sicm_list_fold_op op, double lo,
                      double hi, int backward);

#ifdef __cplusplus
}
#endif

#endif /* SICM_PROGRAM_H */
