// Unit tests of the evaluation form (compiler/cas/evaluation_form.cpp) and of the decimal
// constants that kernel tracing uses (DecimalConstants, algebra/symbolic.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <unordered_set>
#include <vector>

#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "cas/evaluation_form.hpp"
#include "cas/expr.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/kernel.hpp"
#include "eval/interp.hpp"
#include "expr_evaluate.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

namespace sicm {
namespace {

// Evaluate every form of text; the value of the last.
Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<evaluation_form_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

// The simplified expression of a quoted prefix form, as a node.
ExprId simplified(const std::string &prefix) {
  Value v = simplify_value(datum_to_expression(run("'" + prefix)));
  if (v.is(Tag::Expr)) return static_cast<ExprId>(v.i);
  if (v.is(Tag::Symbol)) return expr_symbol(v.symbol());
  return expr_from_number(v);
}

// Multiplications, divisions and additions written out: one per argument
// after the first of + and *, n - 1 for a power (expt v n), one for a
// division; each node counted once (the emitter names shared nodes).
size_t operations(ExprId id, std::unordered_set<ExprId> &seen) {
  if (!seen.insert(id).second || expr_kind(id) != ExprKind::Apply) return 0;
  size_t n = 0;
  std::vector<ExprId> args = expr_arg_vector(id);
  for (ExprId a : args)
    n += operations(a, seen);
  const ExprNode &node = expr_node(id);
  int64_t e;
  if (node.op == Op::Expt && expr_get_int64(args[1], &e)) return n + (e < 0 ? -e : e - 1);
  if (node.op == Op::Add || node.op == Op::Mul) return n + args.size() - 1;
  return n + 1;
}

size_t operations(const std::vector<ExprId> &outputs) {
  std::unordered_set<ExprId> seen;
  size_t n = 0;
  for (ExprId id : outputs)
    n += operations(id, seen);
  return n;
}

double value_at(ExprId id, const std::map<std::string, double> &point) {
  return expr_evaluate(id, [&](const std::string &name) { return point.at(name); });
}

// The outputs keep their values at a few points (to rounding).
void expect_same_values(const std::vector<ExprId> &before, const std::vector<ExprId> &after) {
  ASSERT_EQ(before.size(), after.size());
  const std::map<std::string, double> points[] = {
      {{"x", 0.3}, {"y", -1.7}, {"z", 2.25}, {"w", 0.9}},
      {{"x", -2.1}, {"y", 0.45}, {"z", -0.6}, {"w", 1.3}},
      {{"x", 1.9}, {"y", 3.1}, {"z", 0.05}, {"w", -0.7}},
  };
  for (const auto &p : points)
    for (size_t j = 0; j < before.size(); ++j) {
      double a = value_at(before[j], p), b = value_at(after[j], p);
      EXPECT_NEAR(a, b, 1e-12 * std::max(1.0, std::fabs(a))) << expr_debug_string(after[j]);
    }
}

TEST(EvaluationForm, HornerFactorsTheMostFrequentVariable) {
  std::vector<ExprId> before = {simplified("(+ (* 3 x x y) (* 5 x y) (* 7 y))")};
  std::vector<ExprId> after = before;
  to_evaluation_form(after);
  expect_same_values(before, after);
  // 3x^2y + 5xy + 7y: 2 + 3 + 1 multiplications and 2 additions expanded;
  // ((3x + 5)x + 7)y: 3 multiplications and 2 additions.
  EXPECT_EQ(operations(before), 8u);
  EXPECT_EQ(operations(after), 5u);
}

TEST(EvaluationForm, TakesOutACommonFactorOnlyWhenItPays) {
  std::vector<ExprId> out = {simplified("(+ (* 12 x) (* 12 y) (* 12 z))"),
                             simplified("(+ (* 3 x) (* 5 y))")};
  std::vector<ExprId> before = out;
  to_evaluation_form(out);
  expect_same_values(before, out);
  EXPECT_EQ(expr_debug_string(out[0]), "(* 12 (+ x y z))");
  EXPECT_EQ(expr_debug_string(out[1]), "(+ (* 3 x) (* 5 y))");
}

TEST(EvaluationForm, ProportionalDenominatorsShareOneReciprocal) {
  // Two accelerations over one determinant, scaled differently, and a third
  // output over another denominator.
  std::vector<ExprId> out = {simplified("(/ x (+ 2 (* 4 (cos z) (cos z))))"),
                             simplified("(/ y (+ 3 (* 6 (cos z) (cos z))))"),
                             simplified("(/ w (+ 1 x))")};
  std::vector<ExprId> before = out;
  to_evaluation_form(out);
  expect_same_values(before, out);
  std::vector<ExprId> reciprocals;
  for (size_t j = 0; j < 2; ++j) {
    ASSERT_TRUE(expr_is_apply(out[j], Op::Mul)) << expr_debug_string(out[j]);
    std::vector<ExprId> args = expr_arg_vector(out[j]);
    ASSERT_TRUE(expr_is_apply(args.back(), Op::Expt)) << expr_debug_string(out[j]);
    reciprocals.push_back(args.back());
  }
  EXPECT_EQ(reciprocals[0], reciprocals[1]);
  EXPECT_TRUE(expr_is_apply(out[2], Op::Div)) << expr_debug_string(out[2]);
}

TEST(EvaluationForm, InexactCoefficientsAreKept) {
  std::vector<ExprId> out = {simplified("(+ (* 1.5 x y) (* 2.5 x))")};
  std::vector<ExprId> before = out;
  to_evaluation_form(out);
  expect_same_values(before, out);
  std::string s = expr_debug_string(out[0]);
  EXPECT_NE(s.find("1.5"), std::string::npos) << s;
  EXPECT_NE(s.find("2.5"), std::string::npos) << s;
}

TEST(EvaluationForm, KernelArgumentsAreRewrittenToo) {
  std::vector<ExprId> out = {simplified("(sin (+ (* x x y) (* x y)))")};
  std::vector<ExprId> before = out;
  to_evaluation_form(out);
  expect_same_values(before, out);
  EXPECT_LT(operations(out), operations(before));
}

// Random polynomials in four variables and two kernels: same values, never
// more operations than expanded.
TEST(EvaluationForm, RandomPolynomialsKeepTheirValueAndCostNoMore) {
  const char *vars[] = {"x", "y", "z", "w", "(sin x)", "(cos y)"};
  uint32_t state = 2024;
  auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  for (int i = 0; i < 200; ++i) {
    std::string sum = "(+";
    int terms = 1 + static_cast<int>(next() % 12);
    for (int t = 0; t < terms; ++t) {
      sum += " (* " + std::to_string(static_cast<int>(next() % 19) - 9);
      int factors = static_cast<int>(next() % 5);
      for (int f = 0; f < factors; ++f)
        sum += std::string(" ") + vars[next() % 6];
      sum += ")";
    }
    sum += ")";
    ExprId e = simplified(sum);
    std::vector<ExprId> out = {e};
    to_evaluation_form(out);
    expect_same_values({e}, out);
    EXPECT_LE(operations(out), operations({e})) << sum;
  }
}

TEST(DecimalConstants, FlonumsMeetingSymbolsAreTheirDecimals) {
  Value x = intern("x");
  Value args[] = {Value::flonum(9.8), x};
  {
    DecimalConstants decimal;
    Value p = symbolic_apply(Op::Mul, args, 2);
    EXPECT_EQ(write_string(p), "(* 49/5 x)");
    Value numbers[] = {Value::flonum(1.5), Value::flonum(9.8)};
    // Arithmetic on numbers alone is untouched.
    EXPECT_EQ(write_string(symbolic_apply(Op::Mul, numbers, 2)), "14.700000000000001");
  }
  EXPECT_EQ(write_string(symbolic_apply(Op::Mul, args, 2)), "(* 9.8 x)");
}

// The double pendulum with flonum parameters compiles to the same kernel as
// with exact ones, and its two accelerations share one division.
// Numbers a system captures are its kernel's parameters (KernelParameters):
// two double pendulums that differ only in their numbers are one C source,
// compiled and loaded once, each kernel with its own p[]; a number that
// changes the structure (an exact 0, here no gravity) is folded in.
TEST(KernelParameters, SystemsThatDifferInValuesShareOneKernel) {
  run(R"(
(define ((L-two m1 m2 g) local)
  (let ((q (coordinate local)) (v (velocity local)))
    (- (+ (* 1/2 m1 (+ (square (ref v 0)) (square (ref v 1))))
          (* 1/2 m2 (+ (square (ref v 2)) (square (ref v 3)))))
       (* g (+ (* m1 (ref q 1)) (* m2 (ref q 3)))))))
(define ((angles->rect l1 l2) local)
  (let ((q (coordinate local)))
    (let ((x1 (* l1 (sin (ref q 0)))) (y1 (* -1 l1 (cos (ref q 0)))))
      (up x1 y1 (+ x1 (* l2 (sin (ref q 1)))) (- y1 (* l2 (cos (ref q 1))))))))
(define (L-double m1 m2 l1 l2 g)
  (compose (L-two m1 m2 g) (F->C (angles->rect l1 l2))))
(define sample (up 0. (up 1. .5) (up 0. 0.)))
)");
  std::string why;
  Kernel *a = compile_kernel(run("(Lagrangian->state-derivative (L-double 1.1 1.7 .9 .7 9.8))"),
                             run("(list sample)"), "double", &why);
  ASSERT_NE(a, nullptr) << why;
  Kernel *b = compile_kernel(run("(Lagrangian->state-derivative (L-double 1.2 2.3 .95 .65 9.81))"),
                             run("(list sample)"), "double", &why);
  ASSERT_NE(b, nullptr) << why;
  EXPECT_EQ(a->c_source, b->c_source);
  EXPECT_EQ(a->fn, b->fn); // one shared object
  EXPECT_EQ(a->params.size(), b->params.size());
  EXPECT_NE(std::find(a->params.begin(), a->params.end(), 9.8), a->params.end());
  EXPECT_NE(a->params, b->params);
  double in[5] = {0., 1., .5, .3, -.2}, out_a[5], out_b[5];
  kernel_call(a, in, out_a);
  kernel_call(b, in, out_b);
  EXPECT_NE(out_a[3], out_b[3]);
  Kernel *c = compile_kernel(run("(Lagrangian->state-derivative (L-double 1.1 1.7 .9 .7 0))"),
                             run("(list sample)"), "double", &why);
  ASSERT_NE(c, nullptr) << why;
  EXPECT_NE(c->c_source, a->c_source);
  EXPECT_LT(c->c_source.size(), a->c_source.size());
}

} // namespace
} // namespace sicm
