// Native kernels: procedures on numbers and structures of numbers, compiled to C and loaded.
//
// A kernel is what a numerical primitive runs in its inner loop: a state
// derivative, a map, an integrand. compile_kernel turns a Scheme procedure into
// one in three passes, each in its own file:
//
//   trace.cpp   apply the procedure to fresh symbols shaped like sample
//               arguments, put each scalar leaf of the result in its kernel
//               form (kernel_form.hpp: the traced DAG rewritten locally, or
//               a small kernel's canonical form when that pays)
//               (requires: the procedure computes its result by generic
//               arithmetic alone; produces: a Trace, the outputs as
//               expressions over the input symbols)
//   emit_c.cpp  the Trace as one C11 function with the kernel ABI, after CSE,
//               powers as products, sin/cos pairs as sincos and linear
//               solves as LDL^T or LU factorizations, runs of one shape over
//               many index tuples as loops over index tables (loops.hpp)
//   jit.cpp     the C compiled by the system compiler into a shared object,
//               cached by content hash, and loaded with dlopen
//
// Then the kernel is checked once against the interpreter at the sample
// arguments (see compile_kernel). compile_kernel and the helpers to call a
// kernel live in trace.cpp, beside the first pass. A procedure that cannot be traced (it
// branches on its arguments, returns a non-number, calls a literal function)
// or a C compiler that is missing or fails gives nullptr and a reason: the
// caller interprets the procedure instead.
//
// The ABI of every kernel: void NAME(const double *in, double *out, const
// double *p), in[] the arguments' scalar leaves in order (depth first, left to
// right, argument after argument), out[] the result's leaves in the same
// order, p[] the numbers the procedure captured (its parameters, in the
// order the trace met them: KernelParameters, algebra/symbolic.hpp). Two
// procedures whose numbers differ only in value have the same C, so a
// scan over a parameter compiles and loads one shared object; every
// function of a kernel (derivative, singular factors, Taylor coefficients)
// takes the same p[].
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "base/value.hpp"

namespace sicm {

struct InterpretedKernel; // codegen/kernel_interpreter.hpp

using KernelFn = void (*)(const double *in, double *out, const double *p);
using TaylorFn = void (*)(const double *in, int order, double *c, const double *p);
using TaylorExtendedFn = void (*)(const long double *in, int order, long double *c,
                                  const double *p);

// Allocated with gc_new (it holds Values); its strings are freed by a
// finalizer when it is collected. The loaded code is never unloaded.
struct Kernel {
  KernelFn fn = nullptr;
  size_t nin = 0, nout = 0;
  Value arg_shapes;     // the sample arguments as given (a list): their shapes
  Value source;         // the procedure compiled (applied to arguments that are not numbers)
  Value result_shape;   // a structure of the result's shape, or a number for a scalar result
  std::string name;     // the procedure's name as the user wrote it (for printing)
  std::string c_name;   // the C function's name (generated, [A-Za-z0-9_] only)
  std::string c_source; // the whole translation unit given to the C compiler
  std::string so_path;  // the shared object in the cache
  // For a system derivative compiled with probe_singularities: a function
  // of the same inputs computing what the kernel divides by
  // (codegen/singular_factors.hpp), one value per text; null if nothing.
  KernelFn singular_factors = nullptr;
  std::vector<std::string> singular_texts;
  // For a system derivative compiled with `taylor`: the Taylor coefficients
  // of its solution (codegen/emit_taylor.hpp), for sicm_ode_step_taylor,
  // and the same in long double for sicm_ode_step_taylor_extended; null,
  // with the reason in taylor_why_not, when an operation has no recurrence.
  TaylorFn taylor = nullptr;
  TaylorExtendedFn taylor_extended = nullptr;
  std::string taylor_why_not;
  // The values of p[] for every function above.
  std::vector<double> params;
  // Under SICM_INTERPRET=1 (codegen/kernel_interpreter.hpp): what fn and
  // singular_factors run instead of loaded code (c_source is still the C
  // they would compile, so_path empty; the Taylor functions, which the
  // kernel interpreter does not run, are compiled even so); else null.
  std::shared_ptr<const InterpretedKernel> interpreted;
};

// The p[] to pass to k's functions (null when it has no parameters): the
// numbers of k->params, or for an interpreted kernel the object its
// functions run (not numbers: only k's functions may be given it).
inline const double *kernel_params(const Kernel *k) {
  if (k->interpreted) return reinterpret_cast<const double *>(k->interpreted.get());
  return k->params.empty() ? nullptr : k->params.data();
}

// The p[] to pass to k's Taylor functions: compiled C in both modes, they
// take the numbers of k->params.
inline const double *taylor_params(const Kernel *k) {
  return k->params.empty() ? nullptr : k->params.data();
}

// What compile_kernel makes besides the kernel, for a system derivative
// (whose one argument is the state).
struct KernelOptions {
  // Its singular factors, named by their place in the state ((ref state 1 0)).
  bool probe_singularities = false;
  // The Taylor coefficient functions of its solution (double and long double).
  bool taylor = false;
};

// Compile `proc` for arguments shaped like `sample_args` (a Scheme list with
// one value per argument: a number or a nested up/down structure of numbers).
// `name` names the kernel in messages and, sanitized, in the C source (null:
// the procedure's own name, or "anonymous"). On failure returns nullptr and,
// if why_not is not null, stores a one-line reason there; errors the
// procedure raises while it is traced are caught and become the reason.
// The procedure runs twice: once on symbols, once at the sample arguments to
// check the kernel, so its side effects happen then, not when the kernel runs.
// options asks for more functions of a system derivative (see KernelOptions).
Kernel *compile_kernel(Value proc, Value sample_args, const char *name, std::string *why_not,
                       KernelOptions options = {});

// Called with every kernel compile_kernel makes (sicm emit-c lists them);
// null (the default) for none.
using KernelListener = void (*)(const Kernel *k);
void set_kernel_listener(KernelListener listener);

// Run the kernel: in has k->nin doubles, out room for k->nout.
void kernel_call(const Kernel *k, const double *in, double *out);

// The result as a Scheme value: a flonum, or a structure of k's result shape
// whose leaves are out[0 .. k->nout).
Value kernel_result_value(const Kernel *k, const double *out);

// Append the scalar leaves of v (a number or a nested structure of numbers) to
// out as doubles. Raises MIT's wrong-type error (naming `who`) on anything else.
void flatten_value(Value v, std::vector<double> &out, const char *who = "kernel");

// Does v have the shape of `shape` (same nesting of up and down structures of
// the same lengths, numbers at the leaves)?
bool value_has_shape(Value v, Value shape);

// (compile-procedure proc sample ...), (kernel? x), (kernel-c-source k).
// Called by init_interpreter.

} // namespace sicm
