// Which procedures given to sicm run's numerical primitives run compiled,
// and how many: system derivatives as kernels (codegen/), or, when they
// test the state, by sicm build's partial evaluator; expensive functions
// given to bisect by the partial evaluator. Compiling is never required: a
// null result means the procedure stays interpreted. SICM_INTERPRET=1 in the
// environment keeps the C compiler out: kernels are run by the kernel
// interpreter (codegen/kernel_interpreter.hpp), bit for bit as their C,
// and what only the partial evaluator compiles is not compiled.
#pragma once

#include <cstddef>

#include "base/value.hpp"
#include "builtins/numerics.hpp"
#include "codegen/kernel.hpp"

namespace sicm {

// The kernel of a system derivative on states shaped like `state` (dim
// leaves), compiled once and remembered; with taylor, with the Taylor
// coefficients of its solution when its operations all have recurrences
// (the taylor method asks for them; the others do not pay for compiling
// them). Null when it cannot be traced.
const Kernel *auto_kernel(Value sysder, Value state, size_t dim, bool taylor = false);

// A system derivative that has no kernel (auto_kernel tried first)
// compiled by the partial evaluator, as sicm build compiles it, once; null
// when it cannot be. who: the primitive, for messages.
CompiledFn auto_residual(Value sysder, Value state, const char *who);

// A kernel of (D sysder) on states shaped like `state`, or null (the
// derivative cannot be differentiated and traced, or no C compiler).
const Kernel *jacobian_kernel(Value sysder, Value state, size_t dim);

// crossings' event procedure on states shaped like `state`, compiled by
// the partial evaluator once it has been interpreted often enough to pay
// for the C compiler (kCompileEventAfter calls, counted across the calls of
// crossings with the same procedure: a section map calls crossings once
// per point). Call it after each interpreted call (counts == 1) or to ask
// for what is compiled already (counts == 0); null until then, and when the
// procedure cannot be compiled (then it is not tried again).
CompiledFn compiled_event(Value event, Value state, int counts, const char *who);

// bisect's function f, whose interpreted calls prove expensive, compiled
// by the partial evaluator; null when it cannot be.
CompiledFn compile_expensive_function(Value f, const char *who);

} // namespace sicm
