/* The SVG picture of a plot: frame, ticks, title and axis labels, every
 * series' marks in its colour, and a legend of the named series.
 *
 * Size. A Poincare section has 10^4 to 10^6 points, and the picture must
 * stay small enough to open in a browser or a notebook. Coordinates are
 * written in tenths of a pixel (finer than any screen shows), relative to
 * the previous one, without zeros or spaces the path grammar does not need.
 * A series' dots are one path of zero-length segments with round caps;
 * since dots of one colour may be drawn in any order, they are sorted into
 * one-pixel rows walked alternately left and right, so that each step is a
 * few characters and a dot drawn twice is written once. About 8 bytes a dot
 * (the TSV keeps every point, in order, at full precision). Segments and
 * polylines keep their order, one path per series, a segment that starts
 * where the last one ended continuing it. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plot_internal.h"

enum { kWidth = 660, kHeight = 480, kLeft = 90, kRight = 20, kTop = 40, kBottom = 50 };

/* Coordinates in tenths of a pixel are clamped to +-10^8, far outside the
 * picture (a line to a far-away point leaves the frame there anyway). */
static const double kMaxTenths = 1e8;

/* matplotlib's "tab10": ten colours told apart on white and by most
 * colour-blind readers, in the order series get them. */
static const char *const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                       "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
enum { kPaletteSize = sizeof kPalette / sizeof kPalette[0] };
/* The unnamed series keeps the colours plots have always had. */
static const char kUnnamedPoints[] = "#1f4e99", kUnnamedLines[] = "#b33";

/* Where the frame is on the page. */
typedef struct {
  double left, top, width, height;
} area;

static area plot_area(const sicm_plot *p) {
  area a = {kLeft, kTop, kWidth - kLeft - kRight, kHeight - kTop - kBottom};
  if (p->equal_aspect) {
    const double dx = p->xmax - p->xmin, dy = p->ymax - p->ymin;
    const double scale = fmin(a.width / dx, a.height / dy);
    const double w = scale * dx, h = scale * dy;
    a.left += (a.width - w) / 2;
    a.top += (a.height - h) / 2;
    a.width = w;
    a.height = h;
  }
  return a;
}

static double px(const sicm_plot *p, const area *a, double x) {
  return a->left + (x - p->xmin) / (p->xmax - p->xmin) * a->width;
}
static double py(const sicm_plot *p, const area *a, double y) {
  return a->top + a->height - (y - p->ymin) / (p->ymax - p->ymin) * a->height;
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

static void write_ticks(FILE *f, const sicm_plot *p, const area *a) {
  char label[64];
  const double bottom = a->top + a->height;
  double step = tick_step(p->xmax - p->xmin);
  for (long k = (long)ceil(p->xmin / step - 1e-9); k * step <= p->xmax + step * 1e-9; ++k) {
    double x = px(p, a, k * step);
    tick_label(label, sizeof label, k, step);
    fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"black\"/>\n", x,
            bottom, x, bottom + 5);
    fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">%s</text>\n", x, bottom + 20,
            label);
  }
  step = tick_step(p->ymax - p->ymin);
  for (long k = (long)ceil(p->ymin / step - 1e-9); k * step <= p->ymax + step * 1e-9; ++k) {
    double y = py(p, a, k * step);
    tick_label(label, sizeof label, k, step);
    fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"black\"/>\n",
            a->left - 5, y, a->left, y);
    fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"end\">%s</text>\n", a->left - 8, y + 4,
            label);
  }
}

static void write_labels(FILE *f, const sicm_plot *p, const area *a) {
  if (p->x_label) {
    fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\">", a->left + a->width / 2,
            fmin(a->top + a->height + 40, kHeight - 6));
    write_escaped(f, p->x_label);
    fputs("</text>\n", f);
  }
  if (p->y_label) {
    const double x = fmax(a->left - 74, 16), y = a->top + a->height / 2;
    fprintf(f,
            "<text x=\"%.2f\" y=\"%.2f\" text-anchor=\"middle\" "
            "transform=\"rotate(-90 %.2f %.2f)\">",
            x, y, x, y);
    write_escaped(f, p->y_label);
    fputs("</text>\n", f);
  }
}

