// Symbolic expressions: a hash-consed DAG of nodes in one arena, named by small ids.
//
// Every expression the algebra builds lives here once: building a node that
// already exists returns the existing id, so structural equality is id
// equality, a shared subexpression is one node (simplification memoizes on
// ids, the C emitter gets CSE for free) and children always come before their
// parents (child id < parent id), so a pass over ids in increasing order sees
// operands before the operations that use them. The arena only grows: ids are
// never reused and nodes never change, which is what makes the memo tables of
// the simplifier sound.
//
// Node kinds:
//   Rational  an exact rational number (an integer when its denominator is 1)
//   Flonum    an IEEE double
//   Symbol    a Scheme symbol used as a literal real number ('m, 'theta)
//   Apply     an operator of cas/ops.def applied to argument expressions
//   Call      an unknown function applied to arguments; the function itself is
//             an expression: a symbol f in (f t), or an expression that denotes
//             a derived function, as (D f) in ((D f) t), (expt D 2) in
//             (((expt D 2) f) t) and ((partial 1 0) H) in (((partial 1 0) H) s).
//             A structured argument (up t (up x y)) is a Call whose head is the
//             symbol up or down.
//
// Memory: nodes hold ids, numbers and Symbol pointers, never Values, so the
// arena is ordinary malloc'd memory; the symbols it mentions are also kept in
// a collected vector so an uninterned symbol cannot be freed under it. Exact
// numbers are GMP rationals owned by the arena.
//
// INVARIANTS of every node (checked by expr_apply/expr_call with SICM_EXPR_CHECK,
// on in builds without NDEBUG):
//   I1  children before parents: every argument id and a Call's head id are
//       smaller than the node's own id;
//   I2  uniqueness: no two nodes have the same kind, operator, payload and
//       arguments (a Rational's value is compared with mpq_equal, a Flonum's
//       bit pattern, so 0. and -0. are different nodes);
//   I3  a Rational is in lowest terms with a positive denominator;
//   I4  an Apply has the arity its operator allows: exactly `arity` arguments
//       for fixed-arity operators, 1 or 2 for atan, at least 2 for + and *,
//       exactly 2 for / ; there are no Apply nodes of - (generic subtraction
//       builds (+ a (* -1 b))). Generic division builds (/ a b) (a quotient
//       rounds differently from a product with a reciprocal, and compiled
//       code must round as the interpreter does); in canonical form / is only
//       the top of a quotient of two polynomials (C6).
//
// CANONICAL FORM (what simplify returns; checked by expr_is_canonical, which
// the simplifier asserts on its results in builds without NDEBUG):
//   C1  an expression is a number, a variable, a polynomial or a quotient
//       (/ N D) of two polynomials;
//   C2  a variable is a symbol, a non-finite flonum or a kernel: an Apply of a
//       non-rational operator (sqrt exp log sin cos tan asin acos atan sinh
//       cosh abs, or expt with an exponent that is not an exact integer of
//       magnitude at most kMaxExpandedPower) or a Call, whose arguments are
//       canonical and to which no rule of the simplifier applies (a Call's
//       head is left as built, except that nested partials are sorted);
//   C3  variables are totally ordered by expr_compare: symbols by name (as
//       symbol<? orders them), then kernels;
//   C4  a power is (expt v n) with v a variable and n an exact integer >= 2;
//       a monomial is a variable, a power, or (* c p1 p2 ...) with c an
//       optional number other than 1 (exact 0 never) first and then powers or
//       variables in strictly increasing variable order, at least two
//       arguments in all;
//   C5  a polynomial is a number, a monomial, or (+ m1 m2 ...) with at least
//       two monomials in strictly decreasing graded lexicographic order of
//       exponent vectors, the first variable most significant, except that a
//       constant term comes first: the order in which scmutils prints terms,
//       (+ -1 (expt x 2) (* 2 x y));
//   C6  in (/ N D), N and D have no common factor, N is not 0 and D is not a
//       number; if D is a monomial its coefficient is 1 (scmutils divides
//       numbers through into N); otherwise N and D have exact integer
//       coefficients with no common integer factor and the leading
//       (highest-degree) term of D has a positive coefficient.
// A result computed from flonums has flonum coefficients (see simplify.cpp);
// it satisfies C1-C6 except the integrality of C6.
#pragma once

#include <gmp.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <unordered_set>
#include <vector>

#include "base/value.hpp"
#include "cas/ops.hpp"

