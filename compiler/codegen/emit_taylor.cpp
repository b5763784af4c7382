// The Taylor emitter: Taylor-coefficient recurrences, node by node (see emit_taylor.hpp).
//
// Approach (automatic differentiation of the DAG, as in Jorba and Zou,
// "A software package for the numerical integration of ODEs by means of
// high-order Taylor methods", 2005, and Moore before them). Every node of
// the system derivative that depends on the state gets an array of its
// normalized Taylor coefficients v[0..order] along the solution. They are
// computed one order k at a time: at order k each node's coefficient k is
// computed, in increasing id order (children first), from the coefficients
// 0..k of its arguments and 0..k-1 of itself; then coefficient k of output
// f_i gives coefficient k+1 of x_i, since x_i' = f_i:
//
//   x_i[k+1] = f_i[k] / (k+1)
//
// The per-operation recurrences are the classical ones: sums termwise,
// products by Cauchy convolution, quotients, real powers, sqrt, exp, log,
// sin and cos together (and sinh and cosh), atan2 through
// (x^2 + y^2) theta' = x y' - y x'. They are small static inline C
// functions (c_taylor_support) called with the loop index k; the order is a
// run-time argument, bounded by SICM_ODE_TAYLOR_MAX_ORDER, the size of the
// arrays. Nodes that do not depend on the state (numbers, constant
// subexpressions) are computed once, by the ordinary C emitter, into
// scalars: a product or sum with them costs nothing extra per order, and
// where a recurrence needs an array a constant is spread into one
// (c, 0, 0, ...).
//
// Positive integer powers up to kMaxProductPower are repeated products (the
// power recurrence divides by the base's value, which may pass through 0:
// x^3 in a Duffing oscillator); other constant exponents use the power
// recurrence, which needs the base nonzero, as the derivative of the power
// does.
//
// A linear solve x = M^-1 b (the mass matrix of a chain) is M x = b order
// by order: M_0 x_k = b_k - sum_{j>=1} M_j x_{k-j}, with M_0 factored once
// per expansion, so each order costs a matrix-vector convolution and two
// triangular solves.
//
// A large system repeats a few recurrences many times (an N-body problem's
// pair terms, once per pair): its statements of order k are then loops over
// the rows of one pool of coefficient arrays (codegen/taylor_loops.cpp),
// computing the same bits as the straight-line statements of a small one.
//
// Limits: tan, asin, acos and variable exponents have no recurrence here
// (see emit_taylor.hpp); the caller says so and integrates another way.
#include "codegen/emit_taylor.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <unordered_map>
#include <unordered_set>

#include "algebra/linear_solve.hpp"
#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/taylor_loops.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// Positive integer powers up to this are written as products.
constexpr int64_t kMaxProductPower = 64;

// A function whose coefficient arrays times its order are at most this
// gets a copy for its known order with the order loop unrolled: every
// convolution's bounds become constants, and the Kepler problem's step
// (12 arrays, order 15) took 0.90 of the time, with the same operations
// and so the same bits (bench/taylor-vs-heyoka). Larger systems would pay
// in the C compiler's time more than they gain (the unrolled Kepler copy
// adds 0.15 s of gcc to its build).
constexpr size_t kMaxUnrolledNodeOrders = 400;

// (expt u 0): a constant 1 whatever u is (the C emitter writes it as 1.0).
bool is_zeroth_power(ExprId id) {
  return expr_is_apply(id, Op::Expt) && expr_is_exact_zero(expr_arg(id, 1));
}

// Is id (expt (sqrt u) a) with a constant exponent that is not a small
// positive integer? Its coefficients are those of u^(a/2), by one power
// recurrence instead of a square root's and a power's (the Kepler
// problem's r^-3 = (x^2 + y^2)^(-3/2)).
bool is_power_of_root(ExprId id) {
  if (!expr_is_apply(id, Op::Expt) || !expr_is_apply(expr_arg(id, 0), Op::Sqrt)) return false;
  ExprId a = expr_arg(id, 1);
  int64_t n;
  if (!expr_is_number(a)) return false;
  return !(expr_get_int64(a, &n) && n >= 1 && n <= kMaxProductPower);
}

class TaylorEmitter {
public:
  TaylorEmitter(const Trace &t, TaylorPrecision precision, const SymbolSpeller &spell)
      : t_(t), extended_(precision == TaylorPrecision::Extended), spell_(spell),
        real_(extended_ ? "long double" : "double"), tc_(extended_ ? "sicm_tcl_" : "sicm_tc_") {
    for (size_t i = 0; i < t.inputs.size(); ++i)
      input_[t.inputs[i]] = i;
  }

  bool emit(const std::string &c_name, int known_order, std::string *out, std::string *why_not) {
    if (t_.inputs.size() != t_.outputs.size()) {
      *why_not = "the derivative has " + std::to_string(t_.outputs.size()) +
                 " components but the state " + std::to_string(t_.inputs.size());
      return false;
    }
    collect();
    plan_sums_of_squares();
    plan_shared_products();
    for (ExprId id : nodes_)
      if (series_.count(id) && !absorbed_.count(id) && !emit_node(id, why_not)) return false;
    if (!why_not_.empty()) {
      *why_not = why_not_;
      return false;
    }
    *out = assemble(c_name, known_order);
    return true;
  }

private:
  // The arguments a node's recurrence reads: a power of a root reads the
  // root's argument.
  static std::vector<ExprId> operands_of(ExprId id) {
    std::vector<ExprId> args = expr_arg_vector(id);
    if (is_power_of_root(id)) args[0] = expr_arg(args[0], 0);
    return args;
  }

