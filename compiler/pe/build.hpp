// `sicm build`'s evaluator mode: the program runs at compile time and what
// depends on numerical results is recorded as a residual program (see
// codegen/residual.hpp and pe/build_mode.cpp).
#pragma once

#include <string>

#include "base/error.hpp"
#include "builtins/numerics.hpp"
#include "codegen/residual.hpp"

namespace sicm {

namespace build {
struct BuildState;
}

// A build in progress. While it lives, the primitives whose meaning changes
// are rebound and the evaluator's hooks installed, so that what runs records
// into its residual program; when it goes, the interpreter is sicm run's
// again. One at a time; construct after init_interpreter. Run-time values
// made during the build must not reach anything that outlives it (see
// compile_for_run in pe/for_run.cpp, which ensures it).
class BuildSession {
public:
  BuildSession();
  ~BuildSession();
  BuildSession(const BuildSession &) = delete;
  BuildSession &operator=(const BuildSession &) = delete;

  ResidualProgram &program();
  // The program fails at this point when it runs, with e's message as sicm
  // run prints it (e was raised at the top level: e.at_top_level): the
  // output before it is printed first, then the executable exits 70.
  void fail_here(const Error &e);
  // An error message for the compiler's own words (its warning): the
  // numbers known only at run time in it written <run-time number>.
  static std::string described(const std::string &message);

private:
  build::BuildState *state_; // in memory the collector scans (it holds Values)
};

// Is a build going on (a BuildSession alive)?
bool in_build_mode();

// sicm run: f (a procedure of one real returning a real) compiled by the
// partial evaluator and loaded, or null with the reason in *why_not when it
// cannot be (it has effects, calls numerical primitives, or no C compiler
// works). The interpreter's heap is as it was either way. who: the
// primitive that asks (for messages). See pe/for_run.cpp.
// Given to the numerical primitives at start-up (set_scalar_compiler).
CompiledFn compile_for_run(Value f, const char *who, std::string *why_not);

// sicm run: a system derivative that the kernel tracer cannot compile (it
// tests the state) compiled by the partial evaluator for states shaped like
// `state`, as sicm build compiles it: writes the derivative's leaves for the
// state's leaves. Null with the reason in *why_not when it cannot be, as
// compile_for_run. Given at start-up (set_system_compiler).
CompiledFn compile_system_for_run(Value sysder, Value state, const char *who, std::string *why_not);

// sicm run: the event procedure of crossings (a real function of states
// shaped like `state`) compiled by the partial evaluator, as sicm build
// compiles it (one output, the event's value). Null with the reason in
// *why_not when it cannot be. Given at start-up (set_event_compiler).
CompiledFn compile_event_for_run(Value event, Value state, const char *who, std::string *why_not);

} // namespace sicm