/* ---- paths in tenths of a pixel ------------------------------------------ */

typedef struct {
  long x, y;
} tenths_point;

static long to_tenths(double pixel) {
  double t = round(pixel * 10);
  return (long)fmax(-kMaxTenths, fmin(kMaxTenths, t));
}

static tenths_point mark_at(const sicm_plot *p, const area *a, double x, double y) {
  tenths_point t = {to_tenths(px(p, a, x)), to_tenths(py(p, a, y))};
  return t;
}

/* A path being written: where its pen is, whether it has moved yet, and
 * its last command letter (a lineto after a lineto needs none). */
typedef struct {
  FILE *f;
  tenths_point at;
  int started;
  char last;
} pen;

/* v tenths as the shortest path number: 12.3, .5, -.5, 7 (a space before
 * it only where the previous number would run into it). */
static void put_tenths(FILE *f, long v, int after_number) {
  if (v < 0) {
    fputc('-', f);
    v = -v;
  } else if (after_number) {
    fputc(' ', f);
  }
  const long whole = v / 10, tenth = v % 10;
  if (whole || !tenth) fprintf(f, "%ld", whole);
  if (tenth) fprintf(f, ".%ld", tenth);
}

/* A command to `to`: absolute for the path's first (M), else relative. */
static void pen_command(pen *pn, char relative, tenths_point to) {
  long x = to.x, y = to.y;
  const int repeated = pn->started && relative == 'l' && pn->last == 'l';
  if (pn->started) {
    if (!repeated) fputc(relative, pn->f);
    x -= pn->at.x;
    y -= pn->at.y;
  } else {
    fputc('M', pn->f); /* a path starts with a move */
  }
  put_tenths(pn->f, x, repeated);
  put_tenths(pn->f, y, 1);
  pn->last = pn->started ? relative : 'M';
  pn->at = to;
  pn->started = 1;
}

static int same(tenths_point a, tenths_point b) {
  return a.x == b.x && a.y == b.y;
}

/* Dots in one-pixel rows, alternately left to right and right to left. */
static int by_rows(const void *pa, const void *pb) {
  const tenths_point *a = pa, *b = pb;
  const long ra = a->y / 10, rb = b->y / 10;
  if (ra != rb) return ra < rb ? -1 : 1;
  if (a->x != b->x) return ((a->x < b->x) == (ra % 2 == 0)) ? -1 : 1;
  return a->y < b->y ? -1 : a->y > b->y;
}

static int inside(const sicm_plot *p, double x, double y) {
  return x >= p->xmin && x <= p->xmax && y >= p->ymin && y <= p->ymax;
}

/* ---- series -------------------------------------------------------------- */

/* What a series draws, gathered from the marks. */
typedef struct {
  const sicm_plot_series_info *info;
  size_t *marks; /* its marks' indices, in order */
  size_t n_marks, n_segments;
  double marker; /* dot size, pixels */
  const char *points_colour, *lines_colour;
  double line_width;
} series_view;

static double marker_size(const sicm_plot *p, const sicm_plot_series_info *s) {
  if (s->marker_size >= 0) return s->marker_size;
  if (s->connect) return 0; /* a connected series is a line unless asked for dots */
  if (p->marker_size >= 0) return p->marker_size;
  return p->points < 300 ? 4 : p->points < 3000 ? 3 : 2;
}

