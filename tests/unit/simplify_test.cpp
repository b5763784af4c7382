// Unit tests of the simplifier and the prefix printer (compiler/cas/simplify.cpp,
// prefix_form.cpp); expected forms are scmutils'.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <string>

#include "algebra/symbolic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "base/srcloc.hpp"
#include "cas/expr.hpp"
#include "cas/simplify.hpp"
#include "expr_evaluate.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

namespace sicm {
namespace {

Value S(const char *name) {
  return intern(name);
}
Value N(int64_t n) {
  return Value::fixnum(n);
}
Value Q(int64_t p, int64_t q) {
  return num_div(N(p), N(q));
}
Value F(double d) {
  return Value::flonum(d);
}

Value apply(Op op, std::initializer_list<Value> args) {
  gcvec<Value> v(args);
  return symbolic_apply(op, v.data(), static_cast<int>(v.size()));
}
Value add(std::initializer_list<Value> a) {
  return apply(Op::Add, a);
}
Value sub(std::initializer_list<Value> a) {
  return apply(Op::Sub, a);
}
Value mul(std::initializer_list<Value> a) {
  return apply(Op::Mul, a);
}
Value div(std::initializer_list<Value> a) {
  return apply(Op::Div, a);
}
Value expt(Value b, Value e) {
  return apply(Op::Expt, {b, e});
}
Value square(Value x) {
  return expt(x, N(2));
}
Value fn(Op op, Value x) {
  return apply(op, {x});
}
Value read_datum(const char *text) {
  return read_all(register_source("<simplify_test>", text))[0].datum;
}

// An unknown function applied: (f x ...), the function given as a datum.
Value call(const char *head_datum, std::initializer_list<Value> args) {
  Value head = datum_to_expression(read_datum(head_datum));
  gcvec<Value> v(args);
  return symbolic_call(head, v.data(), static_cast<int>(v.size()));
}

std::string pe(Value v) {
  return write_string(expression_to_datum(v));
}

TEST(Simplify, LikeTermsAndExpansion) {
  Value a = S("a"), b = S("b");
  EXPECT_EQ(pe(add({a, a})), "(* 2 a)");
  EXPECT_EQ(pe(mul({add({a, b}), add({a, b})})), "(+ (expt a 2) (* 2 a b) (expt b 2))");
  EXPECT_EQ(pe(sub({a, a})), "0");
  EXPECT_EQ(pe(sub({add({a, N(1)}), a})), "1");
}

TEST(Simplify, RationalFunctions) {
  Value x = S("x"), k = S("k"), m = S("m");
  EXPECT_EQ(pe(div({sub({mul({x, x}), N(1)}), sub({x, N(1)})})), "(+ 1 x)");
  EXPECT_EQ(pe(div({mul({N(-1), k, x}), m})), "(/ (* -1 k x) m)");
  EXPECT_EQ(pe(div({x, mul({N(2), m})})), "(/ (* 1/2 x) m)");
  EXPECT_EQ(pe(div({add({mul({N(4), x}), N(5)}), N(3)})), "(+ 5/3 (* 4/3 x))");
  EXPECT_EQ(pe(div({mul({S("a"), S("b")}), mul({S("b"), S("c")})})), "(/ a c)");
  // A polynomial denominator: integer coefficients, first term positive.
  EXPECT_EQ(pe(div({x, sub({mul({N(2), S("b")}), mul({N(4), S("a")})})})),
            "(/ (* -1 x) (+ (* 4 a) (* -2 b)))");
  EXPECT_EQ(pe(div({N(1), add({S("a"), S("b")})})), "(/ 1 (+ a b))");
  // Over a monomial denominator each term is written over what is left of
  // it, as scmutils writes the book's Hamiltonians (prefix_form.cpp).
  EXPECT_EQ(pe(add({div({N(1), x}), div({N(1), S("y")})})), "(+ (/ 1 y) (/ 1 x))");
}

TEST(Simplify, ScmutilsTermAndFactorOrder) {
  Value m = S("m"), t = S("t");
  Value dx = call("(D x)", {t}), dy = call("(D y)", {t});
  Value L = add({mul({Q(1, 2), m, square(dx)}), mul({Q(1, 2), m, square(dy)})});
  EXPECT_EQ(pe(L), "(+ (* 1/2 m (expt ((D x) t) 2)) (* 1/2 m (expt ((D y) t) 2)))");
  Value ddx = call("((expt D 2) x)", {t});
  EXPECT_EQ(pe(add({mul({ddx, m}), mul({S("k"), call("x", {t})})})),
            "(+ (* k (x t)) (* m (((expt D 2) x) t)))");
  Value phidot = S("phidot"), r = S("r"), rdot = S("rdot");
  Value e = add({mul({Q(1, 2), m, square(rdot)}), mul({Q(1, 2), m, square(phidot), square(r)}),
                 mul({N(-1), call("U", {r})})});
  EXPECT_EQ(pe(e), "(+ (* 1/2 m (expt phidot 2) (expt r 2)) (* 1/2 m (expt rdot 2)) (* -1 (U r)))");
  Value f_x = call("f", {S("x")});
  EXPECT_EQ(pe(sub({call("((expt D 2) f)", {S("x")}), f_x})),
            "(+ (((expt D 2) f) x) (* -1 (f x)))");
}

TEST(Simplify, Trigonometry) {
  Value x = S("x"), m = S("m");
  Value s2 = square(fn(Op::Sin, x)), c2 = square(fn(Op::Cos, x));
  EXPECT_EQ(pe(add({s2, c2})), "1");
  EXPECT_EQ(pe(mul({m, add({s2, c2})})), "m");
  EXPECT_EQ(pe(sub({N(1), s2})), "(expt (cos x) 2)");
  EXPECT_EQ(pe(add({mul({S("A"), s2}), mul({S("C"), c2})})),
            "(+ (* A (expt (sin x) 2)) (* C (expt (cos x) 2)))");
  EXPECT_EQ(pe(fn(Op::Sin, sub({N(0), x}))), "(* -1 (sin x))");
  EXPECT_EQ(pe(fn(Op::Cos, mul({N(-1), x}))), "(cos x)");
  EXPECT_EQ(pe(fn(Op::Sin, add({x, x}))), "(sin (* 2 x))");
  EXPECT_EQ(pe(fn(Op::Sin, sub({x, x}))), "0");
  EXPECT_EQ(pe(fn(Op::Asin, fn(Op::Sin, x))), "x");
}

TEST(Simplify, RootsExpAndLog) {
  Value x = S("x"), y = S("y");
  EXPECT_EQ(pe(expt(fn(Op::Sqrt, x), N(2))), "x");
  EXPECT_EQ(pe(expt(fn(Op::Sqrt, x), N(3))), "(* x (sqrt x))");
  EXPECT_EQ(pe(div({x, fn(Op::Sqrt, x)})), "(sqrt x)");
  EXPECT_EQ(pe(div({N(1), fn(Op::Sqrt, x)})), "(/ 1 (sqrt x))");
  EXPECT_EQ(pe(expt(x, Q(1, 2))), "(sqrt x)");
  // Inside the simplifier (sqrt 2) stays exact and squares to 2.
  Value root2 = fn(Op::Sqrt, add({x, N(2), mul({N(-1), x})}));
  EXPECT_EQ(pe(root2), "(sqrt 2)");
  EXPECT_EQ(pe(mul({root2, root2})), "2");
  EXPECT_EQ(pe(fn(Op::Sqrt, add({x, N(4), mul({N(-1), x})}))), "2");
  EXPECT_EQ(pe(fn(Op::Sqrt, add({square(x), square(y)}))), "(sqrt (+ (expt x 2) (expt y 2)))");
  EXPECT_EQ(pe(fn(Op::Sqrt, square(x))), "x");
  EXPECT_EQ(pe(fn(Op::Sqrt, div({x, square(y)}))), "(/ (sqrt x) y)");
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({N(2), square(x)}))), "(* x (sqrt 2))");
  EXPECT_EQ(pe(fn(Op::Exp, fn(Op::Log, x))), "x");
  EXPECT_EQ(pe(fn(Op::Log, fn(Op::Exp, x))), "x");
  EXPECT_EQ(pe(fn(Op::Exp, add({x, y}))), "(* (exp x) (exp y))");
  EXPECT_EQ(pe(sub({fn(Op::Exp, mul({N(2), x})), square(fn(Op::Exp, x))})), "0");
  EXPECT_EQ(pe(mul({fn(Op::Exp, x), fn(Op::Exp, sub({y, x}))})), "(exp y)");
  EXPECT_EQ(pe(fn(Op::Exp, mul({N(2), fn(Op::Log, x)}))), "(expt x 2)");
}

