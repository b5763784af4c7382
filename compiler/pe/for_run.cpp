// sicm run's compiled procedures: a procedure of one real (bisect's
// function), a system derivative that tests the state, or the event of
// crossings (a real function of the state), compiled by sicm
// build's partial evaluator into a C function, as a built program compiles
// it, and loaded into the running process.
//
// Why: the function the book gives bisect in section 4.6.1 (which-way?)
// iterates a map thousands of times per call, in a loop whose exit depends
// on the argument; a system derivative with a piecewise force tests the
// state. The kernel tracer (codegen/trace.cpp) compiles only straight-line
// arithmetic, and the interpreter takes minutes where the built program
// takes seconds.
//
// How: build mode is switched on for the trace alone (begin_build_mode ...
// end_build_mode) with a residual program of its own; the procedure is
// traced into one function exactly as sicm build traces bisect's function
// (trace_scalar), a system derivative (trace_system_function) or an event
// (trace_event_function); the
// function is written as a C unit that needs no runtime
// (emit_residual_function) and loaded by the JIT.
//
// The trace runs the procedure once, at compile time, in the interpreter's
// own heap, so nothing it does may outlive it, and nothing the procedure
// does at each call may be done only once. While tracing for run, these are
// refused ("cannot compile") before they happen: set! of a variable made
// before the trace began, mutating a pair, vector or string or forcing a
// promise made before it (as sicm build refuses them: pe/branches.cpp),
// output, random numbers and the clock. After the trace,
// a function that does anything but arithmetic, tests and loops (calls a
// numerical primitive, plots, builds a list of run-time length) is refused.
// A refusal ends the attempt with the heap as it was, and the caller goes on
// interpreting: compiling is never required, and never changes what a
// program prints except in the last digits a different order of floating
// point operations can change (as between sicm run and sicm build).
#include <cstring>
#include <functional>
#include <string>

#include "base/limits.hpp"
#include "codegen/jit.hpp"
#include "codegen/residual_check.hpp"
#include "codegen/residual_emit.hpp"
#include "eval/core.hpp"
#include "eval/procedure.hpp"
#include "pe/build.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"

