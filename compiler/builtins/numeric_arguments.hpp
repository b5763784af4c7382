// What each numerical primitive accepts, written once: the arity of its
// call and the rule of each argument (a tolerance is a positive real, an
// integrator one of the named ones, ...), checked by one function that
// sicm run's primitives (builtins/numerics.cpp) and sicm build's
// (pe/numerics.cpp) both call first, at the user's call, so that the same
// mistake gets the same message in both modes.
//
// In sicm build an argument may be a value known only at run time
// (run_time_value_test, base/primitive.hpp). The rules a compiled program
// needs at compile time (a tolerance, an integrator) then refuse to
// compile; the others are the runtime's to check when the value is known.
#pragma once

#include <string_view>
#include <vector>

#include "base/value.hpp"

namespace sicm {

struct NativeProc;

enum class ArgRule {
  Any,         // the primitive looks at it itself (a state, a flag)
  Procedure,   // a procedure, or a structure of procedures
  Finite,      // a finite real
  IntervalEnd, // a finite real other than the argument before it
  Limit,       // a real that is not NaN, or :+infinity or :-infinity
  Tolerance,   // a positive finite real (also a step size)
  NonNegative, // a finite real >= 0
  Index,       // an exact integer >= 0
  Count,       // an exact integer from 1 to 100000000
  Point,       // a non-empty list or vector of finite reals
  Integrator,  // a symbol naming an integrator (the message lists them)
  Direction,   // the symbol up, down or both (a crossing's direction)
};

struct NumericSignature {
  const char *who; // the primitive's name, in messages
  int min_args, max_args;
  std::vector<ArgRule> rules; // one per argument, optional ones last
};

// The signature of `who` ("evolve" is the call of the procedure evolve
// returns: (state monitor dt t-final [tolerance [integrator]])). Every
// numerical primitive has one; asking for another name is a bug.
const NumericSignature &numeric_signature(std::string_view who);

// Every signature, for the unit test that each numerical primitive has one.
const std::vector<NumericSignature> &numeric_signatures();

// Raise the first error among a[0 .. n): the arity, then each argument
// that is present (not missing, not #!default) by its rule. `self` is the
// procedure called when it is not a primitive (the procedure evolve
// returns), for the arity message; primitives' arity is checked when they
// are applied. Errors are raised at current_call_loc(), the user's call.
void check_numeric_arguments(const NumericSignature &sig, Value *a, int n,
                             NativeProc *self = nullptr);
// The same with numeric_signature(who).
void check_numeric_arguments(const char *who, Value *a, int n, NativeProc *self = nullptr);

} // namespace sicm
