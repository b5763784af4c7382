// Numerical primitives of the interpreter: quadrature, minimization, root
// finding and ODE integration (definite-integral, minimize, nelder-mead,
// multidimensional-minimize, find-root, bisect, state-advancer, evolve), over
// the runtime's numerical modules (runtime/include/sicm/*.h).
#pragma once

#include <string>

#include "base/value.hpp"

namespace sicm {

// A procedure compiled for sicm run: writes f(in) to out (f(in[0]) to
// out[0] for a function of one real; a derivative's leaves for a state's)
// and returns 0, or returns 1 where the interpreter must compute the value
// (a checked operation would leave the reals: division by zero, the square
// root of a negative number; or *interrupt became nonzero in a loop).
using CompiledFn = int (*)(const double *in, double *out, const volatile int *interrupt);

// What compiles bisect's function when one interpreted call proves
// expensive: f compiled and loaded, or null with the reason in *why_not.
// sicm build's partial evaluator provides it (pe/for_run.cpp's
// compile_for_run, given at start-up by driver/init.cpp); without one, the
// function is interpreted.
using ScalarCompiler = CompiledFn (*)(Value f, const char *who, std::string *why_not);
void set_scalar_compiler(ScalarCompiler compiler);

// What compiles a system derivative that the kernel tracer cannot (it tests
// the state), for states shaped like `state`: compiled and loaded, or null
// with the reason in *why_not. pe/for_run.cpp's compile_system_for_run,
// given at start-up; without one, the derivative is interpreted.
using SystemCompiler = CompiledFn (*)(Value sysder, Value state, const char *who,
                                      std::string *why_not);
void set_system_compiler(SystemCompiler compiler);

// What compiles the event procedure of crossings, once its interpreted
// calls prove many, for states shaped like `state` (the same signature: the
// output is the event's one value). pe/for_run.cpp's compile_event_for_run,
// given at start-up; without one, the event is interpreted.
void set_event_compiler(SystemCompiler compiler);

struct NativeProc;

// The call of the procedure (crossings sysder . params) returns, self being
// that procedure: the states at the crossings, computed now. sicm build
// calls it at compile time when every argument is known then
// (pe/numerics.cpp), so that both modes compute the same numbers.
Value crossings_now(NativeProc *self, Value *a, int n);

} // namespace sicm
