// The numerical primitives' defaults and integrator names, shared by the
// interpreter's primitives (builtins/numerics.cpp) and by `sicm build`
// (pe/build_mode.cpp), so a built program means what `sicm run` means.
#pragma once

#include <string>

#include "sicm/ode.h"

namespace sicm {

// scmutils' values.
constexpr double kIntegralTolerance = 1e-11; // *definite-integral-allowable-error*
constexpr double kMinimizeTolerance = 1e-5;  // brent-error
constexpr double kAdvancerTolerance = 1e-12; // *default-advancer-tolerance*
constexpr double kNelderStep = 0.01;         // nelder-start-step
constexpr double kNelderTolerance = 1e-10;   // simplex size (see P_nelder_mead)
constexpr int kNelderMaxIter = 1000;         // nelder-maxiter
constexpr int kBisectBreak = 60;             // *bisect-break*
constexpr long kBisectMaxIter = 10000;

// The runtime's step type variable (sicm/ode.h) for an integrator's name
// ('bulirsch-stoer, 'rk8pd, ...), or null for a name that is none.
const char *integrator_c_name(const std::string &name);

// The runtime's step type for an integrator's name, or null.
const sicm_ode_step_type *integrator_named(const std::string &name);
// The runtime's step type whose variable is c_name (integrator_c_name's
// answer), or null.
const sicm_ode_step_type *integrator_of_c_name(const std::string &c_name);

// The fixed-step symplectic methods (verlet, yoshida4/6/8), whose tolerance
// argument is their step size.
bool integrator_is_fixed_step(const sicm_ode_step_type *T);

// The integrators' names, for messages ("bulirsch-stoer, rk8pd, ...").
const char *integrator_list();

// For an integrator of scmutils that sicm does not provide ('implicit-gear),
// a message saying so and what to use instead; "" for any other name.
std::string integrator_not_provided(const std::string &name);

} // namespace sicm
