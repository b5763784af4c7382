// Procedures written in C++: how they are declared, registered and how they
// report misuse in MIT Scheme's words.
#pragma once

#include <string>
#include <vector>

#include "base/value.hpp"

namespace sicm {

// A primitive receives its evaluated arguments in a contiguous array.
using PrimFn = Value (*)(Value *args, int nargs);

// When a primitive's work happens, declared where it is defined (the
// argument of define_primitive has no default, so a new primitive cannot
// silently be computed while compiling): sicm build computes a Pure one
// while compiling whenever its arguments are known; an Effect (output,
// clocks, randomness, mutation, plots, errors) and RunTime work (the
// numerical primitives, parameters, parallel maps) the build must handle
// itself, which tests/unit/primitive_stage_test.cpp checks against the
// build's tables (pe/specialized.hpp).
enum class Stage { Pure, Effect, RunTime };

struct Primitive {
  const char *name;
  int min_args;
  int max_args; // -1: any number
  PrimFn fn;
  Stage stage;
};

constexpr int kVariadic = -1;

// Bind `name` in the global environment to a new primitive.
void define_primitive(const char *name, int min_args, int max_args, Stage stage, PrimFn fn);

// Every primitive defined so far, in order (rebinding adds another).
std::vector<const Primitive *> defined_primitives();
// Bind `name` to an existing value (constants such as pi, aliases).
void define_global(const char *name, Value v);

// sicm build says which values are known only at run time (no test in sicm
// run): an argument error on one of them is the compiler's "cannot compile"
// error (the value may well be right at run time), and algebra/
// linear_solve.cpp solves with them as the interpreter would.
using RunTimeValueTest = bool (*)(Value);
void set_run_time_value_test(RunTimeValueTest test);
RunTimeValueTest run_time_value_test(); // null outside sicm build
// Does v hold such a value, itself or in a structure, vector or list
// (looked into to a bounded depth and size)? An error message about it
// would show the build's names for them, not the numbers sicm run shows.
bool holds_run_time_value(Value v, int depth = 4);
// sicm build: how to write, in an error message, a structure, vector or
// list that holds run-time numbers, when the error is certain (the object's
// own kind is wrong, whatever its numbers) and raised at the program's top
// level: the text names the numbers by markers that the build turns into
// printing when the executable fails there (pe/build_mode.cpp), so the
// executable prints what sicm run prints. Null: such an error is the
// compiler's "cannot compile".
using RunTimeWriter = std::string (*)(Value);
void set_run_time_writer(RunTimeWriter writer);

// MIT-style argument errors, raised at current_call_loc(). argpos is 1-based.
//   "The object (), passed as the first argument to car, is not the correct type."
[[noreturn]] void wrong_type(Value obj, int argpos, const char *who);
//   "The object 10, passed as the second argument to vector-ref, is not in the correct range."
[[noreturn]] void bad_range(Value obj, int argpos, const char *who);
//   the same with the rule the object breaks: "..., is not in the correct
//   range (a tolerance is a positive real)."
[[noreturn]] void bad_range(Value obj, int argpos, const char *who, const std::string &rule);

// Argument checkers that return the unwrapped value or raise wrong_type.
int64_t arg_fixnum(Value *args, int i, const char *who); // exact integer in int64 range
size_t arg_index(Value *args, int i, const char *who);   // exact non-negative integer
// An index in [lo, hi]: not a fixnum is a wrong type, outside the bounds a bad range.
size_t arg_bounded(Value *args, int i, size_t lo, size_t hi, const char *who);
std::string_view arg_string(Value *args, int i, const char *who);
Symbol *arg_symbol(Value *args, int i, const char *who);

} // namespace sicm