  // The nodes the recurrences need, reachable from the outputs, in
  // increasing id order, and which of them have coefficient arrays
  // (series_): those that depend on the state, and in extended precision
  // every operation (its constant value is then computed in long double
  // too, by the recurrence at order 0).
  void collect() {
    std::vector<ExprId> stack(t_.outputs.begin(), t_.outputs.end());
    std::unordered_set<ExprId> seen;
    while (!stack.empty()) {
      ExprId id = stack.back();
      stack.pop_back();
      if (!seen.insert(id).second) continue;
      nodes_.push_back(id);
      ExprKind kind = expr_kind(id);
      if (kind == ExprKind::Apply || kind == ExprKind::Call)
        for (ExprId a : operands_of(id))
          stack.push_back(a);
    }
    std::sort(nodes_.begin(), nodes_.end());
    for (ExprId id : nodes_) {
      ExprKind kind = expr_kind(id);
      bool depends = false;
      if (kind == ExprKind::Symbol) depends = input_.count(expr_node(id).sym) > 0;
      if ((kind == ExprKind::Apply || kind == ExprKind::Call) && !is_zeroth_power(id)) {
        depends = extended_ && kind == ExprKind::Apply;
        for (ExprId a : operands_of(id))
          depends = depends || series_.count(a) > 0;
      }
      if (depends) series_.insert(id);
    }
    for (ExprId id : nodes_) {
      ExprKind kind = expr_kind(id);
      if (kind == ExprKind::Apply || kind == ExprKind::Call)
        for (ExprId a : operands_of(id))
          ++users_[a];
    }
    for (ExprId id : t_.outputs)
      ++users_[id];
  }

  // ---- fused recurrences (after heyoka's sum_sq) ----
  //
  // An N-body derivative spends most of an order in short convolutions: per
  // pair the squares of three differences, and three products of the
  // pair's inverse cube by the differences, each a call of its own whose
  // set-up costs as much as its few terms. A sum of squares (nested sums of
  // (expt x 2), each used only there) is one recurrence with one loop
  // (sum_sq2, sum_sq3); products of one series factor by others (the
  // forces of a pair) are computed together, one loop reading the shared
  // factor once (product2, product3). Ten bodies (bench/taylor-vs-heyoka's
  // planets, 1e-12): 1,137 M instructions before, 840 M after, 0.83 of the
  // time. The sums are in another order than before, so the last bits of
  // such results change, alike in sicm run and sicm build.

  // The x of (expt x 2) with x a series, or kNoExpr.
  ExprId squared(ExprId id) const {
    int64_t n;
    if (!expr_is_apply(id, Op::Expt) || !expr_get_int64(expr_arg(id, 1), &n) || n != 2)
      return kNoExpr;
    return series_.count(expr_arg(id, 0)) ? expr_arg(id, 0) : kNoExpr;
  }

  // The squared terms of a sum of squares rooted at id, appended to xs; false
  // if it is not one. Inner nodes must be used by their parent alone.
  bool square_terms(ExprId id, bool root, std::vector<ExprId> &xs) const {
    if (!series_.count(id)) return false;
    if (!root && (users_.count(id) ? users_.at(id) : 0) != 1) return false;
    if (ExprId x = squared(id); x != kNoExpr) {
      xs.push_back(x);
      return true;
    }
    if (!expr_is_apply(id, Op::Add)) return false;
    for (ExprId a : expr_arg_vector(id))
      if (!square_terms(a, false, xs)) return false;
    return true;
  }

  // Sums of at least two squares become one recurrence at their root; the
  // squares and inner sums under it get no array (absorbed_).
  void plan_sums_of_squares() {
    for (auto it = nodes_.rbegin(); it != nodes_.rend(); ++it) {
      ExprId id = *it;
      if (absorbed_.count(id) || !expr_is_apply(id, Op::Add)) continue;
      std::vector<ExprId> xs;
      if (!square_terms(id, true, xs) || xs.size() < 2) continue;
      square_sums_[id] = xs;
      std::vector<ExprId> stack = expr_arg_vector(id);
      while (!stack.empty()) {
        ExprId a = stack.back();
        stack.pop_back();
        absorbed_.insert(a);
        if (expr_is_apply(a, Op::Add))
          for (ExprId b : expr_arg_vector(a))
            stack.push_back(b);
      }
    }
  }

  // Products of exactly two series (times constants) grouped by their
  // later factor (the larger id, computed last): each group's members are
  // computed together where the first of them comes (their other factors,
  // of smaller ids, are computed by then).
  void plan_shared_products() {
    std::unordered_map<ExprId, std::vector<ExprId>> by_factor;
    std::vector<ExprId> keys;
    for (ExprId id : nodes_) {
      if (!series_.count(id) || absorbed_.count(id) || !expr_is_apply(id, Op::Mul)) continue;
      std::vector<ExprId> factors;
      for (ExprId a : expr_arg_vector(id))
        if (series_.count(a)) factors.push_back(a);
      if (factors.size() != 2 || factors[0] == factors[1]) continue;
      ExprId later = std::max(factors[0], factors[1]);
      auto [it, fresh] = by_factor.emplace(later, std::vector<ExprId>{});
      if (fresh) keys.push_back(later);
      it->second.push_back(id);
    }
    for (ExprId key : keys) {
      const std::vector<ExprId> &members = by_factor[key];
      for (size_t i = 0; i + 1 < members.size(); i += 3) {
        std::vector<ExprId> group(members.begin() + static_cast<long>(i),
                                  members.begin() +
                                      static_cast<long>(std::min(i + 3, members.size())));
        product_group_[group[0]] = group;
      }
    }
  }

  // The group of shared products that begins at node id, computed together
  // (product2, product3); false if id begins none.
  bool emit_product_group(ExprId id) {
    auto it = product_group_.find(id);
    if (it == product_group_.end()) return false;
    const std::vector<ExprId> &group = it->second;
    std::string shared, outs, scales, others;
    for (ExprId m : group) {
      std::string scale;
      ExprId later = kNoExpr, other = kNoExpr;
      for (ExprId a : expr_arg_vector(m)) {
        if (!series_.count(a)) {
          scale += (scale.empty() ? "" : " * ") + scalar(a);
          continue;
        }
        if (later == kNoExpr || a > later) {
          if (later != kNoExpr) other = later;
          later = a;
        } else {
          other = a;
        }
      }
      shared = array_of_.at(later);
      std::string v = array_of_.count(m) ? array_of_.at(m) : array("v");
      array_of_[m] = v;
      outs += v + ", ";
      scales += (scale.empty() ? std::string("1") : "(" + scale + ")") + ", ";
      others += array_of_.at(other) + ", ";
    }
    line(tc_ + "product" + std::to_string(group.size()) + "(" + outs + scales + shared + ", " +
         others + "k);");
    return true;
  }

