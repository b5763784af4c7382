// c - c cos x as 2c sin^2(x/2) in kernel outputs (see half_angle.hpp).
#include "codegen/half_angle.hpp"

#include <algorithm>
#include <optional>
#include <unordered_map>

#include "algebra/linear_solve.hpp"
#include "base/number.hpp"

namespace sicm {

namespace {

// A term of a sum: sign * coefficient * factors (factors sorted by id, so
// that equal products compare equal whatever order they were built in).
struct Term {
  ExprId node;
  int sign;
  Value coefficient;
  std::vector<ExprId> factors;
};

Term term_of(ExprId node, int sign) {
  Term t{node, sign, Value::fixnum(1), {}};
  if (expr_is_number(node)) {
    t.coefficient = expr_number_value(node);
    return t;
  }
  if (expr_is_apply(node, Op::Mul)) {
    for (ExprId f : expr_arg_vector(node)) {
      if (expr_is_number(f))
        t.coefficient = num_mul(t.coefficient, expr_number_value(f));
      else
        t.factors.push_back(f);
    }
  } else {
    t.factors.push_back(node);
  }
  std::sort(t.factors.begin(), t.factors.end());
  return t;
}

// If `with` is `without` times cos x (x one of with's factors), x.
std::optional<ExprId> extra_cosine(const Term &without, const Term &with) {
  if (with.factors.size() != without.factors.size() + 1) return std::nullopt;
  for (size_t k = 0; k < with.factors.size(); ++k) {
    ExprId f = with.factors[k];
    if (!expr_is_apply(f, Op::Cos)) continue;
    std::vector<ExprId> rest = with.factors;
    rest.erase(rest.begin() + static_cast<long>(k));
    if (rest == without.factors) return expr_arg(f, 0);
  }
  return std::nullopt;
}

// coefficient F trig(x/2)^2.
ExprId half_angle_term(Value coefficient, const std::vector<ExprId> &F, Op trig, ExprId x) {
  ExprId one_half = expr_from_number(num_div(Value::fixnum(1), Value::fixnum(2)));
  ExprId half = expr_apply(Op::Mul, {one_half, x});
  std::vector<ExprId> factors = {expr_from_number(coefficient)};
  factors.insert(factors.end(), F.begin(), F.end());
  factors.push_back(expr_apply(Op::Expt, {expr_apply(trig, {half}), expr_integer(2)}));
  return expr_apply(Op::Mul, factors.data(), factors.size());
}

class HalfAngles {
public:
  ExprId rewrite(ExprId id) {
    auto found = done_.find(id);
    if (found != done_.end()) return found->second;
    ExprId r = id;
    if (expr_kind(id) == ExprKind::Apply || is_solve_node(id)) {
      std::vector<ExprId> args = expr_arg_vector(id);
      bool changed = false;
      for (ExprId &a : args) {
        ExprId b = rewrite(a);
        changed = changed || b != a;
        a = b;
      }
      if (expr_is_apply(id, Op::Add) || expr_is_apply(id, Op::Sub))
        changed = pair_terms(expr_is_apply(id, Op::Sub), args) || changed;
      if (changed) r = rebuild(id, args);
    }
    done_.emplace(id, r);
    return r;
  }

private:
  // Replaces each pair c F, -/+ c F cos x among the terms of a sum (for a
  // difference, args[0] minus the others) by one term; true if any was.
  static bool pair_terms(bool difference, std::vector<ExprId> &args) {
    std::vector<Term> terms;
    for (size_t i = 0; i < args.size(); ++i)
      terms.push_back(term_of(args[i], difference && i > 0 ? -1 : 1));
    std::vector<bool> gone(args.size(), false), paired(args.size(), false);
    bool changed = false;
    for (size_t i = 0; i < terms.size(); ++i) {
      for (size_t j = 0; j < terms.size() && !paired[i]; ++j) {
        if (i == j || paired[j]) continue;
        std::optional<ExprId> x = extra_cosine(terms[i], terms[j]);
        if (!x) continue;
        Value ci = terms[i].sign > 0 ? terms[i].coefficient : num_neg(terms[i].coefficient);
        Value cj = terms[j].sign > 0 ? terms[j].coefficient : num_neg(terms[j].coefficient);
        Op trig;
        if (num_equal(cj, num_neg(ci)))
          trig = Op::Sin; // c F - c F cos x = 2 c F sin^2(x/2)
        else if (num_equal(cj, ci))
          trig = Op::Cos; // c F + c F cos x = 2 c F cos^2(x/2)
        else
          continue;
        // The pair is sign_i 2 c_i F trig^2(x/2). It takes the place of
        // term i, or of the minuend when either was that.
        Value value = num_mul(Value::fixnum(2), ci);
        size_t at = difference && (i == 0 || j == 0) ? 0 : i;
        Value coefficient = difference && at > 0 ? num_neg(value) : value;
        args[at] = half_angle_term(coefficient, terms[i].factors, trig, *x);
        gone[at == i ? j : i] = true;
        paired[i] = paired[j] = true;
        changed = true;
      }
    }
    if (!changed) return false;
    std::vector<ExprId> kept;
    for (size_t i = 0; i < args.size(); ++i)
      if (!gone[i]) kept.push_back(args[i]);
    args = kept;
    return true;
  }

  static ExprId rebuild(ExprId original, const std::vector<ExprId> &args) {
    if (expr_kind(original) == ExprKind::Call)
      return expr_call(expr_node(original).head, args.data(), args.size());
    if (args.size() == 1 && expr_is_apply(original, Op::Add)) return args[0];
    if (args.size() == 1 && expr_is_apply(original, Op::Sub) && expr_node(original).nargs > 1)
      return args[0]; // only the first term, a difference's minuend, is left
    return expr_apply(expr_node(original).op, args.data(), args.size());
  }

  std::unordered_map<ExprId, ExprId> done_;
};

} // namespace

std::vector<ExprId> rewrite_half_angles(const std::vector<ExprId> &outputs) {
  HalfAngles pass;
  std::vector<ExprId> out;
  for (ExprId id : outputs)
    out.push_back(pass.rewrite(id));
  return out;
}

} // namespace sicm
