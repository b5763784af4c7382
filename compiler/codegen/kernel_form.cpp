// Which form of a traced procedure's outputs a kernel computes (see kernel_form.hpp).
#include "codegen/kernel_form.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <unordered_set>

#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/limits.hpp"
#include "base/number.hpp"
#include "cas/evaluation_form.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/half_angle.hpp"
#include "codegen/local_rewrite.hpp"

namespace sicm {

namespace {

// The fuzz target emit-3 found the expansion: (expt (+ (* 2 x) (expt x 3)
// (sinh y)) 216) took gcc -O2 minutes. Growth by a factor of 8 (and 256
// nodes) leaves room for what simplification legitimately multiplies out
// (products of small sums, a cube of a binomial).
constexpr size_t kMaxSimplifiedGrowth = 8;
constexpr size_t kSimplifiedSlack = 256;

// The length of the C that computes the outputs: what the choice between
// two forms is measured by.
size_t emitted_size(const std::vector<ExprId> &outputs) {
  std::vector<std::string> targets(outputs.size(), "o");
  return emit_c_assignments(
             outputs, targets, [](Symbol *) { return std::string("x"); }, "t", "")
      .size();
}

// The number of distinct expressions the outputs divide by (a quotient's
// divisor, the base of a negative power), counting up to `cap` at most.
size_t denominators(const std::vector<ExprId> &roots, size_t cap) {
  std::unordered_set<ExprId> divisors;
  expr_visit(roots, [&](ExprId id) {
    if (expr_is_apply(id, Op::Div)) {
      std::vector<ExprId> args = expr_arg_vector(id);
      for (size_t i = args.size() == 1 ? 0 : 1; i < args.size(); ++i)
        if (!expr_is_number(args[i])) divisors.insert(args[i]);
    }
    if (expr_is_apply(id, Op::Expt) && !expr_is_number(expr_arg(id, 0)) &&
        expr_is_number(expr_arg(id, 1)) && expr_number_sign(expr_arg(id, 1)) < 0)
      divisors.insert(expr_arg(id, 0));
    return divisors.size() < cap;
  });
  return divisors.size();
}

} // namespace

ExprId leaf_expr(Value leaf) {
  if (is_number(leaf)) return expr_from_number(leaf);
  if (leaf.is(Tag::Symbol)) return expr_symbol(leaf.symbol());
  if (leaf.is(Tag::Expr)) return static_cast<ExprId>(leaf.i);
  return kNoExpr;
}

size_t dag_size(const std::vector<ExprId> &roots, size_t cap) {
  size_t n = 0;
  expr_visit(roots, [&](ExprId) { return ++n < cap; });
  return n;
}

ExprId kernel_output_form(ExprId traced, ExprId simplified) {
  size_t limit = kMaxSimplifiedGrowth * dag_size({traced}) + kSimplifiedSlack;
  return dag_size({simplified}, limit + 1) > limit ? traced : simplified;
}

std::vector<bool> allowed_roots(const std::vector<ExprId> &roots, const NodeAllowed &allowed) {
  std::vector<ExprId> nodes;
  expr_visit(roots, [&](ExprId id) {
    nodes.push_back(id);
    return true;
  });
  std::sort(nodes.begin(), nodes.end());
  std::unordered_set<ExprId> refused;
  for (ExprId id : nodes) {
    bool ok = allowed(id);
    ExprKind kind = expr_kind(id);
    if (ok && (kind == ExprKind::Apply || kind == ExprKind::Call))
      for (ExprId a : expr_arg_vector(id))
        ok = ok && !refused.count(a);
    if (!ok) refused.insert(id);
  }
  std::vector<bool> out;
  for (ExprId id : roots)
    out.push_back(!refused.count(id));
  return out;
}

std::vector<ExprId> kernel_outputs(const gcvec<Value> &leaves, const NodeAllowed &allowed) {
  std::vector<ExprId> traced;
  for (Value leaf : leaves)
    traced.push_back(leaf_expr(leaf));
  traced = rewrite_half_angles(rewrite_locally(traced));
  std::vector<bool> usable = allowed_roots(traced, allowed);
  bool all_usable = std::find(usable.begin(), usable.end(), false) == usable.end();
  if (all_usable &&
      (dag_size(traced, kMaxCanonicalizedNodes + 1) > kMaxCanonicalizedNodes ||
       denominators(traced, kMaxCanonicalizedDenominators + 1) > kMaxCanonicalizedDenominators))
    return traced;

  std::vector<ExprId> simplified;
  try {
    // Within a budget when there is a way out: the traced form.
    std::optional<ExpressionBudget> budget;
    if (all_usable) budget.emplace(kCanonicalizationBudget);
    for (size_t i = 0; i < leaves.size(); ++i) {
      ExprId s = leaf_expr(simplify_value(leaves[i]));
      bool keep_traced = usable[i] && kernel_output_form(traced[i], s) == traced[i];
      simplified.push_back(keep_traced ? traced[i] : s);
    }
    to_evaluation_form(simplified);
    simplified = rewrite_half_angles(simplified);
  } catch (const Error &) {
    if (!all_usable) throw;
    return traced;
  }
  if (!all_usable) return simplified;
  return kCanonicalAdvantage * static_cast<double>(emitted_size(simplified)) <=
                 static_cast<double>(emitted_size(traced))
             ? simplified
             : traced;
}

} // namespace sicm
