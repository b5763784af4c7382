/* Lists whose length is known only at run time: growable arrays of
 * fixed-width elements (see sicm/program.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sicm/runtime.h"

void sicm_list_reset(sicm_list *list, size_t width) {
  if (list->width != width) {
    free(list->data);
    list->data = NULL;
    list->cap = 0;
  }
  list->len = 0;
  list->width = width;
}

void sicm_list_push(const sicm_site *site, sicm_list *list, const double *element) {
  if (list->len == list->cap) {
    size_t cap = list->cap ? 2 * list->cap : 64;
    size_t width = list->width ? list->width : 1;
    double *data = realloc(list->data, cap * width * sizeof *data);
    if (!data || cap > ((size_t)-1) / (width * sizeof *data))
      sicm_program_fail(site, "cons", "out of memory");
    list->data = data;
    list->cap = cap;
  }
  if (list->width)
    memcpy(list->data + list->len * list->width, element, list->width * sizeof *element);
  ++list->len;
}

void sicm_list_assign(const sicm_site *site, sicm_list *list, size_t width, const double *data,
                      size_t len) {
  sicm_list_reset(list, width);
  for (size_t i = 0; i < len; ++i)
    sicm_list_push(site, list, data + i * width);
}

double sicm_list_length(const sicm_list *list) {
  return (double)list->len;
}

double sicm_list_ref(const sicm_site *site, const char *who, const sicm_list *list, double index,
                     double lo, double hi, size_t leaf) {
  if (!(index >= lo && index < hi && index >= 0 && index < (double)list->len)) {
    if (!(lo < hi)) sicm_program_fail(site, who, "the list is empty");
    sicm_program_fail(site, who, "the index is past the end of the list");
  }
  return list->data[(size_t)index * list->width + leaf];
}

/* The elements at [lo, hi), in the order the list holds them: backward
 * (from hi - 1 down) for a list built by consing, forward once reversed. */
double sicm_list_fold(const sicm_site *site, const sicm_list *list, sicm_list_fold_op op, double lo,
                      double hi, int backward) {
  static const char *const names[] = {"min", "max", "+", "*"};
  if (hi > (double)list->len || lo < 0)
    sicm_program_fail(site, names[op], "the list is shorter than expected");
  if (!(lo < hi)) {
    if (op == SICM_LIST_SUM) return 0.0;
    if (op == SICM_LIST_PRODUCT) return 1.0;
    sicm_program_fail(site, names[op], "it needs at least one number; the list is empty");
  }
  size_t n = (size_t)(hi - lo), first = (size_t)lo;
  double acc = 0;
  for (size_t k = 0; k < n; ++k) {
    size_t i = backward ? first + n - 1 - k : first + k;
    double x = list->data[i * list->width];
    if (k == 0)
      acc = x;
    else if (op == SICM_LIST_SUM)
      acc += x;
    else if (op == SICM_LIST_PRODUCT)
      acc *= x;
    else if (isnan(acc) || isnan(x))
      acc = NAN;
    else
      acc = op == SICM_LIST_MIN ? fmin(acc, x) : fmax(acc, x);
  }
  return acc;
}