// Square roots end expanded, as scmutils' new-simplify leaves them (its
// last sqrt step is sqrt-expand, after sqrt-contract and root-out-squares),
// so products and quotients of roots combine: the polar-canonical
// transformation's (* (sqrt (* 2 I alpha)) (sqrt (/ (* 2 I) alpha))) is 2I.
TEST(Simplify, RootsOfProductsAndQuotients) {
  Value x = S("x"), y = S("y"), I = S("I"), alpha = S("alpha");
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({x, y}))), "(* (sqrt x) (sqrt y))");
  EXPECT_EQ(pe(fn(Op::Sqrt, div({x, y}))), "(/ (sqrt x) (sqrt y))");
  EXPECT_EQ(pe(fn(Op::Sqrt, div({N(1), x}))), "(/ 1 (sqrt x))");
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({N(2), x}))), "(* (sqrt 2) (sqrt x))");
  Value p = fn(Op::Sqrt, mul({N(2), I, alpha}));
  Value q = fn(Op::Sqrt, div({mul({N(2), I}), alpha}));
  EXPECT_EQ(pe(mul({p, q})), "(* 2 I)");
  EXPECT_EQ(pe(sub({mul({p, q}), mul({N(2), I})})), "0");
  EXPECT_EQ(pe(div({p, q})), "alpha");
  EXPECT_EQ(pe(sub({fn(Op::Sqrt, mul({x, y})), mul({fn(Op::Sqrt, x), fn(Op::Sqrt, y)})})), "0");
  EXPECT_EQ(pe(sub({fn(Op::Sqrt, div({x, y})), div({fn(Op::Sqrt, x), fn(Op::Sqrt, y)})})), "0");
  // Squares and perfect powers leave the root (root-out-squares, assuming
  // them non-negative as sqrt-expt-simplify does).
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({expt(x, N(3)), y}))), "(* x (sqrt x) (sqrt y))");
  EXPECT_EQ(pe(fn(Op::Sqrt, div({expt(x, N(4)), expt(y, N(2))}))), "(/ (expt x 2) y)");
  EXPECT_EQ(pe(fn(Op::Sqrt, expt(add({x, y}), N(2)))), "(+ x y)");
  // A polynomial's content and monomial factor leave it; the rest stays one root.
  EXPECT_EQ(pe(fn(Op::Sqrt, add({mul({N(2), x}), mul({N(2), y})}))), "(* (sqrt 2) (sqrt (+ x y)))");
  EXPECT_EQ(pe(fn(Op::Sqrt, add({mul({x, x, y}), mul({x, y, y})}))),
            "(* (sqrt x) (sqrt y) (sqrt (+ x y)))");
  // Exact numbers: the denominator and small square factors move out.
  Value eight = add({x, N(8), mul({N(-1), x})}), two = add({x, N(2), mul({N(-1), x})});
  EXPECT_EQ(pe(fn(Op::Sqrt, eight)), "(* 2 (sqrt 2))");
  EXPECT_EQ(pe(mul({fn(Op::Sqrt, eight), fn(Op::Sqrt, two)})), "4");
  EXPECT_EQ(pe(fn(Op::Sqrt, add({x, Q(1, 2), mul({N(-1), x})}))), "(* 1/2 (sqrt 2))");
  // A negative sign is not split off: it stays with a polynomial factor,
  // or the root stays whole.
  Value one_minus_x2 = sub({N(1), square(x)});
  EXPECT_EQ(pe(fn(Op::Sqrt, one_minus_x2)), "(sqrt (+ 1 (* -1 (expt x 2))))");
  EXPECT_EQ(pe(fn(Op::Sqrt, div({one_minus_x2, y}))),
            "(/ (sqrt (+ 1 (* -1 (expt x 2)))) (sqrt y))");
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({N(-2), x, y}))), "(sqrt (* -2 x y))");
  // With flonums the radicand stays whole: its root would be a flonum kernel.
  EXPECT_EQ(pe(fn(Op::Sqrt, mul({F(2.5), x}))), "(sqrt (* 2.5 x))");
}

