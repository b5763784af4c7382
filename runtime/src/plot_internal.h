/* Private to the runtime: the plot record that plot.c (files, marks,
 * series, signals) fills and plot_svg.c (the picture) reads, and nothing
 * else uses. */
#ifndef SICM_PLOT_INTERNAL_H
#define SICM_PLOT_INTERNAL_H

#include <stddef.h>
#include <stdio.h>

#include "sicm/runtime.h"

/* One point (x1 is NAN) or segment, and the index of its series. */
typedef struct {
  double x0, y0, x1, y1;
  size_t series;
} sicm_plot_mark;

typedef struct {
  char *name;         /* NULL for the unnamed series (always index 0) */
  long rank;          /* named series: its place among them by first mark; -1 before */
  double marker_size; /* pixels; negative: the plot's default */
  int connect;        /* its points joined by a polyline */
  size_t points;      /* its points so far */
} sicm_plot_series_info;

struct sicm_plot {
  char *path;              /* NAME without extension, in its directory */
  char *title;             /* shown above the picture */
  char *x_label, *y_label; /* under the x axis, beside the y axis; NULL for none */
  double xmin, xmax, ymin, ymax;
  FILE *tsv;
  sicm_plot_mark *marks;
  size_t n, cap;
  sicm_plot_series_info *series;
  size_t n_series, series_cap;
  size_t last_series; /* where the last lookup by name found its series */
  long ranked;        /* named series that have a mark */
  size_t points;      /* points of every series */
  double marker_size; /* default dot size; negative: by the number of points */
  int equal_aspect;
  sicm_plot_legend legend;
  size_t unflushed;
  int closed;
  int silent; /* sicm_plot_open_silent: no files, no marks kept */
};

/* Write p's picture to PATH.svg (through PATH.svg.tmp). 0, or -1. */
int sicm_plot_write_svg(const sicm_plot *p);

#endif /* SICM_PLOT_INTERNAL_H */
