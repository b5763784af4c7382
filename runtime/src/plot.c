/* Plot files: every frame becomes NAME.tsv (the raw points, written as the
 * run goes) and NAME.svg (axes, ticks, labels, points), finished when the
 * frame is closed, at exit, or on SIGINT/SIGTERM.
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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sicm/runtime.h"

enum { kFlushEvery = 4096, kMaxOpenPlots = 256 };

typedef struct {
  double x0, y0, x1, y1; /* a point has x1 = NAN */
} mark;

struct sicm_plot {
  char *path;              /* NAME without extension, in its directory */
  char *title;             /* shown above the picture */
  char *x_label, *y_label; /* under the x axis, beside the y axis; NULL for none */
  double xmin, xmax, ymin, ymax;
  FILE *tsv;
  mark *marks;
  size_t n, cap;
  size_t unflushed;
  int closed;
  int silent; /* sicm_plot_open_silent: no files, no marks kept */
};

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

static int add_mark(sicm_plot *p, mark m) {
  if (p->closed) {
    errno = EINVAL;
    return -1;
  }
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 1024;
    mark *grown = realloc(p->marks, cap * sizeof *grown);
    if (!grown) return -1;
    p->marks = grown;
    p->cap = cap;
  }
  p->marks[p->n++] = m;
  return 0;
}

static int add_point(sicm_plot *p, double x, double y);
static int add_line(sicm_plot *p, double x0, double y0, double x1, double y1);

static void write_tsv_number(FILE *f, double x) {
  char buf[SICM_DOUBLE_BUFSIZE];
  /* The TSV holds plain C numbers (0.5, not MIT's .5) so any tool reads it. */
  snprintf(buf, sizeof buf, "%.17g", x);
  fputs(buf, f);
}

static void after_write(sicm_plot *p) {
  if (++p->unflushed >= kFlushEvery) {
    fflush(p->tsv);
    p->unflushed = 0;
  }
}

int sicm_plot_point(sicm_plot *p, double x, double y) {
  enter_operation();
  int status = add_point(p, x, y);
  leave_operation();
  return status;
}

/* A silent plot keeps nothing but refuses marks once finished, as a real one. */
static int silent_mark(const sicm_plot *p) {
  if (!p->closed) return 0;
  errno = EINVAL;
  return -1;
}

static int add_point(sicm_plot *p, double x, double y) {
  if (p->silent) return silent_mark(p);
  mark m = {x, y, NAN, NAN};
  if (add_mark(p, m) != 0) return -1;
  write_tsv_number(p->tsv, x);
  fputc('\t', p->tsv);
  write_tsv_number(p->tsv, y);
  fputc('\n', p->tsv);
  after_write(p);
  return 0;
}

int sicm_plot_line(sicm_plot *p, double x0, double y0, double x1, double y1) {
  enter_operation();
  int status = add_line(p, x0, y0, x1, y1);
  leave_operation();
  return status;
}

static int add_line(sicm_plot *p, double x0, double y0, double x1, double y1) {
  if (p->silent) return silent_mark(p);
  mark m = {x0, y0, x1, y1};
  if (add_mark(p, m) != 0) return -1;
  write_tsv_number(p->tsv, x0);
  fputc('\t', p->tsv);
  write_tsv_number(p->tsv, y0);
  fputc('\t', p->tsv);
  write_tsv_number(p->tsv, x1);
  fputc('\t', p->tsv);
  write_tsv_number(p->tsv, y1);
  fputc('\n', p->tsv);
  after_write(p);
  return 0;
}

/* ---- the SVG picture ---------------------------------------------------- */

enum { kWidth = 660, kHeight = 480, kLeft = 90, kRight = 20, kTop = 40, kBottom = 50 };

static double px(const sicm_plot *p, double x) {
  return kLeft + (x - p->xmin) / (p->xmax - p->xmin) * (kWidth - kLeft - kRight);
}
static double py(const sicm_plot *p, double y) {
  return kHeight - kBottom - (y - p->ymin) / (p->ymax - p->ymin) * (kHeight - kTop - kBottom);
}

/* A "nice" tick spacing: 1, 2 or 5 times a power of ten, about 5-10 ticks. */
static double tick_step(double span) {
  double raw = span / 6.0;
  double mag = pow(10.0, floor(log10(raw)));
  double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * mag;
}

static void write_escaped(FILE *f, const char *s) {
  for (; *s; ++s) {
    switch (*s) {
    case '<': fputs("&lt;", f); break;
    case '>': fputs("&gt;", f); break;
    case '&': fputs("&amp;", f); break;
    case '"': fputs("&quot;", f); break;
    default: fputc(*s, f);
    }
  }
}

/* A tick label: k * step printed with just the digits the step needs
 * (so 0.46, not .4600000000000001), in plain C notation for SVG readers:
 * fixed-point between 1e-4 and 1e6, else compact scientific notation
 * (2e-10, 1.5e7; not 0.0000000002). */