namespace sicm {

// Invariant checks that cost a pass over a node's arguments: on unless NDEBUG.
#ifdef NDEBUG
#define SICM_EXPR_CHECK(cond) ((void)sizeof(cond)) // not evaluated
#else
#define SICM_EXPR_CHECK(cond) SICM_ASSERT(cond)
#endif

using ExprId = uint32_t;
constexpr ExprId kNoExpr = UINT32_MAX;

enum class ExprKind : uint8_t { Rational, Flonum, Symbol, Apply, Call };

struct ExprNode {
  ExprKind kind;
  Op op;         // Apply only
  uint32_t hash; // of kind, op, payload and arguments
  uint32_t nargs;
  uint32_t args; // index of the first argument in the argument pool
  union {
    uint32_t rat; // Rational: index into the rational pool
    double d;     // Flonum
    Symbol *sym;  // Symbol
    ExprId head;  // Call
  };
};

// ---- construction (hash-consed; no rewriting: callers build what they mean) ----
ExprId expr_rational(mpq_srcptr q); // q need not be canonical
// q must be canonical (as the tower's numbers and FLINT's rationals are): no
// gcd, which for a number of millions of bits takes minutes.
ExprId expr_canonical_rational(mpq_srcptr q);
ExprId expr_integer(int64_t n);
ExprId expr_flonum(double d);
ExprId expr_symbol(Symbol *s);
ExprId expr_apply(Op op, const ExprId *args, size_t nargs);
ExprId expr_apply(Op op, std::initializer_list<ExprId> args);
ExprId expr_call(ExprId head, const ExprId *args, size_t nargs);
// A real number Value (fixnum, bignum, ratnum, flonum) as a node; a complex
// one is a located error (expressions are over the reals).
ExprId expr_from_number(Value v);

// ---- access ----
// The reference is valid until the next node is built.
const ExprNode &expr_node(ExprId id);
const ExprId *expr_args(ExprId id);
inline ExprId expr_arg(ExprId id, size_t i) {
  return expr_args(id)[i];
}
mpq_srcptr expr_rat(ExprId id); // Rational only
size_t expr_count();            // number of nodes so far

inline ExprKind expr_kind(ExprId id) {
  return expr_node(id).kind;
}
inline bool expr_is_number(ExprId id) {
  ExprKind k = expr_kind(id);
  return k == ExprKind::Rational || k == ExprKind::Flonum;
}
inline bool expr_is_apply(ExprId id, Op op) {
  const ExprNode &n = expr_node(id);
  return n.kind == ExprKind::Apply && n.op == op;
}
bool expr_is_exact_zero(ExprId id);
bool expr_is_exact_one(ExprId id);
bool expr_is_exact_integer(ExprId id);
// The value of an exact integer node if it fits in int64 (else false).
bool expr_get_int64(ExprId id, int64_t *out);
// A Rational or Flonum node as a Scheme number.
Value expr_number_value(ExprId id);
// Sign of a number node (-1, 0, 1; NaN counts as 0).
int expr_number_sign(ExprId id);

// + - * / : the operators of the rational skeleton of an expression.
bool op_is_rational(Op op);

// Powers with larger exact integer exponents are not expanded as polynomials
// but kept as kernels (expanding (expt (+ a b) 10000000) would exhaust memory).
constexpr int64_t kMaxExpandedPower = 100000;
// (expt b n) with n an exact integer, |n| <= kMaxExpandedPower.
bool expr_is_polynomial_power(ExprId id);
// A variable in the sense of C2: a symbol, a non-finite flonum, a Call, or an
// Apply of an operator other than + - * / and polynomial powers.
bool expr_is_variable(ExprId id);
// A number that is not a variable: a rational or a finite flonum.
bool expr_is_constant(ExprId id);
// A copy of a node's arguments: node references and argument pointers are
// invalidated when the arena grows, so code that builds nodes while walking
// one takes a copy first.
std::vector<ExprId> expr_arg_vector(ExprId id);

// Call visit(id) once for every node reachable from the roots (the
// arguments of an Apply or a Call are reachable from it; a Call's head is
// not), in no particular order, until visit returns false. Returns false
// if it stopped early.
template <typename Visit> bool expr_visit(const std::vector<ExprId> &roots, Visit visit) {
  std::vector<ExprId> stack(roots.begin(), roots.end());
  std::unordered_set<ExprId> seen;
  while (!stack.empty()) {
    ExprId id = stack.back();
    stack.pop_back();
    if (!seen.insert(id).second) continue;
    if (!visit(id)) return false;
    ExprKind kind = expr_kind(id);
    if (kind != ExprKind::Apply && kind != ExprKind::Call) continue;
    const ExprId *args = expr_args(id);
    stack.insert(stack.end(), args, args + expr_node(id).nargs);
  }
  return true;
}

// ---- order ----
// A total order on expressions, used for variables (C3) and for kernel
// arguments: numbers (by value, exact before inexact when equal) < symbols (by
// name, bytewise) < applications. Applications are compared by head, then
// argument by argument, then by argument count; a derived-function head such
// as (D f) sorts before every named head (so the book's
// (+ (((expt D 2) f) x) (* -1 (f x))) comes out in its order), named heads
// (operators by their Scheme name, literal functions by symbol) compare by
// name. Returns <0, 0, >0; 0 only for the same id.
int expr_compare(ExprId a, ExprId b);

// ---- printing ----
// The expression as a Scheme datum in prefix form (cas/prefix_form.cpp);
// a canonical expression prints in scmutils' order.
Value expr_to_datum(ExprId id);

// ---- checks ----
// C1-C6 of the canonical form, recursively (memoized on ids).
bool expr_is_canonical(ExprId id);
// A one-line debugging rendering in prefix form, e.g. "(+ (* 2 x) 1)".
std::string expr_debug_string(ExprId id);

} // namespace sicm