static int write_dots(FILE *f, const sicm_plot *p, const area *a, const series_view *v) {
  if (v->marker <= 0 || v->info->points == 0) return 0;
  tenths_point *dots = malloc(v->info->points * sizeof *dots);
  if (!dots) return -1;
  size_t n = 0;
  for (size_t k = 0; k < v->n_marks; ++k) {
    const sicm_plot_mark *m = &p->marks[v->marks[k]];
    if (isnan(m->x1) && inside(p, m->x0, m->y0)) dots[n++] = mark_at(p, a, m->x0, m->y0);
  }
  qsort(dots, n, sizeof *dots, by_rows);
  fprintf(f,
          "<path fill=\"none\" stroke=\"%s\" stroke-width=\"%g\" stroke-linecap=\"round\" "
          "d=\"",
          v->points_colour, v->marker);
  pen pn = {f, {0, 0}, 0, 0};
  for (size_t k = 0; k < n; ++k) {
    if (pn.started && same(dots[k], pn.at)) continue; /* drawn already */
    pen_command(&pn, 'm', dots[k]);
    fputs("h0", f);
    pn.last = 'h';
  }
  fputs("\"/>\n", f);
  free(dots);
  return 0;
}

static int finite_mark(const sicm_plot_mark *m) {
  return isfinite(m->x0) && isfinite(m->y0) &&
         (isnan(m->x1) || (isfinite(m->x1) && isfinite(m->y1)));
}

static void write_segments(FILE *f, const sicm_plot *p, const area *a, const series_view *v) {
  if (v->n_segments == 0) return;
  fprintf(f, "<path fill=\"none\" stroke=\"%s\" stroke-width=\"%g\" d=\"", v->lines_colour,
          v->line_width);
  pen pn = {f, {0, 0}, 0, 0};
  for (size_t k = 0; k < v->n_marks; ++k) {
    const sicm_plot_mark *m = &p->marks[v->marks[k]];
    if (isnan(m->x1) || !finite_mark(m)) continue;
    const tenths_point from = mark_at(p, a, m->x0, m->y0), to = mark_at(p, a, m->x1, m->y1);
    if (!pn.started || !same(from, pn.at)) pen_command(&pn, 'm', from);
    pen_command(&pn, 'l', to);
  }
  fputs("\"/>\n", f);
}

/* A connected series: its points joined in order (non-finite ones skipped). */
static void write_polyline(FILE *f, const sicm_plot *p, const area *a, const series_view *v) {
  if (!v->info->connect || v->info->points < 2) return;
  fprintf(f, "<path fill=\"none\" stroke=\"%s\" stroke-width=\"%g\" stroke-linejoin=\"round\" d=\"",
          v->points_colour, v->line_width);
  pen pn = {f, {0, 0}, 0, 0};
  for (size_t k = 0; k < v->n_marks; ++k) {
    const sicm_plot_mark *m = &p->marks[v->marks[k]];
    if (!isnan(m->x1) || !finite_mark(m)) continue;
    const tenths_point to = mark_at(p, a, m->x0, m->y0);
    if (pn.started && same(to, pn.at)) continue;
    pen_command(&pn, pn.started ? 'l' : 'm', to);
  }
  fputs("\"/>\n", f);
}

/* ---- the legend ---------------------------------------------------------- */

/* Characters (not bytes) of a UTF-8 name: its width on the page, roughly. */
static size_t text_length(const char *s) {
  size_t n = 0;
  for (; *s; ++s)
    n += ((unsigned char)*s & 0xC0) != 0x80;
  return n;
}

enum { kRow = 18, kPad = 6, kSwatch = 24, kCharWidth = 7, kInset = 8 };

/* The top left (*x, *y) of a w x h legend in a corner of the frame. */
static void corner_box(const area *a, sicm_plot_legend where, double w, double h, double *x,
                       double *y) {
  const int right = where == SICM_PLOT_LEGEND_TOP_RIGHT || where == SICM_PLOT_LEGEND_BOTTOM_RIGHT;
  const int bottom =
      where == SICM_PLOT_LEGEND_BOTTOM_LEFT || where == SICM_PLOT_LEGEND_BOTTOM_RIGHT;
  *x = right ? a->left + a->width - kInset - w : a->left + kInset;
  *y = bottom ? a->top + a->height - kInset - h : a->top + kInset;
}

