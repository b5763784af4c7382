// `sicm build`'s plots: frame, plot-point, plot-line, plot-series and graphics-close
// record statements of the residual program, so that the built program
// draws what `sicm run` draws; a graphics device is the number of its plot.
// Part of build mode (the design is in pe/build_mode.cpp; the shared
// declarations in pe/state.hpp).
#include <string>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/plot.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"

namespace sicm::build {

namespace {

struct BuildPlot {
  int id;
  char *name; // GC memory
};

void write_plot(std::string &out, const void *obj, bool) {
  out += "#[graphics-device ";
  out += static_cast<const BuildPlot *>(obj)->name;
  out += "]";
}

const OpaqueKind kBuildPlotKind = {"graphics-device", write_plot, nullptr};

BuildPlot *arg_plot(Value *a, int i, const char *who) {
  if (!a[i].is(Tag::Opaque) || a[i].as<Opaque>()->kind != &kBuildPlotKind)
    wrong_type(a[i], i + 1, who);
  return static_cast<BuildPlot *>(a[i].as<Opaque>()->obj);
}

Value P_frame(Value *a, int n) {
  static const char who[] = "frame";
  RStmt s{RKind::Frame};
  s.loc = here();
  double r[4];
  for (int i = 0; i < 4; ++i) {
    if (is_dynamic_scalar(a[i]))
      cannot_compile(here(), "a frame's bounds must be known at compile time");
    if (!is_number(a[i])) wrong_type(a[i], i + 1, who);
    r[i] = to_double(a[i]);
    s.args.push_back(expr_flonum(r[i]));
  }
  if (!(r[1] > r[0])) bad_range(a[1], 2, who);
  if (!(r[3] > r[2])) bad_range(a[3], 4, who);
  FrameArguments f = frame_arguments(a, n, who);
  s.plot = ++g_build->program.plots;
  s.title = f.title;
  s.text = plot_file_name(s.title, s.plot);
  s.axis_labels = f.axis_labels;
  s.plot_options.equal_aspect = f.equal_aspect;
  s.plot_options.marker_size = f.marker_size;
  s.plot_options.legend = f.legend;
  BuildPlot *p = gc_new<BuildPlot>(BuildPlot{s.plot, gc_strdup(s.text)});
  emit(std::move(s));
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kBuildPlotKind, p}));
}

Value P_plot_point(Value *a, int n) {
  RStmt s{RKind::PlotPoint};
  s.plot = arg_plot(a, 0, "plot-point")->id;
  s.args = {expr_of(a[1], "plot-point"), expr_of(a[2], "plot-point")};
  if (n > 3) s.series = series_argument(a, 3, "plot-point");
  emit(std::move(s));
  return Value::unspecified();
}

Value P_plot_line(Value *a, int n) {
  RStmt s{RKind::PlotLine};
  s.plot = arg_plot(a, 0, "plot-line")->id;
  for (int i = 1; i <= 4; ++i)
    s.args.push_back(expr_of(a[i], "plot-line"));
  if (n > 5) s.series = series_argument(a, 5, "plot-line");
  emit(std::move(s));
  return Value::unspecified();
}

Value P_plot_series(Value *a, int n) {
  RStmt s{RKind::PlotStyle};
  s.loc = here();
  s.plot = arg_plot(a, 0, "plot-series")->id;
  s.series = series_argument(a, 1, "plot-series");
  SeriesStyle style = series_style(a, 2, n, "plot-series");
  s.plot_options.marker_size = style.marker_size;
  s.plot_options.connect = style.connect;
  emit(std::move(s));
  return Value::unspecified();
}

Value P_graphics_close(Value *a, int) {
  RStmt s{RKind::Close};
  s.plot = arg_plot(a, 0, "graphics-close")->id;
  emit(std::move(s));
  return Value::unspecified();
}

Value P_graphics_clear(Value *a, int) {
  RStmt s{RKind::Clear};
  s.loc = here();
  s.plot = arg_plot(a, 0, "graphics-clear")->id;
  emit(std::move(s));
  return Value::unspecified();
}

} // namespace

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn p_frame = P_frame, p_plot_point = P_plot_point, p_plot_line = P_plot_line,
             p_plot_series = P_plot_series, p_graphics_close = P_graphics_close,
             p_graphics_clear = P_graphics_clear;

} // namespace sicm::build
