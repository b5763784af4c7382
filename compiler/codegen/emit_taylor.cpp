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
// Limits: tan, asin, acos, variable exponents and linear solves have no
// recurrence here (see emit_taylor.hpp); the caller says so and integrates
// another way.
#include "codegen/emit_taylor.hpp"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "algebra/linear_solve.hpp"
#include "algebra/symbolic.hpp"
#include "codegen/emit_c.hpp"
#include "eval/number.hpp"
#include "sicm/runtime.h"
#include "syntax/error.hpp"

namespace sicm {

namespace {

// Positive integer powers up to this are written as products.
constexpr int64_t kMaxProductPower = 64;

// (expt u 0): a constant 1 whatever u is (the C emitter writes it as 1.0).
bool is_zeroth_power(ExprId id) {
  return expr_is_apply(id, Op::Expt) && expr_is_exact_zero(expr_arg(id, 1));
}

class TaylorEmitter {
public:
  TaylorEmitter(const Trace &t) : t_(t) {
    for (size_t i = 0; i < t.inputs.size(); ++i)
      input_[t.inputs[i]] = i;
  }

  bool emit(const std::string &c_name, std::string *out, std::string *why_not) {
    if (t_.inputs.size() != t_.outputs.size()) {
      *why_not = "the derivative has " + std::to_string(t_.outputs.size()) +
                 " components but the state " + std::to_string(t_.inputs.size());
      return false;
    }
    collect();
    for (ExprId id : nodes_)
      if (series_.count(id) && !emit_node(id, why_not)) return false;
    *out = assemble(c_name);
    return true;
  }

private:
  // The nodes reachable from the outputs in increasing id order, and which
  // of them depend on the state (series_).
  void collect() {
    expr_visit(t_.outputs, [&](ExprId id) {
      nodes_.push_back(id);
      return true;
    });
    std::sort(nodes_.begin(), nodes_.end());
    for (ExprId id : nodes_) {
      ExprKind kind = expr_kind(id);
      bool depends = false;
      if (kind == ExprKind::Symbol) depends = input_.count(expr_node(id).sym) > 0;
      if ((kind == ExprKind::Apply || kind == ExprKind::Call) && !is_zeroth_power(id))
        for (ExprId a : expr_arg_vector(id))
          depends = depends || series_.count(a) > 0;
      if (depends) series_.insert(id);
    }
  }

  // A fresh coefficient array, declared at the top of the function.
  std::string array(const std::string &prefix) {
    std::string name = prefix + std::to_string(narrays_++);
    arrays_.push_back(name);
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
        "  for (int j = 0; j <= order; ++j) " + name + "[j] = j ? 0.0 : " + scalar(id) + ";\n";
    return name;
  }

  // The coefficient array of any node: its own, or a constant spread.
  std::string coefficients(ExprId id) { return series_.count(id) ? array_of_.at(id) : spread(id); }

  // Coefficient k of any node as a C expression.
  std::string coefficient_k(ExprId id) {
    if (series_.count(id)) return array_of_.at(id) + "[k]";
    return "(k == 0 ? " + scalar(id) + " : 0.0)";
  }

  void line(const std::string &s) { body_ += "    " + s + "\n"; }