static void tick_label(char *buf, size_t size, long k, double step) {
  double value = (double)k * step;
  if (fabs(value) < step * 1e-9) value = 0.0;
  if (value != 0 && (step < 1e-4 || fabs(value) >= 1e6)) {
    /* the digits of value down to the step's decade */
    int decimals = (int)floor(log10(fabs(value)) + 1e-9) - (int)floor(log10(step) + 1e-9);
    if (decimals < 0) decimals = 0;
    if (decimals > 15) decimals = 15;
    char mantissa[64];
    snprintf(mantissa, sizeof mantissa, "%.*e", decimals, value);
    char *e = strchr(mantissa, 'e'); /* 2e-05 -> 2e-5, 1.5e+07 -> 1.5e7 */
    int exponent = atoi(e + 1);
    *e = '\0';
    char exponent_text[16];
    snprintf(exponent_text, sizeof exponent_text, "e%d", exponent);
    snprintf(buf, size, "%.32s%s", mantissa, exponent_text);
    return;
  }
  if (value == 0 && step < 1e-4) { /* beside 2e-10, not 0.0000000000 */
    snprintf(buf, size, "0");
    return;
  }
  int decimals = step >= 1 ? 0 : (int)ceil(-log10(step) - 1e-9);
  if (decimals > 15) decimals = 15;
  snprintf(buf, size, "%.*f", decimals, value);
}

static void write_ticks(FILE *f, const sicm_plot *p) {
  char label[64];
  double step = tick_step(p->xmax - p->xmin);
  for (long k = (long)ceil(p->xmin / step - 1e-9); k * step <= p->xmax + step * 1e-9; ++k) {
    double x = px(p, k * step), y0 = kHeight - kBottom;
    tick_label(label, sizeof label, k, step);
    fprintf(f, "<line x1=\"%.2f\" y1=\"%d\" x2=\"%.2f\" y2=\"%d\" stroke=\"black\"/>\n", x, (int)y0,
            x, (int)y0 + 5);
    fprintf(f, "<text x=\"%.2f\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", x, (int)y0 + 20,
            label);
  }
  step = tick_step(p->ymax - p->ymin);
  for (long k = (long)ceil(p->ymin / step - 1e-9); k * step <= p->ymax + step * 1e-9; ++k) {
    double y = py(p, k * step);
    tick_label(label, sizeof label, k, step);
    fprintf(f, "<line x1=\"%d\" y1=\"%.2f\" x2=\"%d\" y2=\"%.2f\" stroke=\"black\"/>\n", kLeft - 5,
            y, kLeft, y);
    fprintf(f, "<text x=\"%d\" y=\"%.2f\" text-anchor=\"end\">%s</text>\n", kLeft - 8, y + 4,
            label);
  }
}

static int inside(const sicm_plot *p, double x, double y) {
  return x >= p->xmin && x <= p->xmax && y >= p->ymin && y <= p->ymax;
}

static void write_marks(FILE *f, const sicm_plot *p) {
  /* All points as one path of zero-length segments with round caps: small
   * files and fast rendering even for hundreds of thousands of points. */
  fputs("<path fill=\"none\" stroke=\"#1f4e99\" stroke-width=\"2\" stroke-linecap=\"round\" d=\"",
        f);
  for (size_t i = 0; i < p->n; ++i) {
    const mark *m = &p->marks[i];
    if (!isnan(m->x1) || !inside(p, m->x0, m->y0)) continue;
    fprintf(f, "M%.2f %.2fh0", px(p, m->x0), py(p, m->y0));
  }
  fputs("\"/>\n", f);
  for (size_t i = 0; i < p->n; ++i) {
    const mark *m = &p->marks[i];
    if (isnan(m->x1)) continue;
    fprintf(f,
            "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"#b33\" "
            "stroke-width=\"1\"/>\n",
            px(p, m->x0), py(p, m->y0), px(p, m->x1), py(p, m->y1));
  }
}

static int write_svg(const sicm_plot *p) {
  char tmp[4096], final[4096];
  snprintf(tmp, sizeof tmp, "%s.svg.tmp", p->path);
  snprintf(final, sizeof final, "%s.svg", p->path);
  FILE *f = fopen(tmp, "w");
  if (!f) return -1;
  fprintf(f,
          "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
          "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
          "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\" font-size=\"12\">\n"
          "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
          kWidth, kHeight, kWidth, kHeight);
  fprintf(f, "<text x=\"%d\" y=\"24\" text-anchor=\"middle\" font-size=\"15\">", kWidth / 2);
  write_escaped(f, p->title);
  fputs("</text>\n", f);
  fprintf(f,
          "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" stroke=\"black\"/>\n",
          kLeft, kTop, kWidth - kLeft - kRight, kHeight - kTop - kBottom);
  fprintf(
      f, "<clipPath id=\"frame\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/></clipPath>\n",
      kLeft, kTop, kWidth - kLeft - kRight, kHeight - kTop - kBottom);
  write_ticks(f, p);
  if (p->x_label) {
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\">",
            kLeft + (kWidth - kLeft - kRight) / 2, kHeight - 10);
    write_escaped(f, p->x_label);
    fputs("</text>\n", f);
  }
  if (p->y_label) {
    const int x = 16, y = kTop + (kHeight - kTop - kBottom) / 2;
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" transform=\"rotate(-90 %d %d)\">", x,
            y, x, y);
    write_escaped(f, p->y_label);
    fputs("</text>\n", f);
  }
  fputs("<g clip-path=\"url(#frame)\">\n", f);
  write_marks(f, p);
  fputs("</g>\n</svg>\n", f);
  int ok = ferror(f) == 0;
  if (fclose(f) != 0) ok = 0;
  if (!ok || rename(tmp, final) != 0) {
    remove(tmp);
    return -1;
  }
  return 0;
}

static int finish_plot(sicm_plot *p) {
  if (p->closed) return 0;
  p->closed = 1;
  if (p->silent) return 0;
  int status = 0;
  if (fclose(p->tsv) != 0) status = -1;
  p->tsv = NULL;
  if (write_svg(p) != 0) status = -1;
  return status;
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
