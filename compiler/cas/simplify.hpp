// The simplifier: any expression to its canonical form (cas/expr.hpp, C1-C6).
//
// Requires: an expression of the arena. Produces: a canonical expression with
// the same value (under scmutils' assumptions: (log (exp x)) = x,
// (asin (sin x)) = x, ...). Memoized on ids for the life of the program, so
// simplifying again, or simplifying a larger expression that shares parts
// with an earlier one, costs little.
#pragma once

#include "cas/expr.hpp"

namespace sicm {

ExprId simplify_expr(ExprId id);

} // namespace sicm
