// Plot primitives (frame, plot-point, ...), where their files go, and the
// reading of their optional arguments, which sicm build (pe/plots.cpp)
// shares.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/value.hpp"

namespace sicm {

// The directory plot files are written to (default "."; `--plot-dir DIR`).
void set_plot_directory(const std::string &dir);
// The file name (without extension) of plot number `number` titled `title`:
// the title's letters, digits, '.', '_' and '-', or plot-NUMBER without one.
std::string plot_file_name(std::string_view title, int number);

// What frame takes after its bounds: [title [x-label [y-label]]] as
// strings, then options as pairs 'name value: 'aspect 'equal (or 'auto),
// 'marker-size PIXELS, 'legend 'best (or 'top-right, 'top-left,
// 'bottom-left, 'bottom-right, 'none). Errors are raised as MIT's argument errors.
struct FrameArguments {
  std::string title;
  std::vector<std::string> axis_labels; // x, then y
  bool equal_aspect = false;
  double marker_size = -1; // negative: by the number of points
  int legend = 0;          // a sicm_plot_legend
};
FrameArguments frame_arguments(Value *a, int n, const char *who);

// plot-series' options from a[from]: 'marker-size PIXELS, 'connect BOOLEAN.
struct SeriesStyle {
  double marker_size = -1;
  bool connect = false;
};
SeriesStyle series_style(Value *a, int from, int n, const char *who);

// A series argument: a string or a symbol names a series, #f (or "") is
// the unnamed one (nullopt); anything else is the wrong type.
std::optional<std::string> series_argument(Value *a, int i, const char *who);

} // namespace sicm