static int in_box(double x, double y, double bx, double by, double w, double h) {
  return x >= bx && x <= bx + w && y >= by && y <= by + h;
}

/* The corner where a w x h legend covers the fewest marks: points, and the
 * ends and middles of segments (a sample that sees a line crossing the
 * box, at the scale of a legend). Ties go to the first corner tried. */
static sicm_plot_legend best_corner(const sicm_plot *p, const area *a, double w, double h) {
  static const sicm_plot_legend corners[] = {SICM_PLOT_LEGEND_TOP_RIGHT, SICM_PLOT_LEGEND_TOP_LEFT,
                                             SICM_PLOT_LEGEND_BOTTOM_RIGHT,
                                             SICM_PLOT_LEGEND_BOTTOM_LEFT};
  size_t covered[4] = {0, 0, 0, 0};
  double bx[4], by[4];
  for (int c = 0; c < 4; ++c)
    corner_box(a, corners[c], w, h, &bx[c], &by[c]);
  for (size_t i = 0; i < p->n; ++i) {
    const sicm_plot_mark *m = &p->marks[i];
    double xs[3] = {m->x0, m->x1, (m->x0 + m->x1) / 2}, ys[3] = {m->y0, m->y1, (m->y0 + m->y1) / 2};
    const int samples = isnan(m->x1) ? 1 : 3;
    for (int k = 0; k < samples; ++k) {
      const double x = px(p, a, xs[k]), y = py(p, a, ys[k]);
      for (int c = 0; c < 4; ++c)
        covered[c] += in_box(x, y, bx[c], by[c], w, h);
    }
  }
  int best = 0;
  for (int c = 1; c < 4; ++c)
    if (covered[c] < covered[best]) best = c;
  return corners[best];
}

static void write_legend(FILE *f, const sicm_plot *p, const area *a, series_view *const *rows,
                         size_t n) {
  if (n == 0 || p->legend == SICM_PLOT_LEGEND_NONE) return;
  size_t longest = 0;
  for (size_t i = 0; i < n; ++i) {
    size_t len = text_length(rows[i]->info->name);
    if (len > longest) longest = len;
  }
  const double w = kPad + kSwatch + kPad + (double)longest * kCharWidth + kPad;
  const double h = (double)n * kRow + kPad;
  const sicm_plot_legend where =
      p->legend == SICM_PLOT_LEGEND_BEST ? best_corner(p, a, w, h) : p->legend;
  double x, y;
  corner_box(a, where, w, h, &x, &y);
  fprintf(f, "<g class=\"legend\">\n");
  fprintf(f,
          "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"white\" "
          "fill-opacity=\"0.85\" stroke=\"#999\"/>\n",
          x, y, w, h);
  for (size_t i = 0; i < n; ++i) {
    const series_view *v = rows[i];
    const double cy = y + kPad / 2.0 + (double)i * kRow + kRow / 2.0, sx = x + kPad;
    if (v->n_segments > 0 || v->info->connect)
      fprintf(f,
              "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
              "stroke-width=\"%g\"/>\n",
              sx, cy, sx + kSwatch, cy, v->lines_colour, fmax(v->line_width, 2));
    if (v->marker > 0 && v->info->points > 0)
      fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"%g\" fill=\"%s\"/>\n", sx + kSwatch / 2.0, cy,
              fmax(v->marker / 2, 3), v->points_colour);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">", sx + kSwatch + kPad, cy + 4);
    write_escaped(f, v->info->name);
    fputs("</text>\n", f);
  }
  fputs("</g>\n", f);
}

/* The frame's clip path's id says where the frame is, so that pictures
 * shown together in one page (a notebook) each clip to their own frame:
 * two plots with the same id have the same clip rectangle. */
static void write_clip_id(FILE *f, const area *a) {
  fprintf(f, "frame-%ld-%ld-%ld-%ld", to_tenths(a->left), to_tenths(a->top), to_tenths(a->width),
          to_tenths(a->height));
}

