// The residual program's verifier: the invariants of codegen/residual.hpp
// checked between the passes of `sicm build`, as QBE verifies its IR.
//
// What a user can get wrong (a numerical result that depends on a symbol
// with no value, a value that escapes the procedure it was computed in) is
// the C emitter's compile error and passes here; what only a bug of the
// partial evaluator can break is a violation: ids out of range, a statement
// without the fields its kind needs, a variable used before (or without)
// its definition or defined twice, a Continue outside its loop, a type that
// contradicts the computation. The checks run when SICM_CHECK_RESIDUAL=1 is
// in the environment (tests/run sets it, so `make check` runs them); a
// violation is an internal error naming the pass after which it was found.
#pragma once

#include <string>

#include "codegen/residual.hpp"

namespace sicm {

// The first violated invariant of `program`, described ("f2: statement 3
// (let): r7 is used before it is defined"), or "" if there is none.
std::string residual_violation(const ResidualProgram &program);

// Is SICM_CHECK_RESIDUAL=1 set (read once)?
bool residual_checks_enabled();

// When the checks are enabled, abort with an internal error if `program`
// violates an invariant after the pass named `pass`.
void check_residual(const ResidualProgram &program, const char *pass);

} // namespace sicm
