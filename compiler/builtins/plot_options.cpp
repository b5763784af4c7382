// The optional arguments of the plot primitives: frame's title, axis labels
// and options, plot-series' options and the series argument of plot-point
// and plot-line, read alike by sicm run (builtins/plot.cpp) and sicm build
// (pe/plots.cpp), so that both accept and refuse the same calls.
#include <cmath>
#include <string>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/plot.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// An option's value is compiled into the program: sicm build refuses one
// known only at run time (bad_range then says "cannot compile").
void require_known(Value *a, int i, const char *who) {
  RunTimeValueTest test = run_time_value_test();
  if (test && test(a[i])) bad_range(a[i], i + 1, who);
}

bool is_option_name(Value v, const char *name) {
  return is_symbol(v) && symbol_name(v) == name;
}

double marker_size(Value *a, int i, const char *who) {
  require_known(a, i, who);
  if (!is_number(a[i]) || !is_real(a[i])) wrong_type(a[i], i + 1, who);
  double size = to_double(a[i]);
  if (!(size >= 0) || !std::isfinite(size) || size > 100)
    bad_range(a[i], i + 1, who, "a marker size is a real from 0 to 100, in pixels");
  return size;
}

struct LegendPlace {
  const char *name;
  sicm_plot_legend where;
};
const LegendPlace kLegendPlaces[] = {{"best", SICM_PLOT_LEGEND_BEST},
                                     {"top-right", SICM_PLOT_LEGEND_TOP_RIGHT},
                                     {"top-left", SICM_PLOT_LEGEND_TOP_LEFT},
                                     {"bottom-left", SICM_PLOT_LEGEND_BOTTOM_LEFT},
                                     {"bottom-right", SICM_PLOT_LEGEND_BOTTOM_RIGHT},
                                     {"none", SICM_PLOT_LEGEND_NONE}};

int legend_place(Value *a, int i, const char *who) {
  require_known(a, i, who);
  if (a[i].is_false()) return SICM_PLOT_LEGEND_NONE;
  if (is_symbol(a[i]))
    for (const LegendPlace &p : kLegendPlaces)
      if (symbol_name(a[i]) == p.name) return p.where;
  bad_range(a[i], i + 1, who,
            "a legend is at 'best, 'top-right, 'top-left, 'bottom-left or 'bottom-right, or "
            "'none");
}

// The option name at a[i], which must have a value after it.
const std::string &option_name(Value *a, int i, int n, const char *who, const char *options) {
  if (!is_symbol(a[i])) wrong_type(a[i], i + 1, who);
  const std::string &name = symbol_name(a[i]);
  if (i + 1 >= n)
    bad_range(a[i], i + 1, who, std::string("an option is followed by its value; ") + options);
  return name;
}

} // namespace

FrameArguments frame_arguments(Value *a, int n, const char *who) {
  static const char options[] = "the options of frame are 'aspect, 'legend and 'marker-size";
  FrameArguments f;
  int i = 4;
  if (i < n && is_string(a[i])) f.title = std::string(string_view(a[i++]));
  for (; i < n && i < 7 && is_string(a[i]); ++i)
    f.axis_labels.emplace_back(string_view(a[i]));
  for (; i < n; i += 2) {
    const std::string &name = option_name(a, i, n, who, options);
    if (name == "aspect") {
      require_known(a, i + 1, who);
      if (is_option_name(a[i + 1], "equal"))
        f.equal_aspect = true;
      else if (is_option_name(a[i + 1], "auto"))
        f.equal_aspect = false;
      else
        bad_range(a[i + 1], i + 2, who, "the aspect is 'equal or 'auto");
    } else if (name == "marker-size") {
      f.marker_size = marker_size(a, i + 1, who);
    } else if (name == "legend") {
      f.legend = legend_place(a, i + 1, who);
    } else {
      bad_range(a[i], i + 1, who, options);
    }
  }
  return f;
}

SeriesStyle series_style(Value *a, int from, int n, const char *who) {
  static const char options[] = "the options of plot-series are 'marker-size and 'connect";
  SeriesStyle style;
  for (int i = from; i < n; i += 2) {
    const std::string &name = option_name(a, i, n, who, options);
    if (name == "marker-size") {
      style.marker_size = marker_size(a, i + 1, who);
    } else if (name == "connect") {
      require_known(a, i + 1, who);
      if (!a[i + 1].is(Tag::Bool)) wrong_type(a[i + 1], i + 2, who);
      style.connect = a[i + 1].truthy();
    } else {
      bad_range(a[i], i + 1, who, options);
    }
  }
  return style;
}

std::optional<std::string> series_argument(Value *a, int i, const char *who) {
  require_known(a, i, who);
  if (a[i].is_false()) return std::nullopt;
  std::string name;
  if (is_string(a[i]))
    name = std::string(string_view(a[i]));
  else if (is_symbol(a[i]))
    name = symbol_name(a[i]);
  else
    wrong_type(a[i], i + 1, who);
  if (name.empty()) return std::nullopt;
  return name;
}

} // namespace sicm
