// Unit tests of the expression DAG (compiler/cas/expr.cpp): hash-consing, order, invariants.
#include <gtest/gtest.h>

#include "algebra/symbolic.hpp"
#include "cas/expr.hpp"

namespace sicm {
namespace {

ExprId sym(const char *name) {
  return expr_symbol(intern(name).symbol());
}

ExprId num(int64_t n) {
  return expr_integer(n);
}

TEST(Expr, EqualStructureIsEqualId) {
  ExprId x = sym("x"), y = sym("y");
  EXPECT_EQ(sym("x"), x);
  EXPECT_EQ(expr_apply(Op::Add, {x, y}), expr_apply(Op::Add, {x, y}));
  EXPECT_NE(expr_apply(Op::Add, {x, y}), expr_apply(Op::Add, {y, x}));
  EXPECT_EQ(expr_apply(Op::Sin, {expr_apply(Op::Mul, {num(2), x})}),
            expr_apply(Op::Sin, {expr_apply(Op::Mul, {num(2), x})}));
  ExprId f = sym("f");
  ExprId args[] = {sym("t")};
  EXPECT_EQ(expr_call(f, args, 1), expr_call(f, args, 1));
}

TEST(Expr, NumbersAreCanonicalAndDistinctByExactness) {
  mpq_t q;
  mpq_init(q);
  mpq_set_si(q, 4, 6); // not in lowest terms
  ExprId two_thirds = expr_rational(q);
  mpq_set_si(q, 2, 3);
  EXPECT_EQ(expr_rational(q), two_thirds);
  mpq_clear(q);
  EXPECT_EQ(expr_integer(5), expr_from_number(Value::fixnum(5)));
  EXPECT_NE(expr_flonum(5.0), expr_integer(5));
  EXPECT_NE(expr_flonum(0.0), expr_flonum(-0.0));
  EXPECT_TRUE(expr_is_exact_zero(expr_integer(0)));
  EXPECT_FALSE(expr_is_exact_zero(expr_flonum(0.0)));
  EXPECT_TRUE(expr_is_exact_one(expr_integer(1)));
}

TEST(Expr, ChildrenBeforeParents) {
  ExprId x = sym("x");
  ExprId s = expr_apply(Op::Sin, {x});
  ExprId p = expr_apply(Op::Mul, {num(3), s, x});
  EXPECT_LT(x, s);
  EXPECT_LT(s, p);
  for (ExprId a : expr_arg_vector(p))
    EXPECT_LT(a, p);
}

TEST(Expr, OrderPutsNumbersThenSymbolsThenApplications) {
  ExprId a = sym("a"), b = sym("b"), big_a = sym("A");
  ExprId sa = expr_apply(Op::Sin, {a}), ca = expr_apply(Op::Cos, {a});
  EXPECT_LT(expr_compare(num(7), a), 0);
  EXPECT_LT(expr_compare(big_a, a), 0); // symbol<? compares bytes: A before a
  EXPECT_LT(expr_compare(a, b), 0);
  EXPECT_LT(expr_compare(b, sa), 0);
  EXPECT_LT(expr_compare(ca, sa), 0); // by operator name
  EXPECT_EQ(expr_compare(sa, sa), 0);
  // A derived-function head sorts before a named one: ((D f) t) < (f t).
  ExprId t[] = {sym("t")}, f[] = {sym("f")};
  ExprId df = expr_call(sym("D"), f, 1);
  EXPECT_LT(expr_compare(expr_call(df, t, 1), expr_call(sym("f"), t, 1)), 0);
}

TEST(Expr, CanonicalChecker) {
  ExprId x = sym("x"), y = sym("y");
  ExprId x2 = expr_apply(Op::Expt, {x, num(2)});
  EXPECT_TRUE(expr_is_canonical(x));
  EXPECT_TRUE(expr_is_canonical(num(3)));
  EXPECT_TRUE(expr_is_canonical(expr_apply(Op::Mul, {num(2), x, y})));
  EXPECT_FALSE(expr_is_canonical(expr_apply(Op::Mul, {num(2), y, x}))); // factors out of order
  EXPECT_FALSE(expr_is_canonical(expr_apply(Op::Mul, {num(1), x})));    // coefficient 1
  EXPECT_TRUE(expr_is_canonical(expr_apply(Op::Add, {num(1), x2, x}))); // the constant first
  EXPECT_FALSE(expr_is_canonical(expr_apply(Op::Add, {x2, x, num(1)})));
  EXPECT_FALSE(expr_is_canonical(expr_apply(Op::Add, {x, x2}))); // degree order
  EXPECT_TRUE(expr_is_canonical(expr_apply(Op::Div, {x, y})));
  EXPECT_FALSE(expr_is_canonical(expr_apply(Op::Div, {x, expr_apply(Op::Mul, {num(2), y})})));
}

TEST(Expr, DebugString) {
  ExprId x = sym("x");
  EXPECT_EQ(expr_debug_string(expr_apply(Op::Add, {expr_apply(Op::Mul, {num(2), x}), num(1)})),
            "(+ (* 2 x) 1)");
}

} // namespace
} // namespace sicm