// scmutils' atan rule divides both arguments by their gcd (assuming it
// positive, aggressive-atan-simplify): the polar-canonical inverse of the
// transformation gives theta back.
TEST(Simplify, AtanDividesOutACommonFactor) {
  Value x = S("x"), y = S("y"), r = S("r"), phi = S("phi");
  auto atan2 = [](Value a, Value b) { return apply(Op::Atan, {a, b}); };
  EXPECT_EQ(pe(atan2(mul({r, fn(Op::Sin, phi)}), mul({r, fn(Op::Cos, phi)}))), "phi");
  EXPECT_EQ(pe(atan2(mul({x, y}), mul({x, x}))), "(atan y x)");
  EXPECT_EQ(pe(atan2(mul({N(2), y}), mul({N(2), x}))), "(atan (* 2 y) (* 2 x))");
  EXPECT_EQ(pe(atan2(y, x)), "(atan y x)");
}

TEST(Simplify, NumbersFoldAsSchemeDoes) {
  EXPECT_EQ(pe(add({N(1), N(2)})), "3");
  EXPECT_EQ(pe(fn(Op::Sin, N(0))), "0");
  EXPECT_EQ(pe(fn(Op::Sqrt, N(4))), "2");
  EXPECT_EQ(pe(mul({N(0), S("x")})), "0");
  EXPECT_EQ(pe(add({S("x"), N(0)})), "x");
  EXPECT_EQ(pe(mul({N(1), S("x")})), "x");
  EXPECT_THROW(div({S("x"), N(0)}), Error);
  EXPECT_THROW(simplify_value(div({S("x"), sub({S("y"), S("y")})})), Error);
}

