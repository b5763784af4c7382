// The kernel interpreter: a kernel's schedule run on doubles, operation for operation as its C
// runs, for SICM_INTERPRET=1 (no C compiler, no JIT).
//
// Requires: the schedule the C emitter prints (codegen/schedule.hpp) of
// unchecked outputs (a kernel's, not a residual program's). Produces:
// for every input, the bits the JIT'ed C gives: the same IEEE operations on
// the same operands (the schedule's trees), the same libm functions (sincos
// for a pair, pow, atan2, ...), the same constants, the linear solves of the
// same C source (codegen/kernel_solve.inc, compiled into this file), and no
// fused multiply-add on either side (-ffp-contract=off for this file in the
// Makefile, and for the generated C in codegen/jit.cpp and
// driver/build_exe.cpp). Evaluating independent terms in another order
// than the C compiler chooses changes nothing: each term is a pure
// function of its operands.
//
// The schedule's trees become a list of three-address instructions over a
// register file (constants, in[], p[], one register per operation,
// arrays for the solves), loaded once per kernel; a call copies the
// inputs in and runs the list. About ten times slower than the JIT'ed C,
// far faster than the generic evaluator.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "cas/expr.hpp"
#include "codegen/kernel.hpp"

namespace sicm {

// Is SICM_INTERPRET set in the environment (and neither empty nor "0")?
// Then kernels are interpreted here and nothing is compiled by a C compiler.
bool kernels_interpreted();

// The instructions of one kernel function (opaque).
class KernelProgram;

// The program computing out[j] = outputs[j] over in[i] = inputs[i] and
// p[k] = params[k]: what emit_kernel_function's C computes for the same
// outputs. Every symbol of the outputs is among inputs or params.
std::shared_ptr<const KernelProgram> load_kernel_program(const std::vector<ExprId> &outputs,
                                                         std::span<Symbol *const> inputs,
                                                         std::span<Symbol *const> params);

// Run it: in has as many doubles as inputs, out room for the outputs, p as
// many as params (or null when there are none). Thread-safe.
void run_kernel_program(const KernelProgram &program, const double *in, double *out,
                        const double *p);

// An interpreted Kernel's functions: what they run, and the numbers of
// p[]. Its functions (interpreted_kernel_entry, interpreted_probe_entry)
// have the kernel ABI and are given, as their p[], this object instead
// of numbers (kernel_params, codegen/kernel.hpp), so the runtime calls
// them as it calls loaded code.
struct InterpretedKernel {
  std::shared_ptr<const KernelProgram> fn, singular_factors;
  std::vector<double> params;
};

// Run InterpretedKernel::fn (respectively singular_factors) of the
// InterpretedKernel that p points to.
KernelFn interpreted_kernel_entry();
KernelFn interpreted_probe_entry();

} // namespace sicm
