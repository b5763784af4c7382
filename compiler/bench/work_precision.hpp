// `sicm bench`: what accuracy costs in time, per integration site of a program.
//
// Each integration a program performs (integration_sites.hpp) is run again
// on its compiled system derivative with every method and tolerance asked
// for, from the same initial state over the same interval, in one call of
// the runtime's integrator (no monitor). For each run: the wall time of the
// integration alone (median of the repeats, at least 3 when a run takes
// under a second), the accepted and rejected steps and the rhs evaluations
// (sicm_ode_stats), and the error of the final state: the largest
// |x - x_ref| over its components, against a reference: the Taylor
// integrator in long double (taylor-extended) at kExtendedReferenceTolerance
// when the derivative has Taylor coefficients (its error estimated by its
// distance from itself at 10 times that tolerance, both rounded to double),
// else Bulirsch-Stoer at kReferenceTolerance, or rk8pd or cvode-bdf if it
// fails, as on a stiff system (its error estimated by its distance from the
// next of them). The estimate is printed. A run that fails (step size too small,
// too many steps, a stiff system) is a row with error inf and the state where it stopped.
//
// Writes DIR/work-precision.tsv (header, then one row per run: site method
// tolerance seconds steps rhs_evals error final), DIR/work-precision.svg
// (log10 error against log10 seconds, one curve per method, one panel per
// site) and prints, per site, how the reference was made and, for each
// accuracy decade reached, the cheapest method and its time.
#pragma once

#include <string>
#include <vector>

namespace sicm {

// Tighter than every adaptive method's useful range in double precision;
// the reference's own error is measured, not assumed.
constexpr double kReferenceTolerance = 1e-15;

// Well under the rounding of double (1.1e-16), within long double's (5.4e-20).
constexpr double kExtendedReferenceTolerance = 1e-19;

struct BenchOptions {
  std::string out_dir;                                // default: FILE-bench
  std::vector<std::string> methods;                   // default: every adaptive method
  double tolerance_from = 1e-3, tolerance_to = 1e-14; // by decades
  int repeats = 3;
};

// Run the benchmark over the sites recorded while the program ran; returns
// the process exit status (0, or 1 when the output cannot be written, with a
// message on stderr).
int run_work_precision(const BenchOptions &options);

} // namespace sicm
