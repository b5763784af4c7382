// Plot primitives of the interpreter: frame, plot-point, plot-line, ...,
// over the runtime's plot files (runtime/src/plot.c).
#include <cerrno>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "builtins/plot.hpp"
#include "eval/core.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

std::string g_plot_dir = ".";
int g_plot_count = 0;

struct PlotWindow {
  sicm_plot *plot;
  char *name; // GC memory
};

void write_window(std::string &out, const void *obj, bool) {
  out += "#[graphics-device ";
  out += static_cast<const PlotWindow *>(obj)->name;
  out += "]";
}

const OpaqueKind kPlotKind = {"graphics-device", write_window, nullptr};

PlotWindow *arg_window(Value *a, int i, const char *who) {
  if (!a[i].is(Tag::Opaque) || a[i].as<Opaque>()->kind != &kPlotKind) wrong_type(a[i], i + 1, who);
  return static_cast<PlotWindow *>(a[i].as<Opaque>()->obj);
}

double arg_real(Value *a, int i, const char *who) {
  if (!is_number(a[i])) wrong_type(a[i], i + 1, who);
  return to_double(a[i]);
}

// (frame xmin xmax ymin ymax [title [x-label y-label]] option value ...)
Value P_frame(Value *a, int n) {
  double r[4];
  for (int i = 0; i < 4; ++i)
    r[i] = arg_real(a, i, "frame");
  if (!(r[1] > r[0])) bad_range(a[1], 2, "frame");
  if (!(r[3] > r[2])) bad_range(a[3], 4, "frame");
  FrameArguments f = frame_arguments(a, n, "frame");
  ++g_plot_count;
  std::string name = plot_file_name(f.title, g_plot_count);
  sicm_plot *p =
      sicm_plot_open(g_plot_dir.c_str(), name.c_str(), f.title.empty() ? nullptr : f.title.c_str(),
                     r[0], r[1], r[2], r[3]);
  if (!p)
    runtime_error(current_call_loc(), "frame: cannot create the plot file " + g_plot_dir + "/" +
                                          name + ".tsv: " + std::strerror(errno));
  if (!f.axis_labels.empty() &&
      sicm_plot_set_labels(p, f.axis_labels[0].c_str(),
                           f.axis_labels.size() > 1 ? f.axis_labels[1].c_str() : nullptr) != 0)
    runtime_error(current_call_loc(), "frame: out of memory");
  sicm_plot_set_equal_aspect(p, f.equal_aspect);
  sicm_plot_set_marker_size(p, f.marker_size);
  sicm_plot_set_legend(p, static_cast<sicm_plot_legend>(f.legend));
  PlotWindow *w = gc_new<PlotWindow>(PlotWindow{p, gc_strdup(name)});
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kPlotKind, w}));
}

// (plot-point window x y [series])
Value P_plot_point(Value *a, int n) {
  PlotWindow *w = arg_window(a, 0, "plot-point");
  double x = arg_real(a, 1, "plot-point"), y = arg_real(a, 2, "plot-point");
  std::optional<std::string> series = n > 3 ? series_argument(a, 3, "plot-point") : std::nullopt;
  if (sicm_plot_series_point(w->plot, series ? series->c_str() : nullptr, x, y) != 0)
    runtime_error(current_call_loc(), "plot-point: the plot is closed or memory is exhausted");
  return Value::unspecified();
}

// (plot-line window x0 y0 x1 y1 [series])
Value P_plot_line(Value *a, int n) {
  PlotWindow *w = arg_window(a, 0, "plot-line");
  double c[4];
  for (int i = 0; i < 4; ++i)
    c[i] = arg_real(a, i + 1, "plot-line");
  std::optional<std::string> series = n > 5 ? series_argument(a, 5, "plot-line") : std::nullopt;
  if (sicm_plot_series_line(w->plot, series ? series->c_str() : nullptr, c[0], c[1], c[2], c[3]) !=
      0)
    runtime_error(current_call_loc(), "plot-line: the plot is closed or memory is exhausted");
  return Value::unspecified();
}

// (plot-series window series option value ...)
Value P_plot_series(Value *a, int n) {
  PlotWindow *w = arg_window(a, 0, "plot-series");
  std::optional<std::string> series = series_argument(a, 1, "plot-series");
  SeriesStyle style = series_style(a, 2, n, "plot-series");
  if (sicm_plot_style_series(w->plot, series ? series->c_str() : nullptr, style.marker_size,
                             style.connect) != 0)
    runtime_error(current_call_loc(), "plot-series: out of memory");
  return Value::unspecified();
}

Value P_graphics_close(Value *a, int) {
  sicm_plot_finish(arg_window(a, 0, "graphics-close")->plot);
  return Value::unspecified();
}

Value P_graphics_clear(Value *a, int) {
  PlotWindow *w = arg_window(a, 0, "graphics-clear");
  if (sicm_plot_clear(w->plot) != 0)
    runtime_error(current_call_loc(), "graphics-clear: the plot is closed or memory is exhausted");
  return Value::unspecified();
}

} // namespace

std::string plot_file_name(std::string_view title, int number) {
  std::string name;
  for (char c : title) {
    bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '.' || c == '_' || c == '-';
    name += keep ? c : '-';
  }
  while (!name.empty() && (name[0] == '.' || name[0] == '-'))
    name.erase(0, 1);
  if (name.size() > 100) name.resize(100);
  return name.empty() ? "plot-" + std::to_string(number) : name;
}

void set_plot_directory(const std::string &dir) {
  g_plot_dir = dir;
}

void install_plot_primitives() {
  define_primitive("frame", 4, kVariadic, Stage::Effect, P_frame);
  define_primitive("plot-point", 3, 4, Stage::Effect, P_plot_point);
  define_primitive("plot-line", 5, 6, Stage::Effect, P_plot_line);
  define_primitive("plot-series", 2, kVariadic, Stage::Effect, P_plot_series);
  define_primitive("graphics-close", 1, 1, Stage::Effect, P_graphics_close);
  define_primitive("graphics-clear", 1, 1, Stage::Effect, P_graphics_clear);
}

} // namespace sicm