TEST(Simplify, FlonumsMakeTheResultInexact) {
  Value x = S("x"), y = S("y");
  EXPECT_EQ(pe(add({mul({F(2.5), x}), mul({F(1.5), x})})), "(* 4. x)");
  EXPECT_EQ(pe(add({mul({F(2.0), x}), y})), "(+ (* 2. x) y)");
  EXPECT_EQ(pe(add({mul({F(0.5), x}), mul({F(-1.5), x})})), "(* -1 x)");
  EXPECT_EQ(pe(add({x, F(1.5), mul({N(-1), x})})), "1.5");
}

TEST(Simplify, IdempotentAndMemoized) {
  Value x = S("x"), y = S("y");
  Value e = div({add({square(fn(Op::Sin, x)), y}), sub({x, mul({N(3), y})})});
  Value s = simplify_value(e);
  ASSERT_TRUE(s.is(Tag::Expr));
  EXPECT_TRUE(expr_is_canonical(static_cast<ExprId>(s.i)));
  EXPECT_TRUE(eq(simplify_value(s), s));
  EXPECT_TRUE(eq(simplify_value(e), s));
}

// The kinetic energy of a rigid body in Euler angles, computed as the book
// does: the angular velocity from M^T Mdot with M = Rz(phi) Rx(theta) Rz(psi).
using Mat = std::array<std::array<Value, 3>, 3>;

