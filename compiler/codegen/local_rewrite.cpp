// Local rewrites of a traced kernel DAG (see local_rewrite.hpp).
//
// One pass over the nodes reachable from the outputs in increasing id
// order, which is topological (an argument is made before its user), so a
// node is rewritten after all of its arguments. Only the node's own
// arguments are looked at, never deeper, except through an argument that
// nothing else uses (merging it into its user removes a node). The order of
// factors and terms is that of their first appearance, as the procedure
// built them: it does not depend on node ids, which differ between `sicm
// run` and `sicm build`.
#include "codegen/local_rewrite.hpp"

#include <algorithm>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "algebra/linear_solve.hpp"
#include "base/number.hpp"

namespace sicm {

namespace {

struct Monomial {
  Value coefficient = Value::fixnum(1);
  std::vector<ExprId> factors; // not numbers; order of first appearance
};

class Rewriter {
public:
  explicit Rewriter(const std::vector<ExprId> &outputs) {
    std::vector<ExprId> nodes;
    std::unordered_set<ExprId> seen;
    std::vector<ExprId> stack(outputs.begin(), outputs.end());
    while (!stack.empty()) {
      ExprId id = stack.back();
      stack.pop_back();
      if (!seen.insert(id).second) continue;
      nodes.push_back(id);
      if (!has_arguments(id)) continue;
      const ExprId *args = expr_args(id);
      stack.insert(stack.end(), args, args + expr_node(id).nargs);
    }
    for (ExprId id : nodes)
      if (has_arguments(id))
        for (ExprId a : expr_arg_vector(id))
          ++uses_[a];
    for (ExprId id : outputs)
      ++uses_[id];
    std::sort(nodes.begin(), nodes.end());
    for (ExprId id : nodes)
      done_[id] = rewrite(id);
  }

  ExprId result(ExprId original) const { return done_.at(original); }

private:
  static bool has_arguments(ExprId id) {
    return expr_kind(id) == ExprKind::Apply || is_solve_node(id);
  }

  // A rewritten node as coefficient times factors.
  static Monomial monomial_of(ExprId r) {
    Monomial m;
    if (expr_is_number(r)) {
      m.coefficient = expr_number_value(r);
      return m;
    }
    if (!expr_is_apply(r, Op::Mul)) {
      m.factors.push_back(r);
      return m;
    }
    std::vector<ExprId> args = expr_arg_vector(r);
    size_t first = 0;
    if (expr_is_number(args[0])) {
      m.coefficient = expr_number_value(args[0]);
      first = 1;
    }
    m.factors.assign(args.begin() + static_cast<long>(first), args.end());
    // c (f g ...), as product() writes a coefficient times several factors.
    if (first == 1 && m.factors.size() == 1 && expr_is_apply(m.factors[0], Op::Mul))
      m.factors = expr_arg_vector(m.factors[0]);
    return m;
  }

  static bool exact_zero(Value v) { return is_exact(v) && num_is_zero(v); }
  static bool exact_one(Value v) { return v.is(Tag::Fixnum) && v.i == 1; }

  // base^n for an integer n, with the power rules of the header.
  ExprId power(ExprId base, int64_t n) {
    if (n == 1) return base;
    if (n == 0) return expr_integer(1);
    if (expr_is_apply(base, Op::Sqrt) && n % 2 == 0) return power(expr_arg(base, 0), n / 2);
    int64_t m;
    if (expr_is_apply(base, Op::Expt) && expr_get_int64(expr_arg(base, 1), &m) && m != 0 &&
        m > INT32_MIN && m < INT32_MAX && n > INT32_MIN && n < INT32_MAX)
      return power(expr_arg(base, 0), m * n);
    return expr_apply(Op::Expt, {base, expr_integer(n)});
  }

