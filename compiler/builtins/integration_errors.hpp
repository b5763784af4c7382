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

[[noreturn]] void taylor_refused(SrcLoc loc, const char *who, const char *method, TaylorRefusal why,
                                 const std::string &operation = {});

} // namespace sicm