namespace sicm {

namespace build {
namespace {

const char kEntry[] = "sicm_run_entry";

[[noreturn]] void refuse(SrcLoc loc, const std::string &what) {
  cannot_compile(loc, what + " in a procedure compiled for sicm run");
}

Value for_run_set_global(Symbol *s, Value, SrcLoc loc) {
  refuse(loc, "set! of the global variable " + s->name);
}

Value for_run_set_local(Frame *f, uint32_t index, Value v, SrcLoc loc) {
  if (!made_since(f->serial, g_build->trace_serial))
    refuse(loc, "set! of a variable made before the call");
  return hook_set_local(f, index, v, loc);
}

void for_run_output(std::string_view) {
  refuse(here(), "output");
}

Value P_effect(Value *, int) {
  refuse(here(), "an effect (a mutation, output, random numbers or the clock)");
}

const DynamicBranchHooks kForRunHooks = {hook_dynamic_test,   hook_branch,       hook_logic,
                                         for_run_set_global,  for_run_set_local, hook_call_closure,
                                         hook_apply_to_other, hook_forcing};

// Build mode for one trace: on while it lives, off (the heap's primitives
// and hooks as they were) when it goes, however the trace ends.
class TraceForRun {
public:
  TraceForRun() {
    for (const char *name : effects_refused_for_run())
      rebind(name, 0, kVariadic, P_effect);
    g_dynamic_branch_hooks = &kForRunHooks;
    set_output_hook(for_run_output);
    g_build->trace_serial = g_frame_serial;
  }
  ResidualProgram &program() { return session_.program(); }

private:
  BuildSession session_; // first made, last gone
};

// Statements a loaded function may hold: arithmetic, tests and loops.
bool only_arithmetic(const std::vector<RStmt> &body) {
  for (const RStmt &s : body) {
    switch (s.kind) {
    case RKind::Let:
      switch (s.compute) {
      case RCompute::Expr:
      case RCompute::Less:
      case RCompute::LessEq:
      case RCompute::Equal:
      case RCompute::Select:
      case RCompute::Not:
      case RCompute::Floor:
      case RCompute::Round:
      case RCompute::Truncate:
      case RCompute::Max:
      case RCompute::Min: break;
      default: return false;
      }
      break;
    case RKind::If:
    case RKind::Loop:
    case RKind::Continue:
    case RKind::Break: break;
    default: return false;
    }
    if (!only_arithmetic(s.then_body) || !only_arithmetic(s.else_body)) return false;
  }
  return true;
}

// Does the C call anything named sicm_ that its own prelude does not define?
bool calls_runtime(const std::string &c) {
  static const char *const kOwn[] = {
      "sicm_site",         "sicm_escape", "sicm_interrupt", "sicm_checked_",
      "sicm_singular_nan", "sicm_ldlt_",  "sicm_lu_",       kEntry};
  for (size_t at = c.find("sicm_"); at != std::string::npos; at = c.find("sicm_", at + 1)) {
    bool own = false;
    for (const char *name : kOwn)
      own = own || c.compare(at, std::strlen(name), name) == 0;
    if (!own) return true;
  }
  return false;
}

} // namespace
} // namespace build

namespace {

// A system derivative's trace defines its kernel parameters in the caller
// (pe/numerics.cpp); here the caller is only the frame of the trace, and
// the values are numbers, so the definitions move to the start of the
// function, which then needs nothing from outside.
void inline_kernel_parameters(ResidualProgram &program, int id) {
  std::vector<RStmt> &outer = program.functions[0].body;
  for (const RStmt &s : outer)
    if (s.kind != RKind::Let || s.compute != RCompute::Expr) return;
  for (const RStmt &s : outer)
    program.vars[s.var].function = id;
  std::vector<RStmt> &body = program.functions[id].body;
  body.insert(body.begin(), outer.begin(), outer.end());
  outer.clear();
}

// What compile_for_run and compile_system_for_run share: `trace` traces the
// procedure into a function of a residual program of its own and returns
// its id; that function, if it is all arithmetic, tests and loops, is
// emitted and loaded.
CompiledFn compile_traced_for_run(Value proc, const std::function<int()> &trace,
                                  std::string *why_not) {
  using namespace build;
  if (in_build_mode()) {
    *why_not = "sicm build compiles it with the program";
    return nullptr;
  }
  if (current_limits().max_steps != kUnlimited) {
    *why_not = "--max-steps counts the interpreter's steps";
    return nullptr;
  }
  JitRequest request(user_call_loc()); // where --max-compiled-kernels would say so
  ResidualProgram program;
  int id = -1;
  {
    // The trace moves the evaluator's current call into the procedure.
    struct KeepCallLoc {
      SrcLoc call = current_call_loc();
      ~KeepCallLoc() { reset_call_loc(call); }
    } keep;
    try {
      TraceForRun build;
      id = trace();
      program = std::move(build.program());
      check_residual(program, "the partial evaluation for sicm run");
    } catch (const Error &e) {
      if (e.cause == ErrorCause::Interrupted) throw;
      *why_not = e.what();
      return nullptr;
    } catch (...) { // an escape from the procedure: it will escape when interpreted, too
      *why_not = "the procedure escapes";
      return nullptr;
    }
  }
  program.source_name = procedure_name(proc);
  if (program.functions.size() == 2) {
    inline_kernel_parameters(program, id);
    check_residual(program, "inline_kernel_parameters");
  }
  if (program.functions.size() != 2 || !program.functions[0].body.empty() ||
      !program.cells.empty() || !program.lists.empty() || program.plots != 0 ||
      !only_arithmetic(program.functions[id].body)) {
    *why_not = "it does more than arithmetic, tests and loops";
    return nullptr;
  }
  std::string c;
  try {
    c = emit_residual_function(program, id, kEntry);
  } catch (const Error &e) {
    *why_not = e.what();
    return nullptr;
  }
  if (calls_runtime(c)) {
    *why_not = "it needs the runtime";
    return nullptr;
  }
  return reinterpret_cast<CompiledFn>(jit_load(c, kEntry, nullptr, why_not));
}

} // namespace

CompiledFn compile_for_run(Value f, const char *who, std::string *why_not) {
  return compile_traced_for_run(
      f, [&] { return build::trace_scalar(f, who); }, why_not);
}

CompiledFn compile_system_for_run(Value sysder, Value state, const char *who,
                                  std::string *why_not) {
  return compile_traced_for_run(
      sysder, [&] { return build::trace_system_function(sysder, state, who); }, why_not);
}

CompiledFn compile_event_for_run(Value event, Value state, const char *who, std::string *why_not) {
  return compile_traced_for_run(
      event, [&] { return build::trace_event_function(event, state, who); }, why_not);
}

} // namespace sicm