  // Coefficient k of x1^2 + x2^2 + ...: sum_sq3 and sum_sq2 over its terms
  // in threes.
  std::string sum_of_squares(const std::vector<ExprId> &xs) {
    std::string s;
    for (size_t i = 0; i < xs.size();) {
      size_t m = xs.size() - i == 2 || xs.size() - i == 4 ? 2 : 3;
      if (xs.size() - i == 1) m = 1;
      std::string term;
      if (m == 1)
        term = tc_ + "square(" + array_of_.at(xs[i]) + ", k)";
      else {
        term = tc_ + "sum_sq" + std::to_string(m) + "(";
        for (size_t j = 0; j < m; ++j)
          term += array_of_.at(xs[i + j]) + ", ";
        term += "k)";
      }
      s += (s.empty() ? "" : " + ") + term;
      i += m;
    }
    return s;
  }

  // A fresh coefficient array, declared at the top of the function; its
  // rank is when its coefficient k is computed in order k.
  std::string array(const std::string &prefix) {
    std::string name = prefix + std::to_string(narrays_++);
    arrays_.push_back(name);
    rank_[name] = static_cast<int>(narrays_);
    return name;
  }

  // The C scalar holding a constant node's value.
  std::string scalar(ExprId id) {
    auto it = scalar_.find(id);
    if (it != scalar_.end()) return it->second;
    std::string name = "k" + std::to_string(scalar_.size());
    scalar_[id] = name;
    constants_.push_back(id);
    constant_names_.push_back(name);
    return name;
  }

  // A constant node spread into a coefficient array (value, 0, 0, ...).
  std::string spread(ExprId id) {
    auto it = spread_.find(id);
    if (it != spread_.end()) return it->second;
    std::string name = array("s");
    spread_[id] = name;
    spread_inits_ +=
        "  for (int j = 0; j <= order; ++j) " + name + "[j] = j ? 0 : " + scalar(id) + ";\n";
    return name;
  }

  // The coefficient array of any node: its own, or a constant spread.
  std::string coefficients(ExprId id) { return series_.count(id) ? array_of_.at(id) : spread(id); }

  // Coefficient k of any node as a C expression.
  std::string coefficient_k(ExprId id) {
    if (series_.count(id)) return array_of_.at(id) + "[k]";
    return "(k == 0 ? " + scalar(id) + " : 0)";
  }

  void line(const std::string &s) { statements_.push_back(s); }

