// Unit tests of structures, matrices and generic arithmetic (algebra/structure.hpp, generic.hpp).
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "algebra/generic.hpp"
#include "algebra/structure.hpp"
#include "print/printer.hpp"

namespace {

using sicm::Value;

Value fx(int64_t i) {
  return Value::fixnum(i);
}

Value up(std::initializer_list<Value> xs) {
  return sicm::make_structure_from(true, xs.begin(), xs.size());
}

Value down(std::initializer_list<Value> xs) {
  return sicm::make_structure_from(false, xs.begin(), xs.size());
}

Value matrix(size_t rows, size_t cols, std::initializer_list<int64_t> entries) {
  Value m = sicm::make_matrix(rows, cols);
  size_t k = 0;
  for (int64_t e : entries)
    sicm::as_matrix(m)->items[k++] = fx(e);
  return m;
}

std::string show(Value v) {
  return sicm::write_string(v);
}

TEST(Structure, PrintsAsUpAndDown) {
  EXPECT_EQ(show(up({fx(1), down({fx(2), fx(3)})})), "(up 1 (down 2 3))");
  EXPECT_EQ(show(up({})), "(up)");
  EXPECT_EQ(show(matrix(2, 2, {1, 2, 3, 4})), "(matrix-by-rows (list 1 2) (list 3 4))");
}

TEST(Structure, DimensionAndLeaves) {
  Value s = up({fx(1), down({fx(2), fx(3)}), up({down({fx(4)})})});
  EXPECT_EQ(sicm::structure_dimension(s), 4u);
  EXPECT_EQ(sicm::structure_dimension(fx(7)), 1u);
  sicm::gcvec<Value> leaves;
  sicm::structure_leaves(s, leaves);
  ASSERT_EQ(leaves.size(), 4u);
  EXPECT_EQ(leaves[3].i, 4);
  // Rebuilding with the dual shape exchanges up and down at every level.
  EXPECT_EQ(show(sicm::shape_from_leaves(s, true, leaves.data())),
            "(down 1 (up 2 3) (down (up 4)))");
}

TEST(Structure, DownTimesUpContracts) {
  Value p = down({fx(1), fx(2), fx(3)}), v = up({fx(4), fx(5), fx(6)});
  EXPECT_EQ(show(sicm::g_mul(p, v)), "32");
  EXPECT_EQ(show(sicm::g_mul(v, p)), "32");
}

TEST(Structure, UpTimesUpScalesEachComponent) {
  Value a = up({fx(1), fx(2)}), b = up({fx(3), fx(4)});
  EXPECT_EQ(show(sicm::g_mul(a, b)), "(up (up 3 6) (up 4 8))");
}

TEST(Structure, ContractionIsNotAssociative) {
  // The book's example (appendix "Our Notation", p.481).
  Value u = up({fx(5), fx(2)}), v = up({fx(11), fx(13)});
  Value g = down({down({fx(3), fx(5)}), down({fx(7), fx(9)})});
  EXPECT_EQ(show(sicm::g_mul(u, sicm::g_mul(g, v))), "964");
  EXPECT_EQ(show(sicm::g_mul(sicm::g_mul(u, g), v)), "878");
}

TEST(Structure, AddingZeroKeepsTheShape) {
  Value s = up({fx(1), fx(2)});
  EXPECT_TRUE(sicm::eq(sicm::g_add(fx(0), s), s));
  EXPECT_EQ(show(sicm::g_add(s, s)), "(up 2 4)");
  EXPECT_EQ(show(sicm::g_square(s)), "5");
  EXPECT_TRUE(sicm::g_zero_p(up({fx(0), down({fx(0)})})));
}

TEST(Structure, InverseOfDownOfDownsIsUpOfUps) {
  Value s = down({down({fx(1), fx(0)}), down({fx(1), fx(1)})});
  Value inverse = sicm::structure_inverse(s, "test");
  EXPECT_EQ(show(inverse), "(up (up 1 0) (up -1 1))");
  Value v = up({fx(2), fx(3)});
  EXPECT_EQ(show(sicm::g_mul(inverse, sicm::g_mul(s, v))), "(up 2 3)");
}

TEST(Structure, NestedMassMatrixDividesAsItsFlattenedMatrix) {
  // The Hessian of 1/2 (v1.v1) + 2 (v2.v2) + v1.v2 in v = (up (up a b) (up c d)):
  // flattened, [[1 0 1 0] [0 1 0 1] [1 0 4 0] [0 1 0 4]].
  auto block = [](int64_t a, int64_t c) {
    return down({down({down({fx(a), fx(0)}), down({fx(c), fx(0)})}),
                 down({down({fx(0), fx(a)}), down({fx(0), fx(c)})})});
  };
  Value m = down({block(1, 1), block(1, 4)});
  Value v = up({up({fx(1), fx(2)}), up({fx(3), fx(4)})});
  Value p = sicm::g_mul(m, v);
  EXPECT_EQ(show(p), "(down (down 4 6) (down 13 18))");
  EXPECT_EQ(show(sicm::divide_by_structure(p, m)), "(up (up 1 2) (up 3 4))");
  Value inverse = sicm::structure_inverse(m, "test");
  EXPECT_EQ(show(sicm::g_mul(inverse, p)), "(up (up 1 2) (up 3 4))");
  EXPECT_EQ(show(sicm::determinant(m)), "9");
}

TEST(Structure, DivisionWithoutASquareMapIsAnError) {
  EXPECT_THROW(sicm::divide_by_structure(up({fx(1), fx(2)}), down({fx(3), fx(4)})), sicm::Error);
  EXPECT_THROW(sicm::structure_inverse(down({down({fx(1), fx(2), fx(3)})}), "test"), sicm::Error);
}

TEST(Matrix, ProductInverseDeterminant) {
  Value a = matrix(2, 2, {1, 2, 3, 4});
  EXPECT_EQ(show(sicm::g_mul(a, a)), "(matrix-by-rows (list 7 10) (list 15 22))");
  EXPECT_EQ(show(sicm::matrix_inverse(a, "test")), "(matrix-by-rows (list -2 1) (list 3/2 -1/2))");
  EXPECT_EQ(show(sicm::determinant(a)), "-2");
  EXPECT_EQ(show(sicm::determinant(matrix(3, 3, {2, 0, 1, 1, 3, 2, 1, 1, 2}))), "6");
  EXPECT_EQ(show(sicm::g_mul(a, up({fx(1), fx(1)}))), "(up 3 7)");
}

TEST(Matrix, SingularInverseIsAnError) {
  EXPECT_THROW(sicm::matrix_inverse(matrix(2, 2, {1, 2, 2, 4}), "test"), sicm::Error);
}

TEST(Generic, ArithmeticTypesByRank) {
  EXPECT_EQ(sicm::arith_type_of(fx(1)), nullptr);
  ASSERT_NE(sicm::arith_type_of(up({})), nullptr);
  EXPECT_STREQ(sicm::arith_type_of(up({}))->name, "structure");
  EXPECT_STREQ(sicm::arith_type_of(matrix(1, 1, {0}))->name, "structure");
  Value car = sicm::intern("car").symbol()->global;
  ASSERT_NE(sicm::arith_type_of(car), nullptr);
  EXPECT_STREQ(sicm::arith_type_of(car)->name, "function");
  EXPECT_EQ(sicm::arith_type_of(sicm::make_string("x")), nullptr);
}

} // namespace
