// Unit tests of the local rewrites of traced kernels (compiler/codegen/local_rewrite.cpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "algebra/symbolic.hpp"
#include "cas/expr.hpp"
#include "codegen/kernel_form.hpp"
#include "codegen/local_rewrite.hpp"
#include "eval/interp.hpp"
#include "syntax/reader.hpp"

namespace sicm {
namespace {

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<local_rewrite_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

// A quoted prefix form as traced arithmetic builds it (symbolic_apply's
// light rewrites only), as a node.
ExprId traced(const std::string &prefix) {
  return leaf_expr(datum_to_expression(run("'" + prefix)));
}

std::string rewritten(const std::string &prefix) {
  return expr_debug_string(rewrite_locally({traced(prefix)})[0]);
}

TEST(LocalRewrite, CoefficientsFoldThroughProducts) {
  EXPECT_EQ(rewritten("(* 1/2 (* 2 x))"), "x");
  EXPECT_EQ(rewritten("(* -1 (* -1 x))"), "x");
}

TEST(LocalRewrite, ATermAndItsNegationCancel) {
  EXPECT_EQ(rewritten("(+ (* a b) (* -1 (* b a)))"), "0");
}

TEST(LocalRewrite, SineSquaredPlusCosineSquared) {
  EXPECT_EQ(rewritten("(+ (* 3 (expt (sin x) 2)) (* 3 (expt (cos x) 2)))"), "3");
  // Different coefficients are left alone.
  EXPECT_NE(rewritten("(+ (* 3 (expt (sin x) 2)) (* 2 (expt (cos x) 2)))"), "3");
}

TEST(LocalRewrite, LikeFactorsBecomeOnePower) {
  EXPECT_EQ(rewritten("(* (expt r -2) (expt r -1))"), "(expt r -3)");
  EXPECT_EQ(rewritten("(* (expt u -1) (expt (sqrt u) -1))"), "(expt (sqrt u) -3)");
  EXPECT_EQ(rewritten("(expt (* 2 x) -1)"), "(* 1/2 (expt x -1))");
}

// 1 - cos x is rounded on its own: merging it into the outer sum would
// round 1 with the other terms (accuracy-pendulum-small-angle.sicm).
TEST(LocalRewrite, ASumWithoutLikeTermsStaysASum) {
  std::string r = rewritten("(+ (* 1/2 (expt v 2)) (* -1 (+ 1 (* -1 (cos x)))))");
  EXPECT_EQ(r, "(+ (* 1/2 (expt v 2)) (* -1 (+ (* -1 (cos x)) 1)))");
}

// A sum merges into its user when terms meet like terms: v^2 - 1/2 v^2.
TEST(LocalRewrite, ASumWithLikeTermsMerges) {
  std::string r = rewritten("(+ (expt v 2) (* -1 (+ (* 1/2 (expt v 2)) (* -1 (cos x)))))");
  EXPECT_EQ(r, "(+ (* 1/2 (expt v 2)) (cos x))");
}

// -(f g) and (f g) share the product f g.
TEST(LocalRewrite, SignedUsesShareTheirProduct) {
  std::vector<ExprId> out = rewrite_locally({traced("(* -1 f g)"), traced("(* f g)")});
  ASSERT_EQ(expr_kind(out[0]), ExprKind::Apply);
  std::vector<ExprId> args = expr_arg_vector(out[0]);
  ASSERT_EQ(args.size(), 2u);
  EXPECT_EQ(args[1], out[1]);
}

TEST(LocalRewrite, NeverEnlarges) {
  for (const char *prefix : {"(+ (* a (+ b c)) (* -1 (* (+ b c) a)) (sin (* 2 (* 1/2 x))))",
                             "(* (expt (+ x y) 2) (expt (+ x y) -3) (+ x y))",
                             "(+ (* 2 (sqrt (* 4 u))) (* 3 (expt (sqrt u) 2)))"}) {
    ExprId t = traced(prefix);
    EXPECT_LE(dag_size(rewrite_locally({t})), dag_size({t})) << prefix;
  }
}

} // namespace
} // namespace sicm
