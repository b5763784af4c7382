// Evaluation form: simplified kernel outputs rewritten into shapes that cost fewer operations.
//
// Requires: expressions in the simplifier's canonical form (cas/expr.hpp,
// C1-C6): expanded polynomials and quotients of them over variables (inputs
// and kernels such as (sin x0)). Produces: expressions equal to them in exact
// arithmetic, no longer canonical, meant only for the C emitter:
//   - each polynomial in greedy multivariate Horner form: the variable found
//     in the most terms is factored out of them, recursively, so
//     a x^2 y + b x y + c y costs 4 multiplications instead of 7;
//   - a common numeric factor of a sum is multiplied once (60 (a - b), not
//     60 a - 60 b) where that saves multiplications;
//   - outputs whose denominators are equal up to a numeric factor share one
//     reciprocal: the accelerations of a system with a mass matrix all divide
//     by its determinant, and a division costs as much as ten multiplications.
// Kernel arguments ((sin (+ x y)), (sqrt u)) are rewritten the same way.
// Floating-point rounding differs from the expanded form's at the level of a
// few units in the last place; that is why only outputs the simplifier has
// already reordered come here (traced state derivatives and compiled
// procedures), never integrands or objectives kept in the interpreter's order.
#pragma once

#include <vector>

#include "cas/expr.hpp"

namespace sicm {

// Rewrite every output in place (see above). Expressions of other shapes are
// left as they are.
void to_evaluation_form(std::vector<ExprId> &outputs);

} // namespace sicm
