// Unit tests of the Taylor integrator (sicm_ode_step_taylor) with hand-written coefficient
// functions: accuracy against analytic solutions, its order of convergence, its failures.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

// Never called: the taylor method takes its coefficients from oscillator_series.
int unused_rhs(double, const double *, double *, void *) {
  return 1;
}

// x' = v, v' = -x.
void oscillator_series(const double *y, int order, double *c, const double *) {
  c[0] = y[0];
  c[1] = y[1];
  for (int k = 0; k < order; ++k) {
    c[(k + 1) * 2 + 0] = c[k * 2 + 1] / (k + 1);
    c[(k + 1) * 2 + 1] = -c[k * 2 + 0] / (k + 1);
  }
}

// The Kepler problem with GM = 1, state (x, y, vx, vy): r2 = x^2 + y^2,
// w = r2^(-3/2), (vx, vy)' = -w (x, y), by the product and power recurrences.
void kepler_series(const double *s, int order, double *c, const double *) {
  double r2[SICM_ODE_TAYLOR_MAX_ORDER + 1], w[SICM_ODE_TAYLOR_MAX_ORDER + 1];
  for (int i = 0; i < 4; ++i)
    c[i] = s[i];
  auto at = [&](int k, int i) -> double & { return c[k * 4 + i]; };
  for (int k = 0; k < order; ++k) {
    r2[k] = 0;
    for (int j = 0; j <= k; ++j)
      r2[k] += at(j, 0) * at(k - j, 0) + at(j, 1) * at(k - j, 1);
    if (k == 0) {
      w[0] = std::pow(r2[0], -1.5);
    } else {
      double sum = 0;
      for (int j = 0; j < k; ++j)
        sum += (-1.5 * (k - j) - j) * r2[k - j] * w[j];
      w[k] = sum / (k * r2[0]);
    }
    double ax = 0, ay = 0;
    for (int j = 0; j <= k; ++j) {
      ax -= w[j] * at(k - j, 0);
      ay -= w[j] * at(k - j, 1);
    }
    at(k + 1, 0) = at(k, 2) / (k + 1);
    at(k + 1, 1) = at(k, 3) / (k + 1);
    at(k + 1, 2) = ax / (k + 1);
    at(k + 1, 3) = ay / (k + 1);
  }
}

sicm_ode *taylor(size_t dim, sicm_ode_taylor_coefficients f, double tol) {
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_taylor, dim, unused_rhs, nullptr, tol, tol);
  if (o) sicm_ode_set_taylor(o, f, nullptr);
  return o;
}

TEST(OdeTaylor, HarmonicOscillatorTenPeriods) {
  sicm_ode *o = taylor(2, oscillator_series, 1e-16);
  ASSERT_NE(o, nullptr);
  double t = 0, y[2] = {1, 0};
  const double t1 = 20 * M_PI;
  ASSERT_EQ(sicm_ode_evolve(o, &t, t1, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  EXPECT_EQ(t, t1);
  EXPECT_NEAR(y[0], std::cos(t1), 1e-14);
  EXPECT_NEAR(y[1], -std::sin(t1), 1e-14);
  const sicm_ode_stats *st = sicm_ode_get_stats(o);
  EXPECT_EQ(st->rhs_evals, st->steps); // one expansion per step
  EXPECT_EQ(st->rejected_steps, 0u);
  sicm_ode_free(o);
}

TEST(OdeTaylor, Backwards) {
  sicm_ode *o = taylor(2, oscillator_series, 1e-14);
  double t = 0, y[2] = {1, 0};
  ASSERT_EQ(sicm_ode_evolve(o, &t, -10, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  EXPECT_NEAR(y[0], std::cos(-10.0), 1e-13);
  EXPECT_NEAR(y[1], -std::sin(-10.0), 1e-13);
  sicm_ode_free(o);
}

// Evolve calls of length H shorter than the controller's step are each one
// Taylor step of exactly that length, of the order p = ceil(-ln(tol)/2) + 1
// the tolerance gives (p = 5 at 1e-3): the global error over a fixed
// interval then falls as H^p.
TEST(OdeTaylor, OrderOfConvergence) {
  const double tol = 1e-3, t_end = 2;
  const int p = static_cast<int>(std::ceil(-std::log(tol) / 2)) + 1;
  ASSERT_EQ(p, 5);
  double previous = 0;
  for (int n = 10; n <= 80; n *= 2) {
    sicm_ode *o = taylor(2, oscillator_series, tol);
    double t = 0, y[2] = {1, 0};
    for (int i = 1; i <= n; ++i)
      ASSERT_EQ(sicm_ode_evolve(o, &t, t_end * i / n, y), SICM_SUCCESS);
    EXPECT_EQ(sicm_ode_get_stats(o)->steps, static_cast<unsigned long>(n));
    double error = std::hypot(y[0] - std::cos(t_end), y[1] + std::sin(t_end));
    if (previous > 0) {
      double order = std::log2(previous / error);
      EXPECT_NEAR(order, p, 0.3) << n << " steps";
    }
    previous = error;
    sicm_ode_free(o);
  }
}

TEST(OdeTaylor, KeplerOnePeriodBackToPeriapsis) {
  const double e = 0.5;
  const double start[4] = {1 - e, 0, 0, std::sqrt((1 + e) / (1 - e))};
  sicm_ode *o = taylor(4, kepler_series, 1e-14);
  double t = 0, s[4] = {start[0], start[1], start[2], start[3]};
  ASSERT_EQ(sicm_ode_evolve(o, &t, 2 * M_PI, s), SICM_SUCCESS) << sicm_ode_last_error(o);
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(s[i], start[i], 1e-12) << "component " << i;
  sicm_ode_free(o);
}

TEST(OdeTaylor, WithoutCoefficientsFailsClearly) {
  CaptureErrors capture;
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_taylor, 2, unused_rhs, nullptr, 1e-10, 1e-10);
  double t = 0, y[2] = {1, 0};
  EXPECT_EQ(sicm_ode_evolve(o, &t, 1, y), SICM_EINVAL);
  EXPECT_NE(std::string(sicm_ode_last_error(o)).find("sicm_ode_set_taylor"), std::string::npos)
      << sicm_ode_last_error(o);
  sicm_ode_free(o);
}

// 1/r at the origin: non-finite coefficients stop the integration there.
void singular_series(const double *y, int order, double *c, const double *) {
  c[0] = y[0];
  for (int k = 0; k < order; ++k)
    c[k + 1] = k == 0 ? -1 / c[0] : 0.0;
}

TEST(OdeTaylor, NonFiniteCoefficientsFail) {
  CaptureErrors capture;
  sicm_ode *o = taylor(1, singular_series, 1e-10);
  double t = 0, y[1] = {0};
  EXPECT_EQ(sicm_ode_evolve(o, &t, 1, y), SICM_EBADFUNC);
  EXPECT_NE(std::string(sicm_ode_last_error(o)).find("non-finite"), std::string::npos);
  sicm_ode_free(o);
}

} // namespace
