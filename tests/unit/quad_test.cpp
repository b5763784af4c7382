// Unit tests of the runtime's quadrature (adaptive Gauss-Kronrod, Romberg) against integrals
// known in closed form, and of the error hook they report through.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

double sine(double x, void *) {
  return std::sin(x);
}
double square_root(double x, void *) {
  return std::sqrt(x);
}
double gaussian(double x, void *) {
  return std::exp(-x * x);
}
double nan_above_half(double x, void *) {
  return x > 0.5 ? NAN : x;
}

TEST(QuadIntegrate, SineOverHalfPeriod) {
  double r = 0;
  ASSERT_EQ(sicm_quad_integrate(sine, nullptr, 0, M_PI, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 2.0, 2e-12);
  ASSERT_EQ(sicm_quad_integrate(sine, nullptr, M_PI, 0, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, -2.0, 2e-12);
  ASSERT_EQ(sicm_quad_integrate(sine, nullptr, 1, 1, 1e-12, &r), SICM_SUCCESS);
  EXPECT_EQ(r, 0);
}

TEST(QuadIntegrate, SquareRootWithSingularDerivative) {
  double r = 0;
  ASSERT_EQ(sicm_quad_integrate(square_root, nullptr, 0, 1, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 2.0 / 3.0, 1e-12);
}

TEST(QuadIntegrate, InfiniteLimits) {
  double r = 0;
  ASSERT_EQ(sicm_quad_integrate(gaussian, nullptr, -INFINITY, INFINITY, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, std::sqrt(M_PI), 1e-12);
  ASSERT_EQ(sicm_quad_integrate(gaussian, nullptr, 0, INFINITY, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, std::sqrt(M_PI) / 2, 1e-12);
  ASSERT_EQ(sicm_quad_integrate(gaussian, nullptr, -INFINITY, 0, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, std::sqrt(M_PI) / 2, 1e-12);
}

TEST(QuadIntegrate, FailuresAreReportedClearly) {
  CaptureErrors capture;
  double r = 1;
  // A zero integral cannot meet a purely relative tolerance; the estimate is still returned.
  EXPECT_EQ(sicm_quad_integrate(sine, nullptr, 0, 2 * M_PI, 1e-10, &r), SICM_ETOL);
  EXPECT_LT(std::fabs(r), 1e-12);
  ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  EXPECT_NE(CaptureErrors::messages()[0].find("cannot reach relative tolerance"), std::string::npos)
      << CaptureErrors::messages()[0];
  EXPECT_EQ(CaptureErrors::statuses()[0], SICM_ETOL);
  EXPECT_EQ(sicm_quad_integrate(nan_above_half, nullptr, 0, 1, 1e-10, &r), SICM_EBADFUNC);
  EXPECT_EQ(sicm_quad_integrate(sine, nullptr, 0, 1, 0, &r), SICM_EINVAL);
  EXPECT_EQ(sicm_quad_integrate(sine, nullptr, NAN, 1, 1e-8, &r), SICM_EINVAL);
  EXPECT_EQ(CaptureErrors::messages().size(), 4u);
}

TEST(QuadRomberg, SmoothAndSingularIntegrands) {
  double r = 0;
  ASSERT_EQ(sicm_quad_romberg(sine, nullptr, 0, M_PI, 1e-12, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 2.0, 1e-12);
  // sqrt has an unbounded derivative at 0: Romberg converges, but slowly.
  ASSERT_EQ(sicm_quad_romberg(square_root, nullptr, 0, 1, 1e-8, &r), SICM_SUCCESS);
  EXPECT_NEAR(r, 2.0 / 3.0, 1e-8);
  CaptureErrors capture;
  EXPECT_EQ(sicm_quad_romberg(square_root, nullptr, 0, 1, 1e-13, &r), SICM_ETOL);
  EXPECT_NEAR(r, 2.0 / 3.0, 1e-9);
  EXPECT_EQ(sicm_quad_romberg(sine, nullptr, 0, INFINITY, 1e-8, &r), SICM_EINVAL);
  EXPECT_EQ(CaptureErrors::messages().size(), 2u);
}

TEST(ErrorHook, DefaultHandlerAndStrerror) {
  EXPECT_EQ(sicm_set_error_handler(nullptr), nullptr); // the default was in place
  EXPECT_STREQ(sicm_strerror(SICM_SUCCESS), "success");
  EXPECT_STREQ(sicm_strerror(SICM_ESTEP), "step size too small");
  EXPECT_STREQ(sicm_strerror(12345), "unknown status");
  testing::internal::CaptureStderr();
  EXPECT_EQ(sicm_error(SICM_EINVAL, "bad %s %d", "thing", 3), SICM_EINVAL);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "sicm: bad thing 3\n");
}

} // namespace
