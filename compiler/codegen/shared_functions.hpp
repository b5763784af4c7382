// Functions of a residual program that are the same C but for the names of
// their registers: the same system derivative traced at two call sites (two
// identical state-advancer calls on different lines) is the same kernel,
// and the built program compiles it once. Registers are numbered across the
// whole program (var_name in residual_emit.cpp), so the two texts differ
// only there; renumbered from 1 in order of first appearance, they are
// equal.
#pragma once

#include <string>

namespace sicm {

// The text of an emitted function with its name (`name`, the identifier
// after "static void ") and its leading comment dropped and its registers
// (r followed by digits) renumbered r1, r2, ... in order of first
// appearance: equal for two functions exactly when one can stand for the
// other.
std::string canonical_function_text(const std::string &code, const std::string &name);

} // namespace sicm
