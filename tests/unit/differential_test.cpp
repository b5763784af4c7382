// Unit tests of differential objects: the algebra of tagged infinitesimals
// and the extraction D relies on.
#include <gtest/gtest.h>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/symbolic.hpp"
#include "print/printer.hpp"

using namespace sicm;

namespace {

std::string show(Value v) {
  return write_string(expression_to_datum(simplify_value(v)));
}

// The procedure y |-> a * y, for a captured in the NativeProc.
Value times_captured(NativeProc *self, Value *args, int) {
  return g_mul(self->a, args[0]);
}

} // namespace

TEST(Differential, InfinitesimalSquaredIsZero) {
  uint32_t e = fresh_differential_tag();
  Value de = times_infinitesimal(Value::fixnum(1), e);
  EXPECT_TRUE(is_differential(de));
  Value sq = g_mul(de, de);
  EXPECT_FALSE(is_differential(sq));
  EXPECT_EQ(write_string(sq), "0");
}

TEST(Differential, ProductRuleOnDualNumbers) {
  // (3 + e)(5 + 2e) = 15 + 11e
  uint32_t e = fresh_differential_tag();
  Value a = add_infinitesimal(Value::fixnum(3), e);
  Value b = g_add(Value::fixnum(5), times_infinitesimal(Value::fixnum(2), e));
  Value p = g_mul(a, b);
  Value finite, tangent;
  split_differential(p, e, &finite, &tangent);
  EXPECT_EQ(write_string(finite), "15");
  EXPECT_EQ(write_string(tangent), "11");
}

TEST(Differential, DistinctTagsMultiplyIntoCrossTerms) {
  // (x + e1)(y + e2) = xy + y e1 + x e2 + e1 e2: the e1 e2 coefficient is 1.
  uint32_t e1 = fresh_differential_tag(), e2 = fresh_differential_tag();
  Value x = add_infinitesimal(intern("x"), e1);
  Value y = add_infinitesimal(intern("y"), e2);
  Value p = g_mul(x, y);
  EXPECT_EQ(max_differential_tag(p), e2);
  Value d2 = extract_tangent(p, e2); // x + e1
  EXPECT_EQ(show(extract_tangent(d2, e1)), "1");
  EXPECT_EQ(show(extract_tangent(extract_tangent(p, e1), e2)), "1");
}

TEST(Differential, ChainRuleThroughSin) {
  // sin(x + e) = sin x + cos(x) e
  uint32_t e = fresh_differential_tag();
  Value s = g_unary(UnaryOp::Sin, add_infinitesimal(intern("x"), e));
  EXPECT_EQ(show(extract_tangent(s, e)), "(cos x)");
}

TEST(Differential, ExtractionIgnoresOtherTags) {
  // Only the asked-for tag is extracted: the heart of avoiding perturbation
  // confusion in nested derivatives.
  uint32_t outer = fresh_differential_tag(), inner = fresh_differential_tag();
  Value v = g_add(times_infinitesimal(Value::fixnum(7), outer),
                  times_infinitesimal(Value::fixnum(9), inner));
  EXPECT_EQ(write_string(extract_tangent(v, outer)), "7");
  EXPECT_EQ(write_string(extract_tangent(v, inner)), "9");
  EXPECT_EQ(write_string(extract_tangent(Value::fixnum(4), inner)), "0");
}

TEST(Differential, TangentOfProcedureHidesItsTag) {
  // P = y |-> (3 + e) y is what f x = (y |-> x y) gives at x = 3 + e; its
  // tangent T is y |-> y. Called with an argument that carries e from
  // another calculation (2 + e), T must give 2 + e, the caller's e intact,
  // not the coefficient 5 of e in (3 + e)(2 + e) = 6 + 5e.
  uint32_t e = fresh_differential_tag();
  Value p = make_native_procedure(times_captured, 0, add_infinitesimal(Value::fixnum(3), e),
                                  Value::nil());
  Value t = extract_tangent(p, e);
  Value arg = add_infinitesimal(Value::fixnum(2), e);
  Value r = apply_procedure(t, &arg, 1);
  Value finite, tangent;
  split_differential(r, e, &finite, &tangent);
  EXPECT_EQ(write_string(finite), "2");
  EXPECT_EQ(write_string(tangent), "1");
  // Without e in the argument, T is just y |-> y.
  Value seven = Value::fixnum(7);
  EXPECT_EQ(write_string(apply_procedure(t, &seven, 1)), "7");
}