  // The product of a monomial: like bases merged into one power. (Exponents
  // enter within int32's range, so their sums fit in int64.)
  ExprId product(const Monomial &m) {
    if (exact_zero(m.coefficient)) return expr_integer(0);
    std::vector<ExprId> bases;
    std::unordered_map<ExprId, int64_t> exponent;
    for (ExprId f : m.factors) {
      ExprId base = f;
      int64_t n;
      if (expr_is_apply(f, Op::Expt) && expr_get_int64(expr_arg(f, 1), &n) && n > INT32_MIN &&
          n < INT32_MAX)
        base = expr_arg(f, 0);
      else
        n = 1;
      auto [it, fresh] = exponent.emplace(base, 0);
      if (fresh) bases.push_back(base);
      it->second += n;
    }
    // u^n (sqrt u)^k is (sqrt u)^(2n + k): one square root, one power.
    for (ExprId b : bases) {
      if (!expr_is_apply(b, Op::Sqrt)) continue;
      auto u = exponent.find(expr_arg(b, 0));
      if (u == exponent.end() || u->second == 0) continue;
      exponent[b] += 2 * u->second;
      u->second = 0;
    }
    std::vector<ExprId> factors;
    if (!exact_one(m.coefficient)) factors.push_back(expr_from_number(m.coefficient));
    for (ExprId b : bases) {
      int64_t n = exponent.at(b);
      if (n == 0) continue;
      factors.push_back(n > INT32_MIN && n < INT32_MAX
                            ? power(b, n)
                            : expr_apply(Op::Expt, {b, expr_integer(n)}));
    }
    if (factors.empty()) return expr_from_number(m.coefficient);
    if (factors.size() == 1) return factors[0];
    // A coefficient times several factors is c (f g ...): the product of the
    // factors is a node of its own, which -(f g) and (f g) share (the force
    // of a pair, added to one body and subtracted from the other).
    if (factors.size() > 2 && expr_is_number(factors[0])) {
      std::vector<ExprId> rest(factors.begin() + 1, factors.end());
      return representative(Op::Mul, {factors[0], representative(Op::Mul, rest)});
    }
    return representative(Op::Mul, factors);
  }

  // One node for each product or sum of the same arguments in any order (a
  // b and b a): the first one made. Then equal subexpressions share one
  // node, and a symmetric matrix is symmetric node for node.
  ExprId representative(Op op, const std::vector<ExprId> &args) {
    ExprId node = expr_apply(op, args.data(), args.size());
    std::vector<ExprId> key = args;
    std::sort(key.begin(), key.end());
    key.push_back(static_cast<ExprId>(op));
    return representatives_.emplace(std::move(key), node).first->second;
  }

  // The factors of a monomial without its coefficient, as one node.
  ExprId rest(const Monomial &m) {
    Monomial r{Value::fixnum(1), m.factors};
    return product(r);
  }

  ExprId rewrite_product(const std::vector<ExprId> &original) {
    Monomial m;
    for (ExprId a : original) {
      Monomial part = monomial_of(done_.at(a));
      m.coefficient = num_mul(m.coefficient, part.coefficient);
      if (part.factors.size() <= 1 || uses_[a] == 1)
        m.factors.insert(m.factors.end(), part.factors.begin(), part.factors.end());
      else
        m.factors.push_back(rest(part));
    }
    return product(m);
  }

  ExprId rewrite_power(ExprId base, ExprId exponent) {
    int64_t n;
    if (!expr_get_int64(exponent, &n) || n <= INT32_MIN || n >= INT32_MAX)
      return expr_apply(Op::Expt, {base, exponent});
    Monomial m = monomial_of(base);
    if (m.factors.empty() || exact_one(m.coefficient) || exact_zero(m.coefficient))
      return product(Monomial{Value::fixnum(1), {power(base, n)}});
    // (c f)^n = c^n f^n, exactly for an exact c. The rest is one power.
    if (!is_exact(m.coefficient)) return expr_apply(Op::Expt, {base, exponent});
    Monomial p{num_expt(m.coefficient, Value::fixnum(n)), {power(rest(m), n)}};
    return product(p);
  }

  // Like terms have equal keys: their factors without the coefficient, in
  // any order (a b and b a).
  static std::vector<ExprId> like_key(ExprId term) {
    std::vector<ExprId> key = monomial_of(term).factors;
    std::sort(key.begin(), key.end());
    return key;
  }

