// The residual program as text: `sicm build --dump=residual` and `sicm
// emit-c --dump=residual` print what the partial evaluator left for run time
// (codegen/residual.hpp), before the C emitter's liveness drops anything.
#pragma once

#include <string>

#include "codegen/residual.hpp"

namespace sicm {

// Each function (f0 is main) with its inputs, outputs and statements, one a
// line, nested blocks indented: "r3 = (* r1 r2)", "print r3", "if r5",
// "evolve f2 (r1 r2 r3) -> r7 r8 r9", ...
std::string dump_residual(const ResidualProgram &program);

// A statement kind as the dump names it ("evolve", "definite-integral").
const char *statement_kind_name(RKind kind);

} // namespace sicm
