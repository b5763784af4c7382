// The errors of an integration about its system derivative (see
// integration_errors.hpp).
#include "builtins/integration_errors.hpp"

#include "builtins/numerics_defaults.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"
#include "sicm/runtime.h"

namespace sicm {

void derivative_shape_error(SrcLoc loc, const char *who, Value derivative, Value state) {
  runtime_error(loc, std::string(who) + ": the system derivative returned " +
                         write_string(derivative) + " for the state " + write_string(state) +
                         "; it must be a structure of real numbers of the state's shape");
}

void check_reachable_tolerance(SrcLoc loc, const char *who, const sicm_ode_step_type *T,
                               double eps) {
  if (!T || integrator_is_fixed_step(T)) return;
  // Each step rounds the state to the working precision: unit roundoff
  // 1.1e-16 in double, 5.4e-20 in long double. A relative error below about
  // that is out of reach, whatever the step size (tests/numerics/
  // evolve-taylor.sicm shows taylor-extended at 1e-20 still converging).
  const bool extended = T == sicm_ode_step_taylor_extended;
  const double reachable = extended ? 1e-20 : 1e-16;
  if (eps >= reachable) return;
  std::string method = sicm_ode_step_type_name(T);
  char tolerance[SICM_DOUBLE_BUFSIZE];
  sicm_format_tolerance(tolerance, eps);
  std::string what = std::string(who) + ": a tolerance of " + tolerance + " is below what " +
                     method + " can reach: " +
                     (extended ? "about 1e-20 relative in long double"
                               : "about 1e-16 relative in double precision") +
                     "; ";
  if (extended)
    what += "ask for 1e-20 or more";
  else
    what += "ask for 1e-16 or more, or use 'taylor-extended, which computes in long double "
            "(down to about 1e-20)";
  runtime_error(loc, what);
}

void check_monitor_arity(SrcLoc call, const char *who, Value monitor, const char *role) {
  if (!monitor.is(Tag::Closure)) return;
  const Lambda *lambda = monitor.as<Closure>()->lambda;
  const uint32_t required = lambda->nrequired, most = required + lambda->noptional;
  if (required <= 1 && (lambda->rest || most >= 1)) return;
  std::string takes = lambda->rest ? "at least " + std::to_string(required)
                      : required == most
                          ? "exactly " + std::to_string(required)
                          : "between " + std::to_string(required) + " and " + std::to_string(most);
  const bool one = !lambda->rest && most == 1 && required == 1;
  SrcLoc at = lambda->loc.known() && !is_library_loc(lambda->loc) ? lambda->loc : call;
  // An event's procedures are called by the evolve they are given to.
  const std::string called =
      std::string(role) == "the monitor" ? std::string(who) + " calls it" : "it is called";
  runtime_error(at, std::string(who) + ": " + role + " " + write_string(monitor) + " takes " +
                        takes + (one ? " argument" : " arguments") + "; " + called +
                        " with one argument, the state");
}

void taylor_refused(SrcLoc loc, const char *who, const char *method, TaylorRefusal why,
                    const std::string &operation) {
  std::string what;
  switch (why) {
  case TaylorRefusal::NotOneExpression:
    what = " needs a system derivative that is one expression of the state; this one tests the "
           "state or keeps values between calls";
    break;
  case TaylorRefusal::NoRecurrence:
    what = " needs a system derivative whose operations all have Taylor recurrences; this one "
           "has " +
           operation;
    break;
  case TaylorRefusal::KernelLimit:
    what = " needs a compiled system derivative; this one was not compiled "
           "(--max-compiled-kernels was reached)";
    break;
  }
  runtime_error(loc, std::string(who) + ": " + method + what + "; choose another integrator");
}

} // namespace sicm
