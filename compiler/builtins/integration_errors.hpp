// The errors an integration raises about the system derivative it was
// given, written once: sicm run (builtins/numerics.cpp) and sicm build
// (pe/numerics.cpp) both raise them, with these words, at the user's call.
// In sicm build they are the program's own errors, not refusals to
// compile: met at the top level, they become the executable's failure
// there, as sicm run fails there.
#pragma once

#include <string>

#include "base/error.hpp"
#include "base/value.hpp"
#include "sicm/ode.h"

namespace sicm {

// The derivative returned a value not shaped like the state (a structure
// of real numbers of the state's shape); `state` as the integrator holds
// it (its leaves flonums).
[[noreturn]] void derivative_shape_error(SrcLoc loc, const char *who, Value derivative,
                                         Value state);

// Why a taylor method cannot take a system derivative.
enum class TaylorRefusal {
  NotOneExpression, // it tests the state, or keeps values between calls
  NoRecurrence,     // an operation has no Taylor recurrence (`operation` says which)
  KernelLimit,      // sicm run: --max-compiled-kernels was reached before it
};

// The tolerance eps asks of integrator T what its arithmetic cannot give: a
// relative error below about 1e-16 in double precision, 1e-20 in long
// double (taylor-extended). An error naming the limit and the method that
// can do better, rather than millions of steps and a worse answer. The
// symplectic methods, whose tolerance argument is their step, have none.
void check_reachable_tolerance(SrcLoc loc, const char *who, const sicm_ode_step_type *T,
                               double eps);

// evolve calls its monitor with one argument, the state: a compound
// procedure that cannot take one is an error that says it is the monitor,
// located at the monitor's own definition (the call's `call` when that is
// not the user's). `role` names what the procedure is ("the monitor",
// "the event procedure") in the message.
void check_monitor_arity(SrcLoc call, const char *who, Value monitor,
                         const char *role = "the monitor");

[[noreturn]] void taylor_refused(SrcLoc loc, const char *who, const char *method, TaylorRefusal why,
                                 const std::string &operation = {});

} // namespace sicm
