// Which procedures given to sicm run's numerical primitives run compiled
// (see compiled_procedures.hpp).
#include "builtins/compiled_procedures.hpp"

#include <cstdint>
#include <string>

#include "base/error.hpp"
#include "base/primitive.hpp"
#include "codegen/kernel_interpreter.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {

// Recent (procedure, shape) -> compiled pairs are remembered, because a
// state advancer inside a map is called over and over with the same
// procedure.
struct CompiledSysder {
  Value sysder;
  Value state_shape;    // a sample state
  const Kernel *kernel; // null: not traceable
  bool taylor;          // compiled with its Taylor coefficients (if it has them)
  // When there is no kernel: the derivative compiled by the partial
  // evaluator (it tests the state), once tried; null if it cannot be.
  bool residual_tried = false;
  CompiledFn residual = nullptr;
};
gcvec<CompiledSysder> g_compiled; // static, hence a root for the collector
constexpr size_t kCompiledMemo = 32;
// There is no count here: a new system made from the same procedures with
// other numbers is the same C (its numbers are the kernel's parameters,
// codegen/kernel.hpp), which the JIT has loaded already; only procedures
// that differ in structure load another shared object, and the JIT bounds
// those (--max-compiled-kernels, base/limits.hpp).

// Recent event procedures of crossings, with their interpreted calls.
struct CompiledEvent {
  Value event;
  Value state_shape; // a sample state
  uint64_t interpreted = 0;
  bool tried = false;
  CompiledFn compiled = nullptr;
};
gcvec<CompiledEvent> g_events; // static, hence a root for the collector
// An interpreted event costs some hundreds of nanoseconds, its compiled
// function a few; the C compiler, once, a tenth of a second or less (the
// JIT keeps what it has compiled). A section of one long orbit evaluates
// the event about ten times a step, a million times over 10^4 time units.
constexpr uint64_t kCompileEventAfter = 20000;

ScalarCompiler g_scalar_compiler = nullptr;
SystemCompiler g_system_compiler = nullptr;
SystemCompiler g_event_compiler = nullptr;

// Under SICM_INTERPRET=1 there is no C compiler: kernels are still made,
// and run by the kernel interpreter (compile_kernel), but what only the
// partial evaluator's C can compile stays with the generic evaluator.
bool c_compiler_enabled() {
  return !kernels_interpreted();
}

} // namespace

const Kernel *auto_kernel(Value sysder, Value state, size_t dim, bool taylor) {
  if (!is_procedure(sysder)) return nullptr;
  for (const CompiledSysder &c : g_compiled)
    if (eq(c.sysder, sysder) && value_has_shape(state, c.state_shape) && (c.taylor || !taylor))
      return c.kernel;
  std::string why;
  KernelOptions options{.probe_singularities = true, .taylor = taylor};
  const Kernel *k = compile_kernel(sysder, list({state}), "system_derivative", &why, options);
  if (k && (k->nin != dim || k->nout != dim)) k = nullptr;
  if (g_compiled.size() >= kCompiledMemo) g_compiled.erase(g_compiled.begin());
  g_compiled.push_back(CompiledSysder{sysder, state, k, taylor});
  return k;
}

CompiledFn auto_residual(Value sysder, Value state, const char *who) {
  if (!c_compiler_enabled() || !g_system_compiler) return nullptr;
  CompiledSysder *entry = nullptr;
  for (CompiledSysder &c : g_compiled)
    if (eq(c.sysder, sysder) && value_has_shape(state, c.state_shape) && !c.kernel) entry = &c;
  if (!entry || entry->residual_tried) return entry ? entry->residual : nullptr;
  entry->residual_tried = true;
  std::string why;
  entry->residual = g_system_compiler(sysder, state, who, &why);
  return entry->residual;
}

const Kernel *jacobian_kernel(Value sysder, Value state, size_t dim) {
  Symbol *d = intern("D").symbol();
  if (!d->bound) return nullptr;
  try {
    Value dsys = apply_procedure(d->global, &sysder, 1);
    std::string why;
    const Kernel *k = compile_kernel(dsys, list({state}), "jacobian", &why);
    return k && k->nin == dim && k->nout == dim * dim ? k : nullptr;
  } catch (const Error &) {
    return nullptr;
  }
}

CompiledFn compiled_event(Value event, Value state, int counts, const char *who) {
  CompiledEvent *entry = nullptr;
  for (CompiledEvent &e : g_events)
    if (eq(e.event, event) && value_has_shape(state, e.state_shape)) entry = &e;
  if (!entry) {
    if (g_events.size() >= kCompiledMemo) g_events.erase(g_events.begin());
    g_events.push_back(CompiledEvent{event, state});
    entry = &g_events.back();
  }
  entry->interpreted += static_cast<uint64_t>(counts);
  if (!entry->tried && entry->interpreted >= kCompileEventAfter && c_compiler_enabled() &&
      g_event_compiler) {
    entry->tried = true;
    std::string why;
    entry->compiled = g_event_compiler(event, state, who, &why);
  }
  return entry->compiled;
}

CompiledFn compile_expensive_function(Value f, const char *who) {
  if (!c_compiler_enabled() || !g_scalar_compiler) return nullptr;
  std::string why_not;
  return g_scalar_compiler(f, who, &why_not);
}

void set_scalar_compiler(ScalarCompiler compiler) {
  g_scalar_compiler = compiler;
}

void set_system_compiler(SystemCompiler compiler) {
  g_system_compiler = compiler;
}

void set_event_compiler(SystemCompiler compiler) {
  g_event_compiler = compiler;
}

} // namespace sicm
