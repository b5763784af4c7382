// Which form of a traced procedure's outputs a kernel computes: the traced DAG, or its canonical
// form.
//
// Display and code want different forms. Printing a result uses the
// simplifier's canonical rational form (numerator expanded over one
// denominator): that is what makes results comparable with the book. For
// code that form grows exponentially with the size of a system (an N-body
// acceleration over one common denominator of every pair's distance) and
// expands differences that floating point needs computed first. The traced
// DAG -- what generic arithmetic built while the procedure ran on symbols,
// hash-consed, one node per distinct subexpression, with the light rewrites
// of symbolic_apply (constants folded, exact 0 and 1) -- grows only as the
// procedure's own work does, and keeps its structure (pair differences
// first).
//
// So every kernel, in `sicm run` and in `sicm build` alike, is traced the
// same way and then:
//   - the traced DAG is rewritten locally (codegen/local_rewrite.hpp: like
//     terms and factors merged, coefficients folded; never enlarged);
//   - if its outputs together have at most kMaxCanonicalizedNodes distinct
//     nodes and divide by at most kMaxCanonicalizedDenominators distinct
//     expressions, each output is also brought to the canonical form (then to the
//     evaluation form of cas/evaluation_form.hpp) within
//     kCanonicalizationBudget new nodes, and the kernel keeps it if its C
//     is kCanonicalAdvantage times shorter than the traced form's. Small
//     kernels (the book's pendulums) gain from it: terms cancel, shared
//     denominators;
//   - otherwise the traced form, never canonicalized whole.
// Both ways the C emitter then shares every repeated node (CSE), writes
// integer powers as products and computes sin and cos of one argument
// together.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "base/value.hpp"
#include "cas/expr.hpp"

namespace sicm {

// Kernels whose traced outputs have more distinct nodes than this are
// never canonicalized (see above). The book's state derivatives have a few
// hundred nodes; a 12-link chain's, 2,200, and its canonical form (each
// entry of its mass matrix and forces a short polynomial in sines and
// cosines) is two thirds of the traced form's C, and as quick to make.
constexpr size_t kMaxCanonicalizedNodes = 20000;

// Nor are kernels that divide by more distinct expressions than this: their
// canonical form puts them all over one common denominator (the N-body
// problem's accelerations over the product of every pair's distance). A
// symbolic 2 x 2 inverse divides by its determinant alone, which the traced
// form holds in up to three spellings (multiples of one another).
constexpr size_t kMaxCanonicalizedDenominators = 4;

// The canonical form is kept only when the traced form's C is this many
// times longer: it must pay for itself clearly, since its expanded sums
// round together what the procedure computed apart (1/2 v^2 + 1 - cos x
// where the procedure had 1/2 v^2 + (1 - cos x)). The book's pendulums
// gain 1.5 to 2 times from it; an energy 1.1 times, not enough.
constexpr double kCanonicalAdvantage = 1.5;

// And the canonical form is given at most this many new expression nodes:
// a kernel of few nodes can still have an enormous canonical form (the
// accelerations of 8 bodies over one common denominator).
constexpr size_t kCanonicalizationBudget = 200000;

// Says whether a kernel may hold one node as it is: a symbol that stands
// for an input (or, in sicm build, a run-time value), a solve node; a number
// or an operation is always allowed, a literal function's call never.
using NodeAllowed = std::function<bool(ExprId)>;

// Which roots hold only allowed nodes, each judged once: one pass over the
// whole DAG in id order (an argument's id is smaller than its user's).
std::vector<bool> allowed_roots(const std::vector<ExprId> &roots, const NodeAllowed &allowed);

// The outputs of a kernel, one per scalar leaf (a number, a symbol or an
// expression: the caller has checked). A traced output that holds a node
// `allowed` refuses (a traced form can still hold what simplification
// cancels, such as a symbol times a zero difference) is replaced by its
// simplified form whatever its size.
std::vector<ExprId> kernel_outputs(const gcvec<Value> &leaves, const NodeAllowed &allowed);

// The number of distinct nodes under the roots (numbers, symbols and
// operations alike), counting up to `cap` at most.
size_t dag_size(const std::vector<ExprId> &roots, size_t cap = SIZE_MAX);

// Which form of one output a kernel computes when it has both: `simplified`,
// unless simplifying multiplied the size of `traced` (the simplifier's
// canonical form expands powers of sums: a 216th power of a trinomial is
// 23,653 terms, a megabyte of C, and cancellation eats the expanded sum's
// value); then `traced`, the same function.
ExprId kernel_output_form(ExprId traced, ExprId simplified);

// The leaf (a number, a symbol or an expression) as an expression node, or
// kNoExpr for anything else.
ExprId leaf_expr(Value leaf);

} // namespace sicm
