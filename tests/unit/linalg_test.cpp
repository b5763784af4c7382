// Unit tests of the runtime's linear algebra (sicm/linalg.h): eigenvalues
// (over Eigen) against eigenvalues known in closed form, and the solve built
// programs use outside kernels against solutions known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

struct Eigenvalues {
  int status;
  std::vector<double> re, im;
};

Eigenvalues eigenvalues(size_t n, const std::vector<double> &a) {
  Eigenvalues e{0, std::vector<double>(n), std::vector<double>(n)};
  e.status = sicm_linalg_eigenvalues(n, a.data(), e.re.data(), e.im.data());
  return e;
}

// A rotation by theta has the eigenvalues cos theta +- i sin theta, on the unit circle.
TEST(LinalgEigenvalues, Rotation) {
  for (double theta : {0.3, 1.0, 2.5}) {
    Eigenvalues e =
        eigenvalues(2, {std::cos(theta), -std::sin(theta), std::sin(theta), std::cos(theta)});
    ASSERT_EQ(e.status, SICM_SUCCESS);
    EXPECT_NEAR(e.re[0], std::cos(theta), 1e-15);
    EXPECT_NEAR(e.im[0], std::sin(theta), 1e-15); // the positive imaginary part first
    EXPECT_NEAR(e.re[1], std::cos(theta), 1e-15);
    EXPECT_NEAR(e.im[1], -std::sin(theta), 1e-15);
  }
}

// The symmetric tridiagonal matrix with 2 on the diagonal and -1 beside it,
// of size n, has the eigenvalues 2 - 2 cos(k pi / (n + 1)), k = 1..n.
TEST(LinalgEigenvalues, SymmetricTridiagonal) {
  const size_t n = 6;
  std::vector<double> a(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    a[i * n + i] = 2;
    if (i + 1 < n) a[i * n + i + 1] = a[(i + 1) * n + i] = -1;
  }
  Eigenvalues e = eigenvalues(n, a);
  ASSERT_EQ(e.status, SICM_SUCCESS);
  for (size_t k = 0; k < n; ++k) { // decreasing: k = n, n - 1, ..., 1
    double expected = 2 - 2 * std::cos(static_cast<double>(n - k) * M_PI / (n + 1));
    EXPECT_NEAR(e.re[k], expected, 1e-14);
    EXPECT_EQ(e.im[k], 0.0);
  }
}

// The Jordan block ((2 1) (0 2)) is defective: 2 twice, with one eigenvector.
// The perturbed block ((2 1) (d 2)) has the eigenvalues 2 +- sqrt(d), so an
// eigenvalue of multiplicity two is known only to about sqrt(epsilon).
TEST(LinalgEigenvalues, Defective) {
  Eigenvalues e = eigenvalues(2, {2, 1, 0, 2});
  ASSERT_EQ(e.status, SICM_SUCCESS);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(e.re[k], 2.0, 1e-7);
    EXPECT_NEAR(e.im[k], 0.0, 1e-7);
  }
  Eigenvalues p = eigenvalues(2, {2, 1, 1e-6, 2});
  ASSERT_EQ(p.status, SICM_SUCCESS);
  EXPECT_NEAR(p.re[0], 2 + 1e-3, 1e-12);
  EXPECT_NEAR(p.re[1], 2 - 1e-3, 1e-12);
}

// The standard map's linearization at (0, 0), ((1 + K 1) (K 1)), has the
// multipliers 1 + K/2 +- sqrt(K + K^2/4), whose product is 1.
TEST(LinalgEigenvalues, StandardMapFixedPoint) {
  double K = 0.8;
  Eigenvalues e = eigenvalues(2, {1 + K, 1, K, 1});
  ASSERT_EQ(e.status, SICM_SUCCESS);
  EXPECT_NEAR(e.re[0], 1 + K / 2 + std::sqrt(K + K * K / 4), 1e-14);
  EXPECT_NEAR(e.re[1], 1 + K / 2 - std::sqrt(K + K * K / 4), 1e-14);
  EXPECT_NEAR(e.re[0] * e.re[1], 1.0, 1e-14);
}

// A 3 x 3 upper triangular matrix: its diagonal, sorted by decreasing modulus.
TEST(LinalgEigenvalues, TriangularOrder) {
  Eigenvalues e = eigenvalues(3, {1, 5, 7, 0, -3, 2, 0, 0, 2});
  ASSERT_EQ(e.status, SICM_SUCCESS);
  EXPECT_NEAR(e.re[0], -3, 1e-14);
  EXPECT_NEAR(e.re[1], 2, 1e-14);
  EXPECT_NEAR(e.re[2], 1, 1e-14);
}

TEST(LinalgEigenvalues, RejectsBadInput) {
  CaptureErrors capture;
  double re[2], im[2];
  EXPECT_EQ(sicm_linalg_eigenvalues(0, nullptr, re, im), SICM_EINVAL);
  const double bad[] = {1, NAN, 0, 1};
  EXPECT_EQ(sicm_linalg_eigenvalues(2, bad, re, im), SICM_EINVAL);
  ASSERT_EQ(CaptureErrors::messages().size(), 2u);
  EXPECT_NE(CaptureErrors::messages()[1].find("(0, 1)"), std::string::npos);
}

// sicm_linalg_solve_as_interpreted: a system with an exact solution (the
// pivots 4, then 2.5 after a row exchange, are exact in binary), one that
// needs a row exchange for a zero pivot, and a singular one.
TEST(LinalgSolveAsInterpreted, SolvesExactly) {
  // A x = b with x = (1, -2, 3).
  std::vector<double> a = {4, 2, 0, 2, 4, 1, 0, 1, 2}, b = {0, -3, 4}, x(3);
  ASSERT_EQ(sicm_linalg_solve_as_interpreted(3, a.data(), b.data(), x.data()), SICM_SUCCESS);
  EXPECT_NEAR(x[0], 1, 1e-15);
  EXPECT_NEAR(x[1], -2, 1e-15);
  EXPECT_NEAR(x[2], 3, 1e-15);
}

TEST(LinalgSolveAsInterpreted, ExchangesRowsForAZeroPivot) {
  std::vector<double> a = {0, 1, 1, 0}, b = {5, 7}, x(2);
  ASSERT_EQ(sicm_linalg_solve_as_interpreted(2, a.data(), b.data(), x.data()), SICM_SUCCESS);
  EXPECT_EQ(x[0], 7);
  EXPECT_EQ(x[1], 5);
}

TEST(LinalgSolveAsInterpreted, SingularGivesNaN) {
  std::vector<double> a = {1, 2, 2, 4}, b = {1, 1}, x(2);
  EXPECT_EQ(sicm_linalg_solve_as_interpreted(2, a.data(), b.data(), x.data()), SICM_ESINGULAR);
  EXPECT_TRUE(std::isnan(x[0]) && std::isnan(x[1]));
}

// The NaN a kernel writes for a singular matrix is told apart from others.
TEST(SingularNaN, RecognizedByItsBits) {
  double d;
  unsigned long long bits = SICM_SINGULAR_NAN_BITS;
  static_assert(sizeof d == sizeof bits);
  std::memcpy(&d, &bits, sizeof d);
  EXPECT_TRUE(std::isnan(d));
  EXPECT_TRUE(sicm_is_singular_nan(d));
  EXPECT_FALSE(sicm_is_singular_nan(NAN));
  EXPECT_FALSE(sicm_is_singular_nan(1.0));
}

} // namespace
