// Tracing: a procedure applied to symbols shaped like its arguments, giving its result as
// expressions.
//
// Requires: a procedure that computes its result from its arguments by generic
// arithmetic. Produces: a Trace, one
// expression per scalar leaf of the result in the form kernel_outputs chooses
// (codegen/kernel_form.hpp), over fresh uninterned symbols x0, x1, ... that
// stand for the arguments' scalar leaves and k0, k1, ... that stand for the
// numbers it captured (the kernel's parameters).
//
// Limits: a procedure that branches on an argument cannot be traced when the
// test raises on a symbol (`<`, `positive?`), which is reported; but `=`,
// `zero?` and `number?` answer #f for a symbol, so such a branch is traced as
// if it were never taken. compile_kernel catches that case at the sample
// point only, by comparing the kernel with the interpreter there.
#pragma once

#include <string>
#include <vector>

#include "base/value.hpp"
#include "cas/expr.hpp"
#include "codegen/kernel_form.hpp"

namespace sicm {

// Lives on the stack (it holds a Value and a gcvec that the collector must see).
struct Trace {
  gcvec<Symbol *> inputs;      // x_i stands for in[i]
  std::vector<ExprId> outputs; // out[j]: numbers, x_i, k_j, ops.def applications, solve nodes
  Value result_shape;          // the result with exact zeros at its leaves (0 for a scalar)
  // k_j stands for p[j], whose value is params[j] (KernelParameters,
  // algebra/symbolic.hpp): the numbers the procedure captured.
  gcvec<Symbol *> param_symbols;
  gcvec<Value> params;
};

// The one way a procedure is traced into a kernel, by `sicm run`
// (trace_procedure) and by `sicm build` (the residual functions of system
// derivatives): proc applied to args whose scalar leaves are the symbols
// that stand for the kernel's inputs, with the numbers it captured as the
// kernel's parameters (KernelParameters, which the caller makes around the
// call), other flonums entering the algebra as
// the decimals they were written as (DecimalConstants) and divisions by
// matrices of run-time values as solve nodes (KernelTracing). The caller
// takes the result's leaves (codegen/state_shape.hpp) and gives them to
// kernel_outputs (codegen/kernel_form.hpp). Errors propagate.
Value apply_traced(Value proc, gcvec<Value> args);

// Trace `proc` on arguments shaped like the elements of the list sample_args
// (each a number or a nested up/down structure of numbers). Returns false and
// a one-line reason in *why_not when the procedure cannot be traced. Errors
// the procedure raises on symbolic arguments are caught and become the reason;
// so do effects that would happen once, while tracing, instead of at each
// call (EffectGuard, eval/effect_guard.hpp).
bool trace_procedure(Value proc, Value sample_args, Trace *out, std::string *why_not);

// True if v is a number or a nested up/down structure whose leaves are numbers.
bool is_numeric_shape(Value v);

} // namespace sicm