  // Emit the statements computing coefficient k of series node id.
  bool emit_node(ExprId id, std::string *why_not) {
    const ExprNode &n = expr_node(id);
    if (n.kind == ExprKind::Symbol) {
      // (Storing coefficient k + 1 into the input's array where it is
      // computed, at the end of order k, instead of this copy from c saved
      // 2% on Kepler but cost 45% on ten bodies.)
      std::string v = array("x");
      array_of_[id] = v;
      rank_[v] = -1; // loaded first in each order
      line(v + "[k] = c[k * " + std::to_string(t_.inputs.size()) + " + " +
           std::to_string(input_.at(n.sym)) + "];");
      return true;
    }
    if (array_of_.count(id)) return true; // a partner: sin/cos, sinh/cosh, a solve's components
    if (n.kind == ExprKind::Call) {
      if (is_solve_node(id) && !is_interpreted_solve(id)) return emit_solve(id);
      *why_not =
          is_solve_node(id) ? "a linear solve outside a kernel" : "a call of an unknown function";
      return false;
    }
    Op op = n.op;
    std::vector<ExprId> args = expr_arg_vector(id);
    std::string v = array("v");
    array_of_[id] = v;
    if (emit_product_group(id)) return true;
    if (auto it = square_sums_.find(id); it != square_sums_.end()) {
      line(v + "[k] = " + sum_of_squares(it->second) + ";");
      return true;
    }
    switch (op) {
    case Op::Add:
    case Op::Sub: return emit_sum(v, op, args);
    case Op::Mul: return emit_product(v, args);
    case Op::Div: return emit_quotient(v, args);
    case Op::Expt: return emit_power(id, v, args, why_not);
    case Op::Sqrt: line(tc_ + "sqrt(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Exp: line(tc_ + "exp(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Log: line(tc_ + "log(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Sin:
    case Op::Cos: return emit_pair(id, v, Op::Sin, Op::Cos, tc_ + "sincos", args[0]);
    case Op::Sinh:
    case Op::Cosh: return emit_pair(id, v, Op::Sinh, Op::Cosh, tc_ + "sinhcosh", args[0]);
    case Op::Atan: {
      std::string y = coefficients(args[0]);
      std::string x = args.size() == 2 ? coefficients(args[1]) : spread(expr_integer(1));
      line(tc_ + "atan2(" + v + ", " + y + ", " + x + ", " + array("r") + ", k);");
      return true;
    }
    case Op::Abs:
      line(v + "[k] = " + coefficients(args[0]) + "[0] < 0 ? -" + coefficient_k(args[0]) + " : " +
           coefficient_k(args[0]) + ";");
      return true;
    case Op::Tan:
    case Op::Asin:
    case Op::Acos: *why_not = std::string("the operation ") + op_info(op).scheme_name; return false;
    }
    *why_not = "an operation without a Taylor recurrence";
    return false;
  }

  // + and -: termwise; constants only in coefficient 0.
  bool emit_sum(const std::string &v, Op op, const std::vector<ExprId> &args) {
    std::string series, constant;
    for (size_t i = 0; i < args.size(); ++i) {
      bool minus = op == Op::Sub && (i > 0 || args.size() == 1);
      std::string sign = minus ? " - " : " + ";
      if (series_.count(args[i]))
        series += sign + array_of_.at(args[i]) + "[k]";
      else
        constant += sign + scalar(args[i]);
    }
    std::string s = series.substr(0, 3) == " + " ? series.substr(3) : "0.0" + series;
    if (!constant.empty()) s += " + (k == 0 ? 0.0" + constant + " : 0.0)";
    line(v + "[k] = " + s + ";");
    return true;
  }

  // *: the constant factors' product times the Cauchy product of the
  // series factors (through intermediate arrays when there are several).
  bool emit_product(const std::string &v, const std::vector<ExprId> &args) {
    std::string constant;
    std::vector<std::string> factors;
    for (ExprId a : args) {
      if (series_.count(a))
        factors.push_back(array_of_.at(a));
      else
        constant += (constant.empty() ? "" : " * ") + scalar(a);
    }
    std::string scale = constant.empty() ? "" : "(" + constant + ") * ";
    if (factors.empty()) { // a product of parameters, a series in extended precision
      line(v + "[k] = k == 0 ? " + constant + " : 0;");
      return true;
    }
    if (factors.size() == 1) {
      line(v + "[k] = " + scale + factors[0] + "[k];");
      return true;
    }
    std::string acc = factors[0];
    for (size_t i = 1; i + 1 < factors.size(); ++i) {
      std::string p = array("p");
      line(p + "[k] = " + product(acc, factors[i]) + ";");
      acc = p;
    }
    line(v + "[k] = " + scale + product(acc, factors.back()) + ";");
    return true;
  }

  // x = M^-1 b: all n components at once, by the solve recurrence, into
  // arrays that the component nodes of the same M and b share.
  bool emit_solve(ExprId id) {
    const size_t n = solve_dimension(id);
    std::string g = "g" + std::to_string(nsolves_++);
    std::string entries, rhs, components;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        entries += (entries.empty() ? "" : ", ") + coefficients(solve_matrix_entry(id, i, j));
    for (size_t i = 0; i < n; ++i)
      rhs += (rhs.empty() ? "" : ", ") + coefficients(solve_rhs_entry(id, i));
    // The component nodes of this M and b: the solve's arguments with
    // another component number.
    std::vector<ExprId> args = expr_arg_vector(id);
    for (size_t c = 0; c < n; ++c) {
      args[0] = expr_integer(static_cast<int64_t>(c));
      ExprId component = expr_call(expr_node(id).head, args.data(), args.size());
      std::string x = array("x");
      if (std::binary_search(nodes_.begin(), nodes_.end(), component)) array_of_[component] = x;
      components += (components.empty() ? "" : ", ") + x;
    }
    const std::string size = std::to_string(n);
    tables_ += "  const " + real_ + " *" + g + "_m[] = {" + entries + "};\n";
    tables_ += "  const " + real_ + " *" + g + "_b[] = {" + rhs + "};\n";
    tables_ += "  " + real_ + " *" + g + "_x[] = {" + components + "};\n";
    tables_ +=
        "  " + real_ + " " + g + "_lu[" + std::to_string(n * n) + "], " + g + "_r[" + size + "];\n";
    tables_ += "  int " + g + "_pivots[" + size + "];\n";
    line(tc_ + "solve(" + size + ", " + g + "_m, " + g + "_b, " + g + "_x, " + g + "_lu, " + g +
         "_pivots, " + g + "_r, k);");
    return true;
  }

  // Coefficient k of a * b: a square by its symmetric half; the factor
  // computed later in an order first (the support adds its newest term last).
  std::string product(const std::string &a, const std::string &b) {
    if (a == b) return tc_ + "square(" + a + ", k)";
    const bool b_later = rank_of(b) > rank_of(a);
    return tc_ + "product(" + (b_later ? b : a) + ", " + (b_later ? a : b) + ", k)";
  }

  // When coefficient k of an array is computed (spread constants: before
  // the loop).
  int rank_of(const std::string &a) const {
    auto it = rank_.find(a);
    return it == rank_.end() || a[0] == 's' ? -2 : it->second;
  }

  // /: by a constant termwise, by a series by the quotient recurrence.
  bool emit_quotient(const std::string &v, const std::vector<ExprId> &args) {
    ExprId num = args.size() == 1 ? expr_integer(1) : args[0];
    // (/ a b c): a / b / c, each division in turn.
    std::string acc_k = coefficient_k(num), acc;
    for (size_t i = args.size() == 1 ? 0 : 1; i < args.size(); ++i) {
      bool last = i + 1 == args.size();
      std::string q = last ? v : array("q");
      if (series_.count(args[i]))
        line(tc_ + "quotient(" + q + ", " + acc_k + ", " + array_of_.at(args[i]) + ", k);");
      else
        line(q + "[k] = " + acc_k + " / " + scalar(args[i]) + ";");
      acc_k = q + "[k]";
    }
    return true;
  }

  // expt with a constant exponent: products for small positive integers,
  // the power recurrence otherwise (of the root's argument for a power of a
  // root, at half the exponent).
  bool emit_power(ExprId id, const std::string &v, const std::vector<ExprId> &args,
                  std::string *why_not) {
    if (series_.count(args[1])) {
      *why_not = "expt with an exponent that depends on the state";
      return false;
    }
    if (is_power_of_root(id)) {
      ExprId half = expr_from_number(num_div(expr_number_value(args[1]), Value::fixnum(2)));
      line(tc_ + "power(" + v + ", " + coefficients(expr_arg(args[0], 0)) + ", " + scalar(half) +
           ", k);");
      return true;
    }
    std::string base = coefficients(args[0]);
    int64_t n;
    if (expr_get_int64(args[1], &n) && n >= 1 && n <= kMaxProductPower) {
      emit_integer_power(v, base, static_cast<uint64_t>(n));
      return true;
    }
    line(tc_ + "power(" + v + ", " + base + ", " + scalar(args[1]) + ", k);");
    return true;
  }

  // base^m into v by binary powering: squares of base, multiplied in.
  void emit_integer_power(const std::string &v, const std::string &base, uint64_t m) {
    if (m == 1) {
      line(v + "[k] = " + base + "[k];");
      return;
    }
    std::string square = base, acc;
    for (;;) {
      if (m & 1) {
        m >>= 1;
        std::string target = m == 0 ? v : array("p");
        if (acc.empty())
          line(target + "[k] = " + square + "[k];");
        else
          line(target + "[k] = " + product(acc, square) + ";");
        acc = target;
      } else {
        m >>= 1;
      }
      if (m == 0) return;
      bool final_square = m == 1 && acc.empty();
      std::string next = final_square ? v : array("p");
      line(next + "[k] = " + product(square, square) + ";");
      square = next;
      if (final_square) return;
    }
  }

  // sin and cos (or sinh and cosh) of one argument are computed together;
  // the partner that is not in the DAG gets an array of its own.
  bool emit_pair(ExprId id, const std::string &v, Op first, Op second, const std::string &fn,
                 ExprId arg) {
    bool is_first = expr_is_apply(id, first);
    ExprId other = expr_apply(is_first ? second : first, {arg});
    std::string partner;
    if (std::binary_search(nodes_.begin(), nodes_.end(), other)) {
      partner = array("v");
      array_of_[other] = partner;
    } else {
      partner = array("w");
    }
    std::string a = is_first ? v : partner, b = is_first ? partner : v;
    line(fn + "(" + a + ", " + b + ", " + coefficients(arg) + ", k);");
    return true;
  }

  // The function; for a small system whose order is known (known_order >
  // 0), also a copy of it for that order alone, with the order loop
  // unrolled, which the function calls for that order (see
  // kMaxUnrolledNodeOrders).
  std::string assemble(const std::string &c_name, int known_order) {
    bool unrolled = known_order > 0 && known_order <= SICM_ODE_TAYLOR_MAX_ORDER && nsolves_ == 0 &&
                    arrays_.size() * static_cast<size_t>(known_order) <= kMaxUnrolledNodeOrders;
    if (!unrolled) return function(c_name, "", "order");
    std::string order = std::to_string(known_order);
    std::string fixed = c_name + "_order" + order;
    return "static " + function(fixed, "", order) + "\n" +
           function(c_name,
                    "  if (order == " + order + ") {\n    " + fixed +
                        "(in, order, c, p);\n    return;\n  }\n",
                    "order");
  }

  // The function named c_name (its type and name, less `static`), beginning
  // with `prologue`, whose order loop runs to `order_bound`: "order", or a
  // number for the unrolled copy.
  std::string function(const std::string &c_name, const std::string &prologue,
                       const std::string &order_bound) {
    const size_t n = t_.inputs.size();
    // c_{k+1} = f_k / (k + 1): one division for the whole order, each
    // component a multiplication by its reciprocal (a division costs as
    // much as a dozen multiplications, and there is one per component).
    const std::string reciprocal =
        "    const " + real_ + " reciprocal = (" + real_ + ")1 / (k + 1);\n";
    std::vector<std::string> outs;
    for (size_t i = 0; i < n; ++i)
      outs.push_back("c[(k + 1) * " + std::to_string(n) + " + " + std::to_string(i) +
                     "] = " + coefficient_k(t_.outputs[i]) + " * reciprocal;");
    std::string f = "void " + c_name + "(const " + real_ + " *in, int order, " + real_ +
                    " *c, const double *p) {\n";
    f += "  (void)p;\n";
    f += prologue;
    f += "  enum { K = " + std::to_string(SICM_ODE_TAYLOR_MAX_ORDER + 1) + " };\n";
    f += "  if (order > K - 1) order = K - 1;\n";
    f += "  if (order < 0) order = 0;\n";
    if (!constants_.empty()) {
      for (const std::string &name : constant_names_)
        f += "  " + real_ + " " + name + ";\n";
      if (extended_) {
        for (size_t i = 0; i < constants_.size(); ++i)
          f += "  " + constant_names_[i] + " = " + extended_constant(constants_[i]) + ";\n";
      } else {
        f += emit_c_assignments(constants_, constant_names_, spell_symbol(), "u", "");
      }
    }
    TaylorLoops loops;
    if (tables_.empty() && order_bound == "order") { // (a solve's tables name its arrays)
      std::vector<std::string> spreads;
      for (const auto &[id, name] : spread_)
        spreads.push_back(name);
      std::vector<std::string> statements = statements_;
      statements.insert(statements.end(), outs.begin(), outs.end());
      loops = plan_taylor_loops(statements, arrays_, spreads, constant_names_, "cf", "kc");
    }
    if (!loops.empty()) return "#include <stdlib.h>\n" + f + pooled(loops, reciprocal);
    for (const std::string &a : arrays_)
      f += "  " + real_ + " " + a + "[K];\n";
    f += tables_;
    f += spread_inits_;
    f += "  for (int i = 0; i < " + std::to_string(n) + "; ++i) c[i] = in[i];\n";
    std::string body;
    for (const std::string &s : statements_)
      body += "    " + s + "\n";
    body += reciprocal;
    for (const std::string &s : outs)
      body += "    " + s + "\n";
    if (order_bound != "order") f += "  _Pragma(\"GCC unroll " + order_bound + "\")\n";
    f += "  for (int k = 0; k < " + order_bound + "; ++k) {\n" + body + "  }\n}\n";
    return f;
  }

  // The rest of the function when its statements are loops over the rows of one pool of
  // coefficients (codegen/taylor_loops.hpp), the outputs' among them (after reciprocal, the
  // declaration they read, now first in the order). The pool is on the heap (100 bodies'
  // is 34 MB, more than a stack), allocated at a thread's first call and kept for its
  // later ones (the runtime keeps its pool threads too): allocated and freed in each call,
  // 100 bodies over 5 time units ran in 1.7 s instead of 0.6 s, the pages of a block that
  // large being mapped afresh each time. When it cannot be allocated, every coefficient
  // past the state is NaN, which fails the step.
  std::string pooled(const TaylorLoops &loops, const std::string &reciprocal) {
    const std::string n = std::to_string(t_.inputs.size());
    std::string f = loops.tables;
    if (loops.scalar_array) {
      f += "  const " + real_ + " kc[] = {";
      for (size_t i = 0; i < constant_names_.size(); ++i)
        f += (i ? ", " : "") + constant_names_[i];
      f += "};\n";
    }
    f += "  static _Thread_local " + real_ + " (*cf)[K];\n";
    f += "  if (!cf) cf = malloc(sizeof(" + real_ + "[K]) * " + std::to_string(loops.rows) + ");\n";
    f += "  if (!cf) {\n";
    f += "    for (int i = 0; i < (order + 1) * " + n + "; ++i) c[i] = i < " + n +
         " ? in[i] : NAN;\n";
    f += "    return;\n  }\n";
    f += loops.in_pool(spread_inits_);
    f += "  for (int i = 0; i < " + n + "; ++i) c[i] = in[i];\n";
    f += "  for (int k = 0; k < order; ++k) {\n" + reciprocal + loops.body + "  }\n}\n";
    return f;
  }

  // A symbol that is not an input (a run-time parameter of a built
  // program) as the caller spells it; an unknown one makes the emitter
  // give up, since it cannot be evaluated here.
  std::function<std::string(Symbol *)> spell_symbol() {
    return [this](Symbol *sym) -> std::string {
      // The trace's own parameters are the kernel's p[j].
      for (size_t j = 0; j < t_.param_symbols.size(); ++j)
        if (t_.param_symbols[j] == sym) return "p[" + std::to_string(j) + "]";
      std::string s = spell_ ? spell_(sym) : "";
      if (s.empty()) {
        if (why_not_.empty()) why_not_ = "a value that is not known where the coefficients are";
        return "0.0";
      }
      return s;
    };
  }

  // A constant of the extended function, in long double: a number exactly
  // (an integer or a ratio of integers of at most 64 bits as written, other
  // numbers as the double they round to, as the double kernels have them),
  // a parameter converted from the double it is.
  std::string extended_constant(ExprId id) {
    const ExprNode &n = expr_node(id);
    if (n.kind == ExprKind::Symbol) return "(long double)" + spell_symbol()(n.sym);
    if (n.kind == ExprKind::Rational) {
      mpq_srcptr q = expr_rat(id);
      if (mpz_sizeinbase(mpq_numref(q), 2) <= 64 && mpz_sizeinbase(mpq_denref(q), 2) <= 64) {
        auto digits = [](mpz_srcptr z) {
          std::string s(mpz_sizeinbase(z, 10) + 2, '\0');
          mpz_get_str(s.data(), 10, z);
          s.resize(std::strlen(s.c_str()));
          return s + ".0L";
        };
        std::string num = digits(mpq_numref(q));
        if (mpz_cmp_ui(mpq_denref(q), 1) == 0) return "(" + num + ")";
        return "(" + num + " / " + digits(mpq_denref(q)) + ")";
      }
    }
    double d = n.kind == ExprKind::Flonum ? n.d : to_double(expr_number_value(id));
    if (!std::isfinite(d)) return "(long double)" + c_double_literal(d);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%aL", d);
    return buf;
  }

  const Trace &t_;
  const bool extended_;
  SymbolSpeller spell_;
  const std::string real_, tc_;
  std::string why_not_;
  std::unordered_map<Symbol *, size_t> input_;
  std::unordered_map<std::string, int> rank_;
  std::vector<ExprId> nodes_; // reachable from the outputs, increasing ids
  std::unordered_set<ExprId> series_;
  std::unordered_map<ExprId, std::string> array_of_, scalar_, spread_;
  std::vector<ExprId> constants_;
  std::vector<std::string> constant_names_, arrays_;
  std::vector<std::string> statements_; // order k's, one C statement each
  std::string spread_inits_, tables_;
  size_t narrays_ = 0, nsolves_ = 0;
  std::unordered_map<ExprId, size_t> users_; // parents among nodes_, plus outputs
  std::unordered_set<ExprId> absorbed_;      // computed inside a fused recurrence
  std::unordered_map<ExprId, std::vector<ExprId>> square_sums_;   // root -> squared terms
  std::unordered_map<ExprId, std::vector<ExprId>> product_group_; // first member -> members
};

} // namespace

std::string emit_taylor_function(const Trace &t, const std::string &c_name, std::string *why_not,
                                 TaylorPrecision precision, const SymbolSpeller &spell,
                                 int known_order) {
  std::string out, reason;
  if (TaylorEmitter(t, precision, spell).emit(c_name, known_order, &out, &reason)) return out;
  if (why_not) *why_not = reason;
  return "";
}

// Each helper computes coefficient k of its result from coefficients 0..k
// of its arguments and 0..k-1 of the result (k = 0: the value itself).
//
// The orders form one chain of dependences (coefficient k of every node
// waits on coefficient k of the state, which waits on coefficient k - 1 of
// the outputs), and that chain is what a small system's expansion waits
// on. So the terms of the newest coefficients (u_k, and a_k b_0 and a_0 b_k
// of a product) are kept out of the convolution sums and added last: the
// sums of the older terms then run ahead, off the chain, out of order.
// Off the chain, a sum's own latency matters less than the set-up of its
// loop, these loops being short (k terms): two partial sums, not four, and
// weights (j, or (alpha + 1) j - k of a power) by increments rather than
// converted from j. Kepler's expansion at order 15, in a harness: 450 ns
// with the newest terms inside four partial sums, 280 ns outside, 230 ns
// with two sums and incremental weights. (The order of the additions
// changes the last bits, not the accuracy.) Written once over the
// macros REAL, TC(name) and POW, SQRT, ... and instantiated for double and
// long double (taylor-extended) by defining them around it.
static const char kTaylorSupport[] = R"(
/* sum_{j=lo}^{hi} a[j] b[k-j], two partial sums. */
static inline REAL TC(dot)(const REAL *a, const REAL *b, int lo, int hi, int k) {
  REAL s0 = 0, s1 = 0;
  int j = lo;
  for (; j + 1 <= hi; j += 2) {
    s0 += a[j] * b[k - j];
    s1 += a[j + 1] * b[k - j - 1];
  }
  if (j <= hi) s0 += a[j] * b[k - j];
  return s0 + s1;
}

/* sum_{j=lo}^{hi} (w + (j - lo) dw) a[j] b[k-j]: the weights by increments
 * (exact where they are small integers or halves, as they are in jdot and
 * in the powers of the book's problems). */
static inline REAL TC(wdot)(const REAL *a, const REAL *b, int lo, int hi, int k, REAL w, REAL dw) {
  REAL s0 = 0, s1 = 0, w0 = w, w1 = w + dw;
  const REAL step = 2 * dw;
  int j = lo;
  for (; j + 1 <= hi; j += 2) {
    s0 += w0 * a[j] * b[k - j];
    s1 += w1 * a[j + 1] * b[k - j - 1];
    w0 += step;
    w1 += step;
  }
  if (j <= hi) s0 += w0 * a[j] * b[k - j];
  return s0 + s1;
}

/* sum_{j=lo}^{hi} j a[j] b[k-j] */
static inline REAL TC(jdot)(const REAL *a, const REAL *b, int lo, int hi, int k) {
  return TC(wdot)(a, b, lo, hi, k, lo, 1);
}

/* a * b where a's coefficient k is computed after b's (the emitter orders
 * them): its term is added last. */
static inline REAL TC(product)(const REAL *a, const REAL *b, int k) {
  if (k == 0) return a[0] * b[0];
  return (TC(dot)(a, b, 1, k - 1, k) + a[0] * b[k]) + a[k] * b[0];
}

/* a * a: the convolution is symmetric, half the products. */
static inline REAL TC(square)(const REAL *a, int k) {
  if (k == 0) return a[0] * a[0];
  const REAL *b = a;
  REAL older = 2 * TC(dot)(a, b, 1, (k - 1) / 2, k) + (k % 2 == 0 ? a[k / 2] * a[k / 2] : 0);
  return older + (2 * a[0]) * a[k];
}

/* a^2 + b^2 (+ c^2): the squares' symmetric halves in one loop, their
 * newest terms last. */
static inline REAL TC(sum_sq2)(const REAL *a, const REAL *b, int k) {
  if (k == 0) return a[0] * a[0] + b[0] * b[0];
  REAL s = 0;
  for (int j = 1; j <= (k - 1) / 2; ++j)
    s += a[j] * a[k - j] + b[j] * b[k - j];
  s *= 2;
  if (k % 2 == 0) s += a[k / 2] * a[k / 2] + b[k / 2] * b[k / 2];
  return s + ((2 * a[0]) * a[k] + (2 * b[0]) * b[k]);
}

static inline REAL TC(sum_sq3)(const REAL *a, const REAL *b, const REAL *c, int k) {
  if (k == 0) return a[0] * a[0] + b[0] * b[0] + c[0] * c[0];
  REAL s = 0;
  for (int j = 1; j <= (k - 1) / 2; ++j)
    s += a[j] * a[k - j] + b[j] * b[k - j] + c[j] * c[k - j];
  s *= 2;
  if (k % 2 == 0) s += a[k / 2] * a[k / 2] + b[k / 2] * b[k / 2] + c[k / 2] * c[k / 2];
  return s + ((2 * a[0]) * a[k] + (2 * b[0]) * b[k] + (2 * c[0]) * c[k]);
}

/* v_i = s_i (a * b_i) for two or three series b_i and one a, computed
 * after them (its newest term added last, as in product): one loop
 * reading a once. */
static inline void TC(product2)(REAL *v1, REAL *v2, REAL s1, REAL s2, const REAL *a,
                                const REAL *b1, const REAL *b2, int k) {
  if (k == 0) {
    v1[0] = s1 * (a[0] * b1[0]);
    v2[0] = s2 * (a[0] * b2[0]);
    return;
  }
  REAL t1 = 0, t2 = 0;
  for (int j = 1; j < k; ++j) {
    t1 += a[j] * b1[k - j];
    t2 += a[j] * b2[k - j];
  }
  v1[k] = s1 * ((t1 + a[0] * b1[k]) + a[k] * b1[0]);
  v2[k] = s2 * ((t2 + a[0] * b2[k]) + a[k] * b2[0]);
}

static inline void TC(product3)(REAL *v1, REAL *v2, REAL *v3, REAL s1, REAL s2, REAL s3,
                                const REAL *a, const REAL *b1, const REAL *b2, const REAL *b3,
                                int k) {
  if (k == 0) {
    v1[0] = s1 * (a[0] * b1[0]);
    v2[0] = s2 * (a[0] * b2[0]);
    v3[0] = s3 * (a[0] * b3[0]);
    return;
  }
  REAL t1 = 0, t2 = 0, t3 = 0;
  for (int j = 1; j < k; ++j) {
    t1 += a[j] * b1[k - j];
    t2 += a[j] * b2[k - j];
    t3 += a[j] * b3[k - j];
  }
  v1[k] = s1 * ((t1 + a[0] * b1[k]) + a[k] * b1[0]);
  v2[k] = s2 * ((t2 + a[0] * b2[k]) + a[k] * b2[0]);
  v3[k] = s3 * ((t3 + a[0] * b3[k]) + a[k] * b3[0]);
}

/* q = a / b, given a's coefficient k. */
static inline void TC(quotient)(REAL *q, REAL a_k, const REAL *b, int k) {
  q[k] = ((a_k - TC(dot)(b, q, 1, k - 1, k)) - b[k] * q[0]) / b[0];
}

/* v = u^alpha: u v' = alpha u' v, so
 * k u0 v_k = sum_{i=1}^{k} (alpha i - (k - i)) u_i v_{k-i}
 *          = sum_{i=1}^{k} ((alpha + 1) i - k) u_i v_{k-i}. */
static inline void TC(power)(REAL *v, const REAL *u, REAL alpha, int k) {
  if (k == 0) {
    v[0] = POW(u[0], alpha);
    return;
  }
  /* The term of u_k, (alpha + 1) k - k = alpha k, apart. */
  v[k] = TC(wdot)(u, v, 1, k - 1, k, alpha - (k - 1), alpha + 1) / (k * u[0]) +
         (alpha * v[0] / u[0]) * u[k];
}

static inline void TC(sqrt)(REAL *v, const REAL *u, int k) {
  if (k == 0) {
    v[0] = SQRT(u[0]);
    return;
  }
  /* u_k = sum_{j=0}^{k} v_j v_{k-j}: the inner terms, symmetric. */
  const REAL *a = v, *b = v;
  REAL inner = 2 * TC(dot)(a, b, 1, (k - 1) / 2, k) + (k % 2 == 0 ? v[k / 2] * v[k / 2] : 0);
  v[k] = (u[k] - inner) / (2 * v[0]);
}

static inline void TC(exp)(REAL *v, const REAL *u, int k) {
  if (k == 0) {
    v[0] = EXP(u[0]);
    return;
  }
  v[k] = TC(jdot)(u, v, 1, k - 1, k) / k + u[k] * v[0];
}

/* u v' = u': k u0 v_k = k u_k - sum_{j=1}^{k-1} j v_j u_{k-j}. */
static inline void TC(log)(REAL *v, const REAL *u, int k) {
  if (k == 0) {
    v[0] = LOG(u[0]);
    return;
  }
  v[k] = (u[k] - TC(jdot)(v, u, 1, k - 1, k) / k) / u[0];
}

/* The pair s, c with s' = c u' and c' = sign s u' (sin and cos: sign -1;
 * sinh and cosh: sign +1), at order k >= 1. */
static inline void TC(pair)(REAL *s, REAL *c, const REAL *u, int k, REAL sign) {
  REAL a = TC(jdot)(u, c, 1, k - 1, k) / k, b = TC(jdot)(u, s, 1, k - 1, k) / k;
  s[k] = a + u[k] * c[0];
  c[k] = sign * (b + u[k] * s[0]);
}

static inline void TC(sincos)(REAL *s, REAL *c, const REAL *u, int k) {
  if (k == 0) {
    s[0] = SIN(u[0]);
    c[0] = COS(u[0]);
  } else {
    TC(pair)(s, c, u, k, -1);
  }
}

static inline void TC(sinhcosh)(REAL *s, REAL *c, const REAL *u, int k) {
  if (k == 0) {
    s[0] = SINH(u[0]);
    c[0] = COSH(u[0]);
  } else {
    TC(pair)(s, c, u, k, 1);
  }
}

/* v = atan2(y, x): r v' = x y' - y x' with r = x^2 + y^2 (kept in r):
 * k r0 v_k = sum_{j=0}^{k-1} (k - j) (x_j y_{k-j} - y_j x_{k-j})
 *            - sum_{j=1}^{k-1} (k - j) r_j v_{k-j}. */
static inline void TC(atan2)(REAL *v, const REAL *y, const REAL *x, REAL *r, int k) {
  r[k] = TC(square)(x, k) + TC(square)(y, k);
  if (k == 0) {
    v[0] = ATAN2(y[0], x[0]);
    return;
  }
  /* with i = k - j: sum_{i=1}^{k} i (x_{k-i} y_i - y_{k-i} x_i), and
   * sum_{i=1}^{k-1} i v_i r_{k-i} */
  REAL d = TC(jdot)(y, x, 1, k, k) - TC(jdot)(x, y, 1, k, k) - TC(jdot)(v, r, 1, k - 1, k);
  v[k] = d / (k * r[0]);
}
/* x = M^-1 b for series M (n x n, row-major) and b, by M x = b order by
 * order: M_0 x_k = b_k - sum_{j=1}^{k} M_j x_{k-j}. At k = 0, M_0 is
 * factored (LU with partial pivoting) into lu and pivots, kept for the
 * other orders; a singular M_0 gives NaN coefficients. */
static inline void TC(solve)(int n, const REAL *const *m, const REAL *const *b, REAL *const *x,
                            REAL *lu, int *pivots, REAL *r, int k) {
  if (k == 0) {
    for (int i = 0; i < n * n; ++i) lu[i] = m[i][0];
    for (int c = 0; c < n; ++c) {
      int p = c;
      for (int i = c + 1; i < n; ++i)
        if (FABS(lu[i * n + c]) > FABS(lu[p * n + c])) p = i;
      pivots[c] = p;
      for (int j = 0; p != c && j < n; ++j) {
        REAL t = lu[c * n + j];
        lu[c * n + j] = lu[p * n + j];
        lu[p * n + j] = t;
      }
      if (lu[c * n + c] == 0) lu[c * n + c] = NAN;
      for (int i = c + 1; i < n; ++i) {
        REAL f = lu[i * n + c] /= lu[c * n + c];
        for (int j = c + 1; j < n; ++j) lu[i * n + j] -= f * lu[c * n + j];
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    REAL s = b[i][k];
    for (int j = 0; j < n; ++j) s -= TC(dot)(m[i * n + j], x[j], 1, k, k);
    r[i] = s;
  }
  for (int c = 0; c < n; ++c) {
    REAL t = r[c];
    r[c] = r[pivots[c]];
    r[pivots[c]] = t;
  }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < i; ++j) r[i] -= lu[i * n + j] * r[j];
  for (int i = n - 1; i >= 0; --i) {
    for (int j = i + 1; j < n; ++j) r[i] -= lu[i * n + j] * r[j];
    r[i] /= lu[i * n + i];
    x[i][k] = r[i];
  }
}
)";

namespace {

// The macros kTaylorSupport is written over, for one precision.
const char *const kMathNames[] = {"POW",  "SQRT", "EXP", "LOG",   "SINH",
                                  "COSH", "SIN",  "COS", "ATAN2", "FABS"};

std::string instantiate(TaylorPrecision precision) {
  const bool extended = precision == TaylorPrecision::Extended;
  std::string defines = std::string("#define REAL ") + (extended ? "long double" : "double") +
                        "\n#define TC(name) " + (extended ? "sicm_tcl_" : "sicm_tc_") + "##name\n";
  std::string undefs = "#undef REAL\n#undef TC\n";
  for (const char *name : kMathNames) {
    std::string c = name;
    for (char &ch : c)
      ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    defines += std::string("#define ") + name + " " + c + (extended ? "l" : "") + "\n";
    undefs += std::string("#undef ") + name + "\n";
  }
  return defines + kTaylorSupport + undefs;
}

} // namespace

std::string c_taylor_support(TaylorPrecision precision) {
  return std::string("/* Taylor-coefficient recurrences (sicm's Taylor emitter), in ") +
         (precision == TaylorPrecision::Extended ? "long double" : "double") + ". */\n" +
         instantiate(precision) + "\n";
}

} // namespace sicm
