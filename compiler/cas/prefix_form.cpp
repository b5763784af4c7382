// Expressions as Scheme data in scmutils' prefix form: (+ (* 1/2 m (expt v 2)) (* -1 (U r))).
//
// The canonical form already has scmutils' term and factor order (expr.hpp,
// C4-C6), so printing a simplified expression is a walk that copies it.
// Other expressions print faithfully too: a product with negative integer
// powers becomes a quotient, (expt x -1) becomes (/ 1 x), so an unsimplified
// expression never shows an exponent the user did not write.
#include <algorithm>
#include <unordered_map>
#include <vector>

#include "cas/expr.hpp"

namespace sicm {
namespace {

using DatumMemo = std::unordered_map<ExprId, Value, std::hash<ExprId>, std::equal_to<ExprId>,
                                     gc_allocator<std::pair<const ExprId, Value>>>;

Value to_datum(ExprId id, DatumMemo &memo);

Value op_symbol(Op op) {
  return intern(op_info(op).scheme_name);
}

Value list_of(Value head, const gcvec<Value> &items) {
  return cons(head, list_from(items.data(), items.size()));
}

// b^e for a positive integer e, as a datum.
Value power_datum(ExprId base, Value exponent, DatumMemo &memo) {
  if (eq(exponent, Value::fixnum(1))) return to_datum(base, memo);
  return list({op_symbol(Op::Expt), to_datum(base, memo), exponent});
}

// (* f ...) of already converted factors, or the single factor, or 1.
Value product_datum(const gcvec<Value> &factors) {
  if (factors.empty()) return Value::fixnum(1);
  if (factors.size() == 1) return factors[0];
  return list_of(op_symbol(Op::Mul), factors);
}

// A product, split into numerator and denominator by the signs of integer exponents.
Value mul_datum(ExprId id, DatumMemo &memo) {
  gcvec<Value> num, den;
  for (ExprId f : expr_arg_vector(id)) {
    int64_t e;
    if (expr_is_apply(f, Op::Expt) && expr_get_int64(expr_arg(f, 1), &e) && e < 0)
      den.push_back(power_datum(expr_arg(f, 0), Value::fixnum(-e), memo));
    else
      num.push_back(to_datum(f, memo));
  }
  if (den.empty()) return list_of(op_symbol(Op::Mul), num);
  return list({op_symbol(Op::Div), product_datum(num), product_datum(den)});
}

// A monomial as scmutils' printer sees it: an optional number and factors
// (base, positive exponent) in order. Anything that is not a product of
// powers (a sum, a quotient) is not one; other kernels are bases.
struct Monomial {
  ExprId coefficient = kNoExpr;
  std::vector<std::pair<ExprId, int64_t>> factors;
};

bool add_factor(ExprId f, Monomial &m) {
  int64_t e;
  if (expr_is_apply(f, Op::Add) || expr_is_apply(f, Op::Div) || expr_is_apply(f, Op::Mul))
    return false;
  if (expr_is_apply(f, Op::Expt) && expr_get_int64(expr_arg(f, 1), &e)) {
    if (e <= 0) return false;
    m.factors.push_back({expr_arg(f, 0), e});
  } else {
    m.factors.push_back({f, 1});
  }
  return true;
}

bool as_monomial(ExprId id, Monomial &m) {
  if (expr_is_number(id)) {
    m.coefficient = id;
    return true;
  }
  if (!expr_is_apply(id, Op::Mul)) return add_factor(id, m);
  std::vector<ExprId> args = expr_arg_vector(id);
  for (size_t i = 0; i < args.size(); ++i) {
    if (i == 0 && expr_is_number(args[i])) {
      m.coefficient = args[i];
      continue;
    }
    if (!add_factor(args[i], m)) return false;
  }
  return true;
}

// term / den with their common powers cancelled, as a datum: the term
// itself when den cancels entirely.
Value term_over(const Monomial &term, Monomial den, DatumMemo &memo) {
  gcvec<Value> num, below;
  if (term.coefficient != kNoExpr) num.push_back(to_datum(term.coefficient, memo));
  for (auto [base, e] : term.factors) {
    for (auto &[dbase, d] : den.factors)
      if (dbase == base) {
        int64_t common = std::min(e, d);
        e -= common;
        d -= common;
      }
    if (e > 0) num.push_back(power_datum(base, Value::fixnum(e), memo));
  }
  for (auto [dbase, d] : den.factors)
    if (d > 0) below.push_back(power_datum(dbase, Value::fixnum(d), memo));
  Value top = product_datum(num);
  if (below.empty()) return top;
  return list({op_symbol(Op::Div), top, product_datum(below)});
}

// scmutils writes a sum over a monomial denominator as the sum of its
// terms, each over what is left of the denominator:
// (+ ((D x) t) (/ (* -1 (p_x t)) m)), not (/ (+ (* m ((D x) t)) (* -1 (p_x t))) m).
bool split_quotient(ExprId id, DatumMemo &memo, Value *out) {
  ExprId n = expr_arg(id, 0), d = expr_arg(id, 1);
  Monomial den;
  if (!expr_is_apply(n, Op::Add) || !as_monomial(d, den) || den.coefficient != kNoExpr ||
      den.factors.empty())
    return false;
  std::vector<Monomial> terms;
  for (ExprId t : expr_arg_vector(n)) {
    terms.emplace_back();
    if (!as_monomial(t, terms.back())) return false;
  }
  gcvec<Value> items;
  for (const Monomial &t : terms)
    items.push_back(term_over(t, den, memo));
  *out = list_of(op_symbol(Op::Add), items);
  return true;
}

Value compute_datum(ExprId id, DatumMemo &memo) {
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: return expr_number_value(id);
  case ExprKind::Symbol: return Value::object(Tag::Symbol, n.sym);
  case ExprKind::Call: {
    ExprId head = n.head;
    gcvec<Value> items;
    for (ExprId a : expr_arg_vector(id))
      items.push_back(to_datum(a, memo));
    return list_of(to_datum(head, memo), items);
  }
  case ExprKind::Apply: break;
  }
  Op op = n.op;
  if (op == Op::Mul) return mul_datum(id, memo);
  if (Value split; op == Op::Div && split_quotient(id, memo, &split)) return split;
  int64_t e;
  if (op == Op::Expt && expr_get_int64(expr_arg(id, 1), &e) && e < 0)
    return list({op_symbol(Op::Div), Value::fixnum(1),
                 power_datum(expr_arg(id, 0), Value::fixnum(-e), memo)});
  gcvec<Value> items;
  for (ExprId a : expr_arg_vector(id))
    items.push_back(to_datum(a, memo));
  return list_of(op_symbol(op), items);
}

Value to_datum(ExprId id, DatumMemo &memo) {
  auto it = memo.find(id);
  if (it != memo.end()) return it->second;
  Value d = compute_datum(id, memo);
  memo.emplace(id, d);
  return d;
}

} // namespace

Value expr_to_datum(ExprId id) {
  DatumMemo memo;
  return to_datum(id, memo);
}

} // namespace sicm
