// A numeric evaluator of expression DAGs for tests (see expr_evaluate.hpp).
#include "expr_evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "base/number.hpp"

namespace sicm {

namespace {

double operation(Op op, const std::vector<double> &v) {
  double r = 0;
  switch (op) {
  case Op::Add:
    for (double d : v)
      r += d;
    return r;
  case Op::Mul:
    r = 1;
    for (double d : v)
      r *= d;
    return r;
  case Op::Div: return v[0] / v[1];
  case Op::Expt: return std::pow(v[0], v[1]);
  case Op::Sqrt: return std::sqrt(v[0]);
  case Op::Exp: return std::exp(v[0]);
  case Op::Log: return std::log(v[0]);
  case Op::Sin: return std::sin(v[0]);
  case Op::Cos: return std::cos(v[0]);
  default: return NAN;
  }
}

} // namespace

double expr_evaluate(ExprId id, const std::function<double(const std::string &)> &value_of,
                     double *largest) {
  double v = NAN;
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: v = to_double(expr_number_value(id)); break;
  case ExprKind::Symbol: v = value_of(n.sym->name); break;
  case ExprKind::Call: v = NAN; break;
  case ExprKind::Apply: {
    Op op = n.op;
    std::vector<double> args;
    for (ExprId a : expr_arg_vector(id))
      args.push_back(expr_evaluate(a, value_of, largest));
    v = operation(op, args);
    break;
  }
  }
  if (largest) *largest = std::max(*largest, std::fabs(v));
  return v;
}

} // namespace sicm
