// Local rewrites of a traced kernel DAG: the simplification that never enlarges it.
//
// Requires: kernel outputs as traced (codegen/kernel_form.hpp): a DAG of
// numbers, input symbols, ops.def applications and solve nodes. Produces:
// the same functions (equal in exact arithmetic) as a DAG with at most as
// many operations, in which, node by node:
//   - numeric factors of a product are one coefficient, first: the
//     coefficients of its factor products are hoisted into it, so
//     1/2 (2 x) is x and -(-(x)) is x;
//   - like factors of a product are one power (x^-2 x^-1 is x^-3), and an
//     integer power of a product with a coefficient is the coefficient's
//     power times the product's ((2 x)^-1 is 1/2 x^-1);
//   - like terms of a sum are one term with the sum of their coefficients,
//     so a term cancelled by its negation is gone, and c sin^2 x + c cos^2 x
//     is c;
//   - a product used by just one other product is merged into it; a sum
//     used by just one other sum only when some of its terms are like
//     terms of the other's (else it is rounded on its own, as written);
//   - powers of powers with integer exponents multiply their exponents,
//     and an even power of a square root is a power of its argument.
// Nothing is expanded, nothing shared is copied into its users, and
// differences stay differences, so floating-point evaluation keeps the
// structure of the procedure (pair differences first).
#pragma once

#include <vector>

#include "cas/expr.hpp"

namespace sicm {

// The outputs rewritten (one result per output, in order).
std::vector<ExprId> rewrite_locally(const std::vector<ExprId> &outputs);

} // namespace sicm