Mat mat_mul(const Mat &a, const Mat &b) {
  Mat c;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      Value s = N(0);
      for (int k = 0; k < 3; k++)
        s = add({s, mul({a[i][k], b[k][j]})});
      c[i][j] = s;
    }
  return c;
}
Mat mat_add(const Mat &a, const Mat &b) {
  Mat c;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[i][j] = add({a[i][j], b[i][j]});
  return c;
}
Mat mat_scale(Value k, const Mat &a) {
  Mat c;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[i][j] = mul({k, a[i][j]});
  return c;
}
Mat transpose(const Mat &a) {
  Mat c;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      c[i][j] = a[j][i];
  return c;
}
Mat rot_z(Value a, bool derivative) {
  Value s = fn(Op::Sin, a), c = fn(Op::Cos, a), ms = mul({N(-1), s}), mc = mul({N(-1), c});
  if (derivative) return Mat{{{ms, mc, N(0)}, {c, ms, N(0)}, {N(0), N(0), N(0)}}};
  return Mat{{{c, ms, N(0)}, {s, c, N(0)}, {N(0), N(0), N(1)}}};
}
Mat rot_x(Value a, bool derivative) {
  Value s = fn(Op::Sin, a), c = fn(Op::Cos, a), ms = mul({N(-1), s}), mc = mul({N(-1), c});
  if (derivative) return Mat{{{N(0), N(0), N(0)}, {N(0), ms, mc}, {N(0), c, ms}}};
  return Mat{{{N(1), N(0), N(0)}, {N(0), c, ms}, {N(0), s, c}}};
}

TEST(Simplify, RigidBodyKineticEnergyIsFast) {
  Value phi = S("phi"), theta = S("theta"), psi = S("psi");
  Value phidot = S("phidot"), thetadot = S("thetadot"), psidot = S("psidot");
  Mat M = mat_mul(mat_mul(rot_z(phi, false), rot_x(theta, false)), rot_z(psi, false));
  Mat Mdot = mat_add(
      mat_add(mat_scale(phidot,
                        mat_mul(mat_mul(rot_z(phi, true), rot_x(theta, false)), rot_z(psi, false))),
              mat_scale(thetadot, mat_mul(mat_mul(rot_z(phi, false), rot_x(theta, true)),
                                          rot_z(psi, false)))),
      mat_scale(psidot,
                mat_mul(mat_mul(rot_z(phi, false), rot_x(theta, false)), rot_z(psi, true))));
  Mat W = mat_mul(transpose(M), Mdot);
  Value w[3] = {W[2][1], W[0][2], W[1][0]};
  Value T = mul({Q(1, 2), add({mul({S("A"), square(w[0])}), mul({S("B"), square(w[1])}),
                               mul({S("C"), square(w[2])})})});
  auto start = std::chrono::steady_clock::now();
  Value simplified = simplify_value(T);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 0.5);
  RecordProperty("simplify_seconds", std::to_string(seconds));
  // The same energy from the book's omega-body formulas.
  Value sin_psi = fn(Op::Sin, psi), cos_psi = fn(Op::Cos, psi), sin_theta = fn(Op::Sin, theta);
  Value a = add({mul({thetadot, cos_psi}), mul({phidot, sin_theta, sin_psi})});
  Value b = add({mul({N(-1), thetadot, sin_psi}), mul({phidot, sin_theta, cos_psi})});
  Value c = add({mul({phidot, fn(Op::Cos, theta)}), psidot});
  Value T2 =
      mul({Q(1, 2),
           add({mul({S("A"), square(a)}), mul({S("B"), square(b)}), mul({S("C"), square(c)})})});
  EXPECT_EQ(pe(sub({simplified, T2})), "0");
  EXPECT_EQ(pe(simplified), pe(T2));
  // omega-c, the simplest component.
  EXPECT_EQ(pe(w[2]), "(+ (* phidot (cos theta)) psidot)");
}

TEST(Simplify, MixedPartialsCommute) {
  Value s = call("up", {S("t"), S("x")});
  Value a = call("((partial 1) ((partial 0) H))", {s});
  Value b = call("((partial 0) ((partial 1) H))", {s});
  EXPECT_EQ(pe(sub({a, b})), "0");
  EXPECT_EQ(pe(a), "(((partial 0) ((partial 1) H)) (up t x))");
}

