// Unit tests of the runtime's minimizers (Brent, Nelder-Mead) and root finder (Brent) against
// known minima and roots.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

double shifted_parabola(double x, void *) {
  return (x - 2) * (x - 2) + 1;
}

TEST(MinBrent, Parabola) {
  for (double tol : {1e-4, 1e-8, 1e-12}) {
    double x = 0, f = 0;
    int iterations = 0;
    ASSERT_EQ(sicm_min_brent(shifted_parabola, nullptr, 0, 5, tol, &x, &f, &iterations),
              SICM_SUCCESS);
    EXPECT_NEAR(x, 2.0, 1e-7);
    EXPECT_DOUBLE_EQ(f, 1.0);
    EXPECT_GT(iterations, 0);
    EXPECT_LT(iterations, 50);
  }
}

double cosine(double x, void *) {
  return std::cos(x);
}

TEST(MinBrent, CosineHasItsMinimumAtPi) {
  double x = 0, f = 0;
  ASSERT_EQ(sicm_min_brent(cosine, nullptr, 2, 4, 1e-10, &x, &f, nullptr), SICM_SUCCESS);
  EXPECT_NEAR(x, M_PI, 3e-8); // a minimum is only located to about sqrt(eps) |x|
  EXPECT_DOUBLE_EQ(f, -1.0);
}

double identity(double x, void *) {
  return x;
}

TEST(MinBrent, MonotoneFunctionGivesTheLowerEnd) {
  double x = 1, f = 1;
  int iterations = -1;
  ASSERT_EQ(sicm_min_brent(identity, nullptr, -1, 3, 1e-8, &x, &f, &iterations), SICM_SUCCESS);
  EXPECT_EQ(x, -1);
  EXPECT_EQ(f, -1);
  EXPECT_EQ(iterations, 0);
}

// A minimum away from the golden-section point, found through the grid.
double narrow_well(double x, void *) {
  return -std::exp(-1e4 * (x - 0.9) * (x - 0.9));
}

TEST(MinBrent, NarrowWellNeedsTheGrid) {
  double x = 0, f = 0;
  ASSERT_EQ(sicm_min_brent(narrow_well, nullptr, 0, 1, 1e-10, &x, &f, nullptr), SICM_SUCCESS);
  EXPECT_NEAR(x, 0.9, 1e-7);
  EXPECT_NEAR(f, -1.0, 1e-14);
}

double nan_above_one(double x, void *) {
  return x > 1 ? NAN : x * x;
}

TEST(MinBrent, Errors) {
  CaptureErrors capture;
  double x, f;
  EXPECT_EQ(sicm_min_brent(shifted_parabola, nullptr, 5, 0, 1e-8, &x, &f, nullptr), SICM_EINVAL);
  EXPECT_EQ(sicm_min_brent(shifted_parabola, nullptr, 0, 5, 0, &x, &f, nullptr), SICM_EINVAL);
  EXPECT_EQ(sicm_min_brent(nan_above_one, nullptr, -1, 2, 1e-8, &x, &f, nullptr), SICM_EBADFUNC);
  ASSERT_EQ(CaptureErrors::messages().size(), 3u);
  EXPECT_NE(CaptureErrors::messages()[2].find("not a finite number"), std::string::npos);
}

double rosenbrock(const double *x, void *) {
  const double a = 1 - x[0], b = x[1] - x[0] * x[0];
  return a * a + 100 * b * b;
}

TEST(MinNelderMead, Rosenbrock) {
  double x[2] = {-1.2, 1}, f = 1;
  int iterations = 0;
  ASSERT_EQ(sicm_min_nelder_mead(rosenbrock, nullptr, 2, x, 0.5, 1e-10, 5000, &f, &iterations),
            SICM_SUCCESS);
  EXPECT_NEAR(x[0], 1.0, 1e-6);
  EXPECT_NEAR(x[1], 1.0, 1e-6);
  EXPECT_LT(f, 1e-12);
  EXPECT_GT(iterations, 10);
}

double sphere4(const double *x, void *) {
  double s = 0;
  for (int i = 0; i < 4; i++)
    s += (x[i] - i) * (x[i] - i);
  return s;
}

TEST(MinNelderMead, FourDimensions) {
  double x[4] = {5, 5, 5, 5}, f = 1;
  ASSERT_EQ(sicm_min_nelder_mead(sphere4, nullptr, 4, x, 1.0, 1e-10, 10000, &f, nullptr),
            SICM_SUCCESS);
  for (int i = 0; i < 4; i++)
    EXPECT_NEAR(x[i], i, 1e-6);
}

TEST(MinNelderMead, IterationLimit) {
  CaptureErrors capture;
  double x[2] = {-1.2, 1}, f = 0;
  int iterations = 0;
  EXPECT_EQ(sicm_min_nelder_mead(rosenbrock, nullptr, 2, x, 0.5, 1e-10, 10, &f, &iterations),
            SICM_EMAXITER);
  EXPECT_EQ(iterations, 10);
  EXPECT_EQ(f, rosenbrock(x, nullptr)); // x is the best point so far
  ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  EXPECT_EQ(sicm_min_nelder_mead(rosenbrock, nullptr, 0, x, 0.5, 1e-10, 10, &f, nullptr),
            SICM_EINVAL);
}

double cos_minus_x(double x, void *) {
  return std::cos(x) - x;
}

TEST(RootBrent, DottieNumber) {
  double r = 0;
  ASSERT_EQ(sicm_root_brent(cos_minus_x, nullptr, 0, 1, 0, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 0.7390851332151607, 2e-16);
  ASSERT_EQ(sicm_root_brent(cos_minus_x, nullptr, 0, 1, 1e-6, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 0.7390851332151607, 1e-6);
}

double cubic(double x, void *) {
  return (x - 1) * (x - 1) * (x - 1);
}

TEST(RootBrent, EndpointsAndBrackets) {
  double r = 0;
  ASSERT_EQ(sicm_root_brent(cubic, nullptr, 1, 3, 0, &r), SICM_SUCCESS);
  EXPECT_EQ(r, 1); // f(a) = 0
  ASSERT_EQ(sicm_root_brent(cubic, nullptr, -2, 3, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 1, 1e-11);
  CaptureErrors capture;
  EXPECT_EQ(sicm_root_brent(cos_minus_x, nullptr, 2, 3, 0, &r), SICM_EBRACKET);
  ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  EXPECT_NE(CaptureErrors::messages()[0].find("same sign"), std::string::npos)
      << CaptureErrors::messages()[0];
  EXPECT_EQ(sicm_root_brent(cos_minus_x, nullptr, 1, 0, 0, &r), SICM_EINVAL);
}

} // namespace
