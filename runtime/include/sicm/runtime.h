/* sicm runtime library (libsicmrt): the one public header.
 *
 * C11, every symbol prefixed sicm_. Generated programs and the compiler link
 * against it. Functions are grouped by module; each group says what it
 * provides. */
#ifndef SICM_RUNTIME_H
#define SICM_RUNTIME_H

#include <stddef.h>

/* Numerical modules, one header each (documented there): status codes and
 * the error hook, ODE integrators, minimizers, root finders, quadrature,
 * dense linear algebra (eigenvalues, over Eigen). */
#include "sicm/error.h"
#include "sicm/linalg.h"
#include "sicm/min.h"
#include "sicm/ode.h"
#include "sicm/program.h"
#include "sicm/quad.h"
#include "sicm/root.h"
#include "sicm/stats.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- number printing --------------------------------------------------
 * The one implementation of flonum printing, shared by the compiler (for
 * values known at compile time) and by generated programs (for values
 * computed at run time), so both print identically.
 *
 * sicm_format_double writes x in MIT Scheme's form: the shortest digit
 * string that reads back as x, laid out as MIT does ("435.", ".75",
 * "-1.5987211554602254e-14", "1e21", "+inf.0", "-inf.0", "+nan.0", "0.",
 * "-0."). buf must hold at least SICM_DOUBLE_BUFSIZE bytes. Returns the
 * length written (not counting the terminating NUL). */
#define SICM_DOUBLE_BUFSIZE 40
size_t sicm_format_double(char *buf, double x);

/* sicm_format_tolerance writes x as people write a tolerance: the shortest
 * %g form that reads back as x ("1e-12", "2.5e-13", "0.01"), not Scheme's
 * ".000000000001" (messages and --stats). buf must hold at least
 * SICM_DOUBLE_BUFSIZE bytes. Returns the length written. */
size_t sicm_format_tolerance(char *buf, double x);

/* sicm_shortest_digits stores in digits (>= 18 bytes) the shortest decimal
 * digit string d1 d2 ... dn (no sign, no point, no trailing zeros) such that
 * 0.d1d2...dn * 10^(*exponent10 + 1) read back gives |x|, i.e. |x| is
 * d1.d2...dn * 10^(*exponent10). x must be finite and non-zero. Returns n. */
size_t sicm_shortest_digits(char *digits, int *exponent10, double x);

/* ---- plot files ----------------------------------------------------------
 * A plot is a frame [xmin, xmax] x [ymin, ymax] that collects points and line
 * segments. sicm_plot_open creates DIR/NAME.tsv at once and appends every
 * point to it as it arrives; sicm_plot_finish closes the TSV and writes
 * DIR/NAME.svg (axes, ticks, labels, the marks inside the frame, a legend)
 * atomically: to NAME.svg.tmp, then renamed. Every plot still open is finished at exit
 * and on SIGINT/SIGTERM (the process then exits 128+signal), so an
 * interrupted run keeps every point it produced. Functions return 0 on
 * success and -1 with errno set on failure. */
typedef struct sicm_plot sicm_plot;

/* Open a plot; dir NULL means ".", title NULL means name. dir and its
 * parents are created if they do not exist. NULL on failure, errno saying
 * why (EINVAL for an empty range; mkdir's or fopen's reason otherwise). */
sicm_plot *sicm_plot_open(const char *dir, const char *name, const char *title, double xmin,
                          double xmax, double ymin, double ymax);
/* A plot that writes no file and keeps no mark, for the MPI ranks that stay
 * quiet (every rank but 0): it takes every call a plot takes, and refuses
 * marks once finished, as a real plot does, so the quiet ranks fail where
 * rank 0 fails. name is its title. NULL if memory runs out. */
sicm_plot *sicm_plot_open_silent(const char *name);
/* Label the axes (either NULL for none): x_label under the x axis, y_label
 * beside the y axis, written into the SVG. */
int sicm_plot_set_labels(sicm_plot *p, const char *x_label, const char *y_label);
int sicm_plot_point(sicm_plot *p, double x, double y);
int sicm_plot_line(sicm_plot *p, double x0, double y0, double x1, double y1);

/* Series. Every mark belongs to a series: the unnamed one (series NULL,
 * what sicm_plot_point and sicm_plot_line add to; dark blue points, red
 * segments) or one named by a non-empty string. A named series gets the
 * next colour of a ten-colour palette when its first mark arrives, and the
 * legend lists the named series in that order, so the picture depends only
 * on the order of the marks. In the TSV a named series' mark has its name
 * as a last column (tabs and newlines in it written as spaces). */
int sicm_plot_series_point(sicm_plot *p, const char *series, double x, double y);
int sicm_plot_series_line(sicm_plot *p, const char *series, double x0, double y0, double x1,
                          double y1);
/* How a series (NULL: the unnamed one) is drawn: its points as dots of
 * marker_size pixels across (0: no dots; negative: the plot's size, below),
 * and, if connect is non-zero, joined in the order they came by a polyline. */
int sicm_plot_style_series(sicm_plot *p, const char *series, double marker_size, int connect);

/* Frame options (each may be set any time before the plot is finished). The default dot size, for
 * every series not styled with its own: marker_size pixels, or (negative, the default) by the
 * number of points in the plot: 4 below 300 points, 3 below 3000, else 2, so that a sparse section
 * stays visible and a dense one does not blot. */
int sicm_plot_set_marker_size(sicm_plot *p, double marker_size);
/* Equal aspect (non-zero): a unit of x is as long on the page as a unit of
 * y; the frame is shrunk along one axis and centred. */
int sicm_plot_set_equal_aspect(sicm_plot *p, int equal);
/* Where the legend of the named series goes (none without named series):
 * BEST, the default, is the corner inside the frame where it hides the
 * fewest marks (top right, top left, bottom right, bottom left on ties). */
typedef enum {
  SICM_PLOT_LEGEND_BEST,
  SICM_PLOT_LEGEND_TOP_RIGHT,
  SICM_PLOT_LEGEND_TOP_LEFT,
  SICM_PLOT_LEGEND_BOTTOM_LEFT,
  SICM_PLOT_LEGEND_BOTTOM_RIGHT,
  SICM_PLOT_LEGEND_NONE
} sicm_plot_legend;
int sicm_plot_set_legend(sicm_plot *p, sicm_plot_legend where);
/* Remove every mark plotted so far (graphics-clear): the picture shows only
 * the marks added after it, the named series lose their colours and legend
 * rows until their next mark, styles and frame options stay. The TSV, a
 * log of the marks in order, gets the line "# cleared" there. -1 (errno
 * EINVAL) once the plot is finished. */
int sicm_plot_clear(sicm_plot *p);
/* Whether the plot has been finished (its marks are refused). */
int sicm_plot_is_finished(const sicm_plot *p);
/* Number of marks (points and segments) added so far. */
size_t sicm_plot_count(const sicm_plot *p);
/* Write the SVG and close the TSV; later marks are refused. Idempotent. */
int sicm_plot_finish(sicm_plot *p);
/* Finish (if needed) and release a plot. */
void sicm_plot_free(sicm_plot *p);
/* Finish every open plot (called at exit and on SIGINT/SIGTERM). */
void sicm_plot_close_all(void);

#ifdef __cplusplus
}
#endif

#endif /* SICM_RUNTIME_H */