// Random expressions: the simplified form has the same value at random
// points, is canonical, and simplifies to itself.
class RandomExpressions {
public:
  explicit RandomExpressions(uint32_t seed) : state_(seed) {}

  // `positive`: only operations that keep positive arguments positive, for
  // the arguments of sqrt and log (whose rules assume real, non-negative
  // radicands as scmutils does).
  Value make(int depth, bool positive) {
    uint32_t r = next() % (depth <= 0 ? 3 : 11);
    switch (r) {
    case 0: return S(next() % 2 ? "x" : "y");
    case 1: return N(static_cast<int64_t>(next() % 5) + 1);
    case 2: return Q(static_cast<int64_t>(next() % 7) + 1, static_cast<int64_t>(next() % 3) + 2);
    case 3: return add({make(depth - 1, positive), make(depth - 1, positive)});
    case 4: return mul({make(depth - 1, positive), make(depth - 1, positive)});
    case 5:
      return positive ? div({make(depth - 1, true), make(depth - 1, true)})
                      : sub({make(depth - 1, false), make(depth - 1, false)});
    case 6: return div({make(depth - 1, positive), make(depth - 1, positive)});
    case 7: return expt(make(depth - 1, positive), N(static_cast<int64_t>(next() % 3) + 2));
    case 8:
      if (positive) return make(depth - 1, true);
      return fn(next() % 2 ? Op::Sin : Op::Cos, make(depth - 1, false));
    case 9: return fn(Op::Sqrt, make(depth - 1, true));
    default:
      // log of a positive quantity may be negative, and square roots of
      // squares are taken to be non-negative (as scmutils does).
      if (positive || next() % 2) return fn(Op::Exp, make(depth - 1, false));
      return fn(Op::Log, make(depth - 1, true));
    }
  }

private:
  uint32_t next() {
    state_ = state_ * 1664525u + 1013904223u;
    return state_ >> 8;
  }
  uint32_t state_;
};

// The value of an expression of x and y; *largest grows to the largest
// magnitude met on the way.
double evaluate(ExprId id, double x, double y, double *largest) {
  return expr_evaluate(
      id, [&](const std::string &name) { return name == "x" ? x : y; }, largest);
}

// SICM_FUZZ_SEED and SICM_FUZZ_COUNT run other and more cases, for a longer
// search by hand.
TEST(Simplify, RandomExpressionsKeepTheirValue) {
  uint32_t seed =
      getenv("SICM_FUZZ_SEED") ? static_cast<uint32_t>(atoi(getenv("SICM_FUZZ_SEED"))) : 12345;
  int count = getenv("SICM_FUZZ_COUNT") ? atoi(getenv("SICM_FUZZ_COUNT")) : 400;
  RandomExpressions gen(seed);
  int checked = 0;
  for (int i = 0; i < count; i++) {
    Value e, s;
    try {
      e = gen.make(4, false);
      if (!e.is(Tag::Expr)) continue;
      s = simplify_value(e);
    } catch (const Error &) {
      continue; // numbers out of a function's domain, division by zero
    }
    ExprId raw = static_cast<ExprId>(e.i);
    ExprId simple = s.is(Tag::Expr)     ? static_cast<ExprId>(s.i)
                    : s.is(Tag::Symbol) ? expr_symbol(s.symbol())
                                        : expr_from_number(s);
    EXPECT_TRUE(expr_is_canonical(simple)) << expr_debug_string(simple);
    EXPECT_EQ(simplify_expr(simple), simple) << expr_debug_string(simple);
    for (auto [x, y] : {std::pair{0.7, 1.3}, std::pair{1.9, 0.45}}) {
      double largest = 0;
      double a = evaluate(raw, x, y, &largest), b = evaluate(simple, x, y, &largest);
      if (!std::isfinite(a) || !std::isfinite(b) || largest > 1e3) continue;
      EXPECT_NEAR(a, b, 1e-7 * (1 + std::fabs(a)))
          << expr_debug_string(raw) << "\n => " << expr_debug_string(simple);
      checked++;
    }
  }
  EXPECT_GT(checked, 300);
}

} // namespace
} // namespace sicm
