// `sicm build`'s evaluator mode: the program runs at compile time and what
// depends on numerical results is recorded as a residual program (see
// codegen/residual.hpp and eval/builtins_build.cpp).
#pragma once

#include "codegen/residual.hpp"

namespace sicm {

// Rebind the primitives and install the evaluator's hooks so that what runs
// from now on records into `program` (which must outlive the run). Call
// after init_interpreter, before running the program; there is no way back
// (a build is one process).
void begin_build_mode(ResidualProgram *program);

} // namespace sicm
