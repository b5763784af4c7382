// The integrations a program performs, recorded for `sicm bench` (one per call site).
//
// While `sicm bench` runs a program, evolve and state-advancer record the
// first integration each call site performs: the compiled system
// derivative, the initial state, the interval and the tolerance and method
// the program asked for. work_precision.hpp then integrates each again with
// every method and tolerance. A site whose derivative was not compiled (it
// could not be traced) is recorded without a kernel and reported as such;
// while sites are recorded, derivatives are compiled with their Taylor
// coefficients too, so that 'taylor can be benchmarked.
#pragma once

#include <string>
#include <vector>

#include "codegen/kernel.hpp"

namespace sicm {

struct IntegrationSite {
  std::string where; // file:line:col of the call
  std::string who;   // evolve, state-advancer
  KernelFn kernel;   // the system derivative (loaded code is never unloaded), or null
  TaylorFn taylor;   // its Taylor coefficients (for 'taylor), or null
  TaylorExtendedFn taylor_extended; // the same in long double (for 'taylor-extended)
  std::vector<double> params;       // the p[] of the three functions (kernel.hpp)
  std::vector<double> y;            // the initial state's leaves
  bool time_first;                  // y[0] is the time
  double t0, t1;                    // the interval, in the integrator's time
  double tolerance;
  std::string method; // what the program used
};

// Recording is off unless sicm bench turns it on.
void record_integration_sites(bool on);
bool recording_integration_sites();

// The first integration of each site is kept; later ones are ignored.
void record_integration_site(IntegrationSite site);

const std::vector<IntegrationSite> &recorded_integration_sites();

} // namespace sicm
