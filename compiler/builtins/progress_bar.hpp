// A progress bar on stderr for evolve's long integrations (sicm run's
// builtins/numerics.cpp).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <unistd.h>

namespace sicm {

// A progress bar on stderr for integrations that run longer than a second,
// drawn only when stderr is a terminal (never in pipes, logs or tests), at
// most ten times a second, and erased when the integration ends.
class ProgressBar {
public:
  ProgressBar(double t0, double t1) : t0_(t0), t1_(t1), start_(now()), last_(start_) {
    enabled_ = isatty(2) && t1 != t0;
  }
  ~ProgressBar() {
    if (drawn_) std::fprintf(stderr, "\r%*s\r", 60, "");
  }
  void update(double t) {
    if (!enabled_) return;
    double s = now();
    if (s - start_ < 1.0 || s - last_ < 0.1) return;
    last_ = s;
    double f = std::clamp((t - t0_) / (t1_ - t0_), 0.0, 1.0);
    int filled = static_cast<int>(f * 30);
    std::fprintf(stderr, "\revolve [%.*s%*s] %3d%% t = %.6g", filled,
                 "==============================", 30 - filled, "", static_cast<int>(f * 100), t);
    std::fflush(stderr);
    drawn_ = true;
  }

private:
  static double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
  }
  double t0_, t1_, start_, last_;
  bool enabled_ = false, drawn_ = false;
};

} // namespace sicm