  // Emit the statements computing coefficient k of series node id.
  bool emit_node(ExprId id, std::string *why_not) {
    const ExprNode &n = expr_node(id);
    if (n.kind == ExprKind::Symbol) {
      std::string v = array("x");
      array_of_[id] = v;
      line(v + "[k] = c[k * " + std::to_string(t_.inputs.size()) + " + " +
           std::to_string(input_.at(n.sym)) + "];");
      return true;
    }
    if (n.kind == ExprKind::Call) {
      *why_not = is_solve_node(id) ? "a linear solve (a division by a matrix of the state)"
                                   : "a call of an unknown function";
      return false;
    }
    if (array_of_.count(id)) return true; // the partner of a sin/cos or sinh/cosh pair
    Op op = n.op;
    std::vector<ExprId> args = expr_arg_vector(id);
    std::string v = array("v");
    array_of_[id] = v;
    switch (op) {
    case Op::Add:
    case Op::Sub: return emit_sum(v, op, args);
    case Op::Mul: return emit_product(v, args);
    case Op::Div: return emit_quotient(v, args);
    case Op::Expt: return emit_power(v, args, why_not);
    case Op::Sqrt: line("sicm_tc_sqrt(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Exp: line("sicm_tc_exp(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Log: line("sicm_tc_log(" + v + ", " + coefficients(args[0]) + ", k);"); return true;
    case Op::Sin:
    case Op::Cos: return emit_pair(id, v, Op::Sin, Op::Cos, "sicm_tc_sincos", args[0]);
    case Op::Sinh:
    case Op::Cosh: return emit_pair(id, v, Op::Sinh, Op::Cosh, "sicm_tc_sinhcosh", args[0]);
    case Op::Atan: {
      std::string y = coefficients(args[0]);
      std::string x = args.size() == 2 ? coefficients(args[1]) : spread(expr_integer(1));
      line("sicm_tc_atan2(" + v + ", " + y + ", " + x + ", " + array("r") + ", k);");
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
    if (factors.size() == 1) {
      line(v + "[k] = " + scale + factors[0] + "[k];");
      return true;
    }
    std::string acc = factors[0];
    for (size_t i = 1; i + 1 < factors.size(); ++i) {
      std::string p = array("p");
      line(p + "[k] = sicm_tc_product(" + acc + ", " + factors[i] + ", k);");
      acc = p;
    }
    line(v + "[k] = " + scale + "sicm_tc_product(" + acc + ", " + factors.back() + ", k);");
    return true;
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
        line("sicm_tc_quotient(" + q + ", " + acc_k + ", " + array_of_.at(args[i]) + ", k);");
      else
        line(q + "[k] = " + acc_k + " / " + scalar(args[i]) + ";");
      acc_k = q + "[k]";
    }
    return true;
  }

  // expt with a constant exponent: products for small positive integers,
  // the power recurrence otherwise.
  bool emit_power(const std::string &v, const std::vector<ExprId> &args, std::string *why_not) {
    if (series_.count(args[1])) {
      *why_not = "expt with an exponent that depends on the state";
      return false;
    }
    std::string base = coefficients(args[0]);
    int64_t n;
    if (expr_get_int64(args[1], &n) && n >= 1 && n <= kMaxProductPower) {
      emit_integer_power(v, base, static_cast<uint64_t>(n));
      return true;
    }
    line("sicm_tc_power(" + v + ", " + base + ", " + scalar(args[1]) + ", k);");
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
          line(target + "[k] = sicm_tc_product(" + acc + ", " + square + ", k);");
        acc = target;
      } else {
        m >>= 1;
      }
      if (m == 0) return;
      bool final_square = m == 1 && acc.empty();
      std::string next = final_square ? v : array("p");
      line(next + "[k] = sicm_tc_product(" + square + ", " + square + ", k);");
      square = next;
      if (final_square) return;
    }
  }

  // sin and cos (or sinh and cosh) of one argument are computed together;
  // the partner that is not in the DAG gets an array of its own.
  bool emit_pair(ExprId id, const std::string &v, Op first, Op second, const char *fn, ExprId arg) {
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
    line(std::string(fn) + "(" + a + ", " + b + ", " + coefficients(arg) + ", k);");
    return true;
  }

  std::string assemble(const std::string &c_name) {
    const size_t n = t_.inputs.size();
    std::string outs;
    for (size_t i = 0; i < n; ++i)
      outs += "    c[(k + 1) * " + std::to_string(n) + " + " + std::to_string(i) +
              "] = " + coefficient_k(t_.outputs[i]) + " / (k + 1);\n";
    std::string f =
        "void " + c_name + "(const double *in, int order, double *c, const double *p) {\n";
    f += "  (void)p;\n";
    f += "  enum { K = " + std::to_string(SICM_ODE_TAYLOR_MAX_ORDER + 1) + " };\n";
    f += "  if (order > K - 1) order = K - 1;\n";
    f += "  if (order < 0) order = 0;\n";
    if (!constants_.empty()) {
      for (const std::string &name : constant_names_)
        f += "  double " + name + ";\n";
      auto no_symbol = [](Symbol *) -> std::string {
        internal_failure(__FILE__, __LINE__, "a constant node with a symbol");
      };
      f += emit_c_assignments(constants_, constant_names_, no_symbol, "u", "");
    }
    for (const std::string &a : arrays_)
      f += "  double " + a + "[K];\n";
    f += spread_inits_;
    f += "  for (int i = 0; i < " + std::to_string(n) + "; ++i) c[i] = in[i];\n";
    f += "  for (int k = 0; k < order; ++k) {\n" + body_ + outs + "  }\n}\n";
    return f;
  }

  const Trace &t_;
  std::unordered_map<Symbol *, size_t> input_;
  std::vector<ExprId> nodes_; // reachable from the outputs, increasing ids
  std::unordered_set<ExprId> series_;
  std::unordered_map<ExprId, std::string> array_of_, scalar_, spread_;
  std::vector<ExprId> constants_;
  std::vector<std::string> constant_names_, arrays_;
  std::string body_, spread_inits_;
  size_t narrays_ = 0;
};

} // namespace

std::string emit_taylor_function(const Trace &t, const std::string &c_name, std::string *why_not) {
  std::string out, reason;
  if (TaylorEmitter(t).emit(c_name, &out, &reason)) return out;
  if (why_not) *why_not = reason;
  return "";
}

// Each helper computes coefficient k of its result from coefficients 0..k
// of its arguments and 0..k-1 of the result (k = 0: the value itself).
std::string c_taylor_support() {
  return R"(/* Taylor-coefficient recurrences (sicm's Taylor emitter). */
static inline double sicm_tc_product(const double *a, const double *b, int k) {
  double s = 0;
  for (int j = 0; j <= k; ++j) s += a[j] * b[k - j];
  return s;
}

/* q = a / b, given a's coefficient k. */
static inline void sicm_tc_quotient(double *q, double a_k, const double *b, int k) {
  double s = a_k;
  for (int j = 1; j <= k; ++j) s -= b[j] * q[k - j];
  q[k] = s / b[0];
}

/* v = u^alpha: u v' = alpha u' v. */
static inline void sicm_tc_power(double *v, const double *u, double alpha, int k) {
  if (k == 0) {
    v[0] = pow(u[0], alpha);
    return;
  }
  double s = 0;
  for (int j = 0; j < k; ++j) s += (alpha * (k - j) - j) * u[k - j] * v[j];
  v[k] = s / (k * u[0]);
}

static inline void sicm_tc_sqrt(double *v, const double *u, int k) {
  if (k == 0) {
    v[0] = sqrt(u[0]);
    return;
  }
  double s = u[k];
  for (int j = 1; j < k; ++j) s -= v[j] * v[k - j];
  v[k] = s / (2 * v[0]);
}

static inline void sicm_tc_exp(double *v, const double *u, int k) {
  if (k == 0) {
    v[0] = exp(u[0]);
    return;
  }
  double s = 0;
  for (int j = 1; j <= k; ++j) s += j * u[j] * v[k - j];
  v[k] = s / k;
}

static inline void sicm_tc_log(double *v, const double *u, int k) {
  if (k == 0) {
    v[0] = log(u[0]);
    return;
  }
  double s = 0;
  for (int j = 1; j < k; ++j) s += j * v[j] * u[k - j];
  v[k] = (u[k] - s / k) / u[0];
}

/* The pair s, c with s' = c u' and c' = sign s u' (sin and cos: sign -1;
 * sinh and cosh: sign +1), at order k >= 1. */
static inline void sicm_tc_pair(double *s, double *c, const double *u, int k, double sign) {
  double a = 0, b = 0;
  for (int j = 1; j <= k; ++j) {
    a += j * u[j] * c[k - j];
    b += j * u[j] * s[k - j];
  }
  s[k] = a / k;
  c[k] = sign * b / k;
}

static inline void sicm_tc_sincos(double *s, double *c, const double *u, int k) {
  if (k == 0)
    sincos(u[0], &s[0], &c[0]);
  else
    sicm_tc_pair(s, c, u, k, -1.0);
}

static inline void sicm_tc_sinhcosh(double *s, double *c, const double *u, int k) {
  if (k == 0) {
    s[0] = sinh(u[0]);
    c[0] = cosh(u[0]);
  } else {
    sicm_tc_pair(s, c, u, k, 1.0);
  }
}

/* v = atan2(y, x): r v' = x y' - y x' with r = x^2 + y^2 (kept in r). */
static inline void sicm_tc_atan2(double *v, const double *y, const double *x, double *r, int k) {
  r[k] = sicm_tc_product(x, x, k) + sicm_tc_product(y, y, k);
  if (k == 0) {
    v[0] = atan2(y[0], x[0]);
    return;
  }
  double d = 0;
  for (int j = 0; j < k; ++j) d += (k - j) * (x[j] * y[k - j] - y[j] * x[k - j]);
  for (int j = 1; j < k; ++j) d -= r[j] * (k - j) * v[k - j];
  v[k] = d / (k * r[0]);
}

)";
}

} // namespace sicm
