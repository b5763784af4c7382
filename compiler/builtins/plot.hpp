// Plot primitives (frame, plot-point, ...) and where their files go.
#pragma once

#include <string>
#include <string_view>

namespace sicm {

// The directory plot files are written to (default "."; `--plot-dir DIR`).
void set_plot_directory(const std::string &dir);
// The file name (without extension) of plot number `number` titled `title`:
// the title's letters, digits, '.', '_' and '-', or plot-NUMBER without one.
std::string plot_file_name(std::string_view title, int number);

} // namespace sicm