/* ---- the whole picture ----------------------------------------------------- */

/* Each series that has marks, the unnamed one first, then by rank. */
static series_view *gather_series(const sicm_plot *p, size_t **order_storage) {
  series_view *views = calloc(p->n_series ? p->n_series : 1, sizeof *views);
  size_t *order = malloc((p->n ? p->n : 1) * sizeof *order);
  size_t *start = calloc(p->n_series + 1, sizeof *start);
  if (!views || !order || !start) {
    free(views);
    free(order);
    free(start);
    return NULL;
  }
  for (size_t i = 0; i < p->n; ++i)
    ++start[p->marks[i].series + 1];
  for (size_t s = 0; s < p->n_series; ++s)
    start[s + 1] += start[s];
  for (size_t s = 0; s < p->n_series; ++s) {
    const sicm_plot_series_info *info = &p->series[s];
    views[s].info = info;
    views[s].marks = order + start[s];
    views[s].marker = marker_size(p, info);
    const char *colour = info->name ? kPalette[info->rank % kPaletteSize] : NULL;
    views[s].points_colour = colour ? colour : kUnnamedPoints;
    views[s].lines_colour = colour ? colour : kUnnamedLines;
    views[s].line_width = info->name ? 1.5 : 1;
  }
  for (size_t i = 0; i < p->n; ++i) {
    series_view *v = &views[p->marks[i].series];
    v->marks[v->n_marks++] = i;
    if (!isnan(p->marks[i].x1)) ++v->n_segments;
  }
  free(start);
  *order_storage = order;
  return views;
}

static int write_marks_and_legend(FILE *f, const sicm_plot *p, const area *a) {
  size_t *order = NULL;
  series_view *views = gather_series(p, &order);
  series_view **rows = calloc(p->n_series ? p->n_series : 1, sizeof *rows);
  if (!views || !rows) {
    free(views);
    free(order);
    free(rows);
    return -1;
  }
  size_t n_rows = 0;
  for (size_t s = 0; s < p->n_series; ++s)
    if (p->series[s].name && p->series[s].rank >= 0) rows[p->series[s].rank] = &views[s], ++n_rows;
  int status = 0;
  fputs("<g clip-path=\"url(#", f);
  write_clip_id(f, a);
  fputs(")\">\n", f);
  for (size_t k = 0; k <= n_rows && status == 0; ++k) {
    series_view *v = k == 0 ? (p->n_series ? &views[0] : NULL) : rows[k - 1];
    if (!v || v->n_marks == 0) continue;
    write_segments(f, p, a, v);
    write_polyline(f, p, a, v);
    status = write_dots(f, p, a, v);
  }
  fputs("</g>\n", f);
  write_legend(f, p, a, rows, n_rows);
  free(rows);
  free(views);
  free(order);
  return status;
}

int sicm_plot_write_svg(const sicm_plot *p) {
  char tmp[4096], final[4096];
  snprintf(tmp, sizeof tmp, "%s.svg.tmp", p->path);
  snprintf(final, sizeof final, "%s.svg", p->path);
  FILE *f = fopen(tmp, "w");
  if (!f) return -1;
  const area a = plot_area(p);
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
          "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"none\" "
          "stroke=\"black\"/>\n",
          a.left, a.top, a.width, a.height);
  fputs("<clipPath id=\"", f);
  write_clip_id(f, &a);
  fprintf(f, "\"><rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\"/></clipPath>\n", a.left,
          a.top, a.width, a.height);
  write_ticks(f, p, &a);
  write_labels(f, p, &a);
  int ok = write_marks_and_legend(f, p, &a) == 0;
  fputs("</svg>\n", f);
  if (ferror(f)) ok = 0;
  if (fclose(f) != 0) ok = 0;
  if (!ok || rename(tmp, final) != 0) {
    remove(tmp);
    return -1;
  }
  return 0;
}