  static ExprId square_of(Op op, ExprId x) {
    return expr_apply(Op::Expt, {expr_apply(op, {x}), expr_integer(2)});
  }

  // The terms of a sum: its arguments, with a sum that only this one uses
  // (or a number times one) merged into it when one of its terms is like a
  // term outside it (the derivative of a product leaves a b' + a' b next to
  // -(a b' + a' b)).
  // Otherwise a sum inside a sum stays a sum of its own: merging it would
  // save no addition and would round its terms with the others' (1 - cos x
  // computed on its own keeps its value near x = 0; 1/2 v^2 + 1 - cos x
  // loses it).
  // The terms of the sum that argument a of a sum contributes if merged:
  // a's own if a is a sum only it uses, c t_i if a is c times such a sum
  // (the coefficient distributed: -(x - y) is -x + y); else none.
  std::vector<ExprId> inner_terms(ExprId a) {
    if (uses_[a] != 1) return {};
    ExprId sum = a;
    Value c = Value::fixnum(1);
    if (expr_is_apply(a, Op::Mul) && expr_node(a).nargs == 2 && expr_is_number(expr_arg(a, 0)) &&
        expr_is_apply(expr_arg(a, 1), Op::Add) && uses_[expr_arg(a, 1)] == 1) {
      sum = expr_arg(a, 1);
      c = expr_number_value(expr_arg(a, 0));
    }
    ExprId r = done_.at(sum);
    if (!expr_is_apply(sum, Op::Add) || !expr_is_apply(r, Op::Add)) return {};
    std::vector<ExprId> terms = expr_arg_vector(r);
    if (exact_one(c)) return terms;
    for (ExprId &t : terms) {
      Monomial m = monomial_of(t);
      m.coefficient = num_mul(m.coefficient, c);
      t = product(m);
    }
    return terms;
  }

  std::vector<ExprId> sum_terms(const std::vector<ExprId> &original) {
    std::map<std::vector<ExprId>, int> count;
    auto note = [&](ExprId t) {
      if (!expr_is_number(t)) ++count[like_key(t)];
    };
    std::vector<std::vector<ExprId>> inner;
    for (ExprId a : original) {
      inner.push_back(inner_terms(a));
      if (inner.back().empty()) {
        note(done_.at(a));
        continue;
      }
      for (ExprId t : inner.back())
        note(t);
    }
    std::vector<ExprId> terms;
    for (size_t i = 0; i < original.size(); ++i) {
      ExprId r = done_.at(original[i]);
      if (inner[i].empty()) {
        terms.push_back(r);
        continue;
      }
      const std::vector<ExprId> &parts = inner[i];
      std::map<std::vector<ExprId>, int> own;
      for (ExprId t : parts)
        if (!expr_is_number(t)) ++own[like_key(t)];
      bool merges = false;
      for (auto &[key, n] : own)
        merges = merges || count[key] > n;
      if (merges)
        terms.insert(terms.end(), parts.begin(), parts.end());
      else
        terms.push_back(r);
    }
    return terms;
  }

