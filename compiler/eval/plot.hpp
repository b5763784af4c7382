// Plot primitives (frame, plot-point, ...) and where their files go.
#pragma once

#include <string>

namespace sicm {

void install_plot_primitives();
// The directory plot files are written to (default "."; `--plot-dir DIR`).
void set_plot_directory(const std::string &dir);

} // namespace sicm
