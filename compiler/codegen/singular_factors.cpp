// The factors of what a kernel divides by (see singular_factors.hpp).
#include "codegen/singular_factors.hpp"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/limits.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

// Simplifying a 3 x 3 determinant of a rigid body's mass matrix takes a few
// thousand nodes; a budget keeps a pathological one from costing more.
constexpr uint64_t kDeterminantBudget = 200000;

Value value_of(ExprId id) {
  if (expr_is_number(id)) return expr_number_value(id);
  Value v;
  v.tag = Tag::Expr;
  v.i = id;
  return v;
}

ExprId expr_of_value(Value v) {
  if (v.is(Tag::Expr)) return static_cast<ExprId>(v.i);
  if (is_number(v)) return expr_from_number(v);
  return kNoExpr;
}

class Collector {
public:
  explicit Collector(const std::function<std::string(Symbol *)> &name_of) : name_of_(name_of) {}

  void collect(const std::vector<ExprId> &outputs) {
    // The nodes first, in id order (the order they were made, so texts come
    // in the order the procedure met its divisors): probing builds nodes,
    // which a walk must not see.
    std::vector<ExprId> nodes;
    expr_visit(outputs, [&](ExprId id) {
      nodes.push_back(id);
      return true;
    });
    std::sort(nodes.begin(), nodes.end());
    std::unordered_set<ExprId> solves_seen;
    for (ExprId id : nodes) {
      if (full()) break;
      if (is_solve_node(id)) {
        // Every component of one solve has the same matrix: probe it once.
        if (solves_seen.insert(solve_matrix_entry(id, 0, 0)).second) determinant_of(id);
      } else if (expr_kind(id) == ExprKind::Apply) {
        divisors_of(id);
      }
    }
  }

  SingularFactors result() const { return found_; }

private:
  bool full() const { return found_.values.size() >= kMaxSingularFactors; }

  void divisors_of(ExprId id) {
    Op op = expr_node(id).op; // (node references do not survive new nodes)
    std::vector<ExprId> args = expr_arg_vector(id);
    int64_t k;
    if (op == Op::Expt && expr_get_int64(args[1], &k) && k < 0)
      add_factors(args[0]);
    else if (op == Op::Div)
      for (size_t i = 1; i < args.size(); ++i)
        add_factors(args[i]);
    else if (op == Op::Log)
      add_factors(args[0]);
  }

  void determinant_of(ExprId solve) {
    size_t dim = solve_dimension(solve);
    if (dim > kMaxProbedSolve) return;
    try {
      ExpressionBudget budget(kDeterminantBudget);
      Value m = make_matrix(dim, dim);
      for (size_t i = 0; i < dim; ++i)
        for (size_t j = 0; j < dim; ++j)
          matrix_at(as_matrix(m), i, j) = value_of(solve_matrix_entry(solve, i, j));
      ExprId det = expr_of_value(simplify_value(determinant(m)));
      if (det != kNoExpr) add_factors(det);
    } catch (const Error &) {
      // Too large to simplify: the solve's own failure message stands.
    }
  }

  // The distinct non-numeric factors of id: those of a product, the base
  // of a power, or id itself.
  void add_factors(ExprId id) {
    if (full() || expr_is_number(id)) return;
    bool apply = expr_kind(id) == ExprKind::Apply;
    Op op = expr_node(id).op;
    std::vector<ExprId> args = apply ? expr_arg_vector(id) : std::vector<ExprId>{};
    if (apply && op == Op::Mul) {
      for (ExprId a : args)
        add_factors(a);
      return;
    }
    if (apply &&
        ((op == Op::Expt && expr_is_number(args[1])) || (op == Op::Sub && args.size() == 1))) {
      add_factors(args[0]); // a power's base; a negation's argument
      return;
    }
    if (!seen_.insert(id).second) return;
    found_.values.push_back(id);
    found_.texts.push_back(text_of(id));
  }

  std::string text_of(ExprId id) const { return display_string(renamed(expr_to_datum(id))); }

  Value renamed(Value datum) const {
    if (is_symbol(datum)) {
      std::string name = name_of_(datum.symbol());
      return name.empty() ? datum : intern(name); // the user's terms, not a generated name
    }
    if (!is_pair(datum)) return datum;
    return cons(renamed(car(datum)), renamed(cdr(datum)));
  }

  const std::function<std::string(Symbol *)> &name_of_;
  std::unordered_set<ExprId> seen_;
  SingularFactors found_;
};

ExprId substituted(ExprId id, std::unordered_map<ExprId, ExprId> &done) {
  auto found = done.find(id);
  if (found != done.end()) return found->second;
  ExprId r = id;
  ExprKind kind = expr_kind(id);
  if (kind == ExprKind::Apply || kind == ExprKind::Call) {
    std::vector<ExprId> args = expr_arg_vector(id);
    bool changed = false;
    for (ExprId &a : args) {
      ExprId b = substituted(a, done);
      changed = changed || b != a;
      a = b;
    }
    if (changed)
      r = kind == ExprKind::Apply ? expr_apply(expr_node(id).op, args.data(), args.size())
                                  : expr_call(expr_node(id).head, args.data(), args.size());
  }
  done.emplace(id, r);
  return r;
}

} // namespace

std::vector<ExprId> with_inputs(const std::vector<ExprId> &factors,
                                const std::vector<Symbol *> &from,
                                const std::vector<Symbol *> &to) {
  std::unordered_map<ExprId, ExprId> done;
  for (size_t i = 0; i < from.size() && i < to.size(); ++i)
    done[expr_symbol(from[i])] = expr_symbol(to[i]);
  std::vector<ExprId> out;
  for (ExprId f : factors)
    out.push_back(substituted(f, done));
  return out;
}

std::vector<ExprId> with_leaves(const std::vector<ExprId> &values,
                                const std::unordered_map<ExprId, ExprId> &leaves) {
  std::unordered_map<ExprId, ExprId> done(leaves);
  std::vector<ExprId> out;
  for (ExprId v : values)
    out.push_back(substituted(v, done));
  return out;
}

SingularFactors singular_factors(const std::vector<ExprId> &outputs,
                                 const std::function<std::string(Symbol *)> &name_of) {
  Collector c(name_of);
  c.collect(outputs);
  return c.result();
}

} // namespace sicm