  ExprId rewrite_sum(const std::vector<ExprId> &original) {
    Value constant = Value::fixnum(0);
    std::vector<ExprId> rests; // order of first appearance
    std::map<std::vector<ExprId>, ExprId> rest_of_key;
    std::unordered_map<ExprId, Value> coefficient;
    gcvec<Value> keep; // the coefficients, visible to the collector
    auto add_term = [&](Value c, ExprId r) {
      auto [k, fresh_key] = rest_of_key.emplace(like_key(r), r);
      r = k->second; // the first order of these factors
      auto [it, fresh] = coefficient.emplace(r, c);
      if (fresh)
        rests.push_back(r);
      else
        it->second = num_add(it->second, c);
      keep.push_back(it->second);
    };
    for (ExprId t : sum_terms(original)) {
      if (expr_is_number(t)) {
        constant = num_add(constant, expr_number_value(t));
        continue;
      }
      Monomial m = monomial_of(t);
      add_term(m.coefficient, rest(m));
    }
    // c r sin(x)^2 + c r cos(x)^2 is c r.
    for (size_t i = 0; i < rests.size(); ++i) {
      ExprId r = rests[i];
      Value c = coefficient.at(r);
      if (num_is_zero(c)) continue;
      Monomial m = monomial_of(r);
      for (size_t f = 0; f < m.factors.size(); ++f) {
        ExprId sq = m.factors[f];
        if (!expr_is_apply(sq, Op::Expt) || !expr_is_apply(expr_arg(sq, 0), Op::Sin) ||
            expr_arg(sq, 1) != expr_integer(2))
          continue;
        ExprId x = expr_arg(expr_arg(sq, 0), 0);
        std::vector<ExprId> partner_key = m.factors;
        partner_key[f] = square_of(Op::Cos, x);
        std::sort(partner_key.begin(), partner_key.end());
        auto partner = rest_of_key.find(partner_key);
        if (partner == rest_of_key.end()) continue;
        Value pc = coefficient.at(partner->second);
        if (!num_equal(pc, c)) continue;
        coefficient[r] = Value::fixnum(0);
        coefficient[partner->second] = Value::fixnum(0);
        Monomial without = m;
        without.factors.erase(without.factors.begin() + static_cast<long>(f));
        if (without.factors.empty())
          constant = num_add(constant, c);
        else
          add_term(c, rest(without));
        break;
      }
    }
    std::vector<ExprId> out;
    for (ExprId r : rests) {
      Value c = coefficient.at(r);
      if (num_is_zero(c)) continue; // a term cancelled by its negation
      Monomial m = monomial_of(r);
      m.coefficient = num_mul(m.coefficient, c);
      out.push_back(product(m));
    }
    if (!num_is_zero(constant) || (out.empty() && !is_exact(constant)))
      out.push_back(expr_from_number(constant));
    if (out.empty()) return expr_integer(0);
    if (out.size() == 1) return out[0];
    return representative(Op::Add, out);
  }

  ExprId rewrite(ExprId id) {
    if (!has_arguments(id)) return id;
    std::vector<ExprId> original = expr_arg_vector(id);
    std::vector<ExprId> args;
    for (ExprId a : original)
      args.push_back(done_.at(a));
    if (expr_kind(id) == ExprKind::Call)
      return expr_call(expr_node(id).head, args.data(), args.size());
    switch (expr_node(id).op) {
    case Op::Mul: return rewrite_product(original);
    case Op::Add: return rewrite_sum(original);
    case Op::Expt: return rewrite_power(args[0], args[1]);
    case Op::Div: {
      // A quotient is a product by the divisor's reciprocal, so that its
      // factors merge with the others (the emitter writes negative powers
      // in a product as divisions again). By a number known exactly, the
      // reciprocal is exact; a flonum divisor stays a division.
      if (args.size() == 1) args.insert(args.begin(), expr_integer(1)); // (/ x) is 1/x
      if (args.size() != 2 || expr_is_exact_zero(args[1])) break;
      bool number = expr_is_number(args[1]);
      if (number && !is_exact(expr_number_value(args[1]))) break;
      Monomial m = monomial_of(args[0]);
      if (number) {
        m.coefficient =
            num_mul(m.coefficient, num_div(Value::fixnum(1), expr_number_value(args[1])));
      } else {
        Monomial d = monomial_of(rewrite_power(args[1], expr_integer(-1)));
        m.coefficient = num_mul(m.coefficient, d.coefficient);
        m.factors.insert(m.factors.end(), d.factors.begin(), d.factors.end());
      }
      return product(m);
    }
    default: break;
    }
    return expr_apply(expr_node(id).op, args.data(), args.size());
  }

  std::unordered_map<ExprId, uint32_t> uses_;
  std::unordered_map<ExprId, ExprId> done_;
  std::map<std::vector<ExprId>, ExprId> representatives_; // sorted arguments and op -> node
};

} // namespace

std::vector<ExprId> rewrite_locally(const std::vector<ExprId> &outputs) {
  Rewriter r(outputs);
  std::vector<ExprId> out;
  for (ExprId id : outputs)
    out.push_back(r.result(id));
  return out;
}

} // namespace sicm
