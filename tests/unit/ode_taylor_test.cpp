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

// The same Kepler order of convergence: fixed steps of a period / n at
// tolerance 1e-3 (p = 5), e = 0.5, back at periapsis after one period.
TEST(OdeTaylor, KeplerOrderOfConvergence) {
  const double e = 0.5, period = 2 * M_PI;
  const double start[4] = {1 - e, 0, 0, std::sqrt((1 + e) / (1 - e))};
  double previous = 0;
  for (int n = 400; n <= 3200; n *= 2) {
    sicm_ode *o = taylor(4, kepler_series, 1e-3);
    double t = 0, s[4] = {start[0], start[1], start[2], start[3]};
    for (int i = 1; i <= n; ++i)
      ASSERT_EQ(sicm_ode_evolve(o, &t, period * i / n, s), SICM_SUCCESS);
    double error = 0;
    for (int i = 0; i < 4; ++i)
      error = std::fmax(error, std::fabs(s[i] - start[i]));
    if (previous > 0) {
      EXPECT_NEAR(std::log2(previous / error), 5, 0.3) << n << " steps";
    }
    previous = error;
    sicm_ode_free(o);
  }
}

// Dense output: with the horizon set, a monitor loop that stops every
// 1/100 takes the steps one call would and each stop is as accurate as a
// step.
TEST(OdeTaylor, DenseOutputCostsNoSteps) {
  const double t_end = 20;
  sicm_ode *once = taylor(2, oscillator_series, 1e-14);
  double t = 0, y[2] = {1, 0};
  ASSERT_EQ(sicm_ode_evolve(once, &t, t_end, y), SICM_SUCCESS);
  const unsigned long steps_once = sicm_ode_get_stats(once)->steps;
  sicm_ode_free(once);

  sicm_ode *o = taylor(2, oscillator_series, 1e-14);
  sicm_ode_set_horizon(o, t_end);
  double u = 0, z[2] = {1, 0};
  for (int i = 1; i <= 2000; ++i) {
    const double ti = t_end * i / 2000;
    ASSERT_EQ(sicm_ode_evolve(o, &u, ti, z), SICM_SUCCESS) << sicm_ode_last_error(o);
    ASSERT_NEAR(z[0], std::cos(ti), 1e-13) << "t = " << ti;
    ASSERT_NEAR(z[1], -std::sin(ti), 1e-13) << "t = " << ti;
  }
  EXPECT_LE(sicm_ode_get_stats(o)->steps, steps_once + 1);
  EXPECT_LT(steps_once, 100u); // so that many of the 2000 stops fall inside each step
  sicm_ode_free(o);
}

// A caller who changes the state between calls (a map that kicks the
// system) is followed: the method starts afresh from the new state.
TEST(OdeTaylor, ChangedStateStartsAfresh) {
  sicm_ode *o = taylor(2, oscillator_series, 1e-14);
  sicm_ode_set_horizon(o, 10);
  double t = 0, y[2] = {1, 0};
  ASSERT_EQ(sicm_ode_evolve(o, &t, 1, y), SICM_SUCCESS);
  y[0] = 1; // back to the start, at t = 1
  y[1] = 0;
  ASSERT_EQ(sicm_ode_evolve(o, &t, 2, y), SICM_SUCCESS);
  EXPECT_NEAR(y[0], std::cos(1.0), 1e-13);
  EXPECT_NEAR(y[1], -std::sin(1.0), 1e-13);
  sicm_ode_free(o);
}

// x' = v, v' = -x in long double.
void oscillator_series_extended(const long double *y, int order, long double *c, const double *) {
  c[0] = y[0];
  c[1] = y[1];
  for (int k = 0; k < order; ++k) {
    c[(k + 1) * 2 + 0] = c[k * 2 + 1] / (k + 1);
    c[(k + 1) * 2 + 1] = -c[k * 2 + 0] / (k + 1);
  }
}

// taylor-extended is accurate to long double. After one period T (the
// double nearest 2 pi) the velocity -sin T is tiny (2.4e-16), so its double
// holds it to 1e-32 and shows the integrator's absolute error: under 1e-18
// in long double, where double's is some 1e-16.
TEST(OdeTaylor, ExtendedIsAccurateToLongDouble) {
  const double period = 2 * M_PI;
  const long double want = -sinl((long double)period);
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_taylor_extended, 2, unused_rhs, nullptr, 1e-20, 1e-20);
  ASSERT_NE(o, nullptr);
  sicm_ode_set_taylor_extended(o, oscillator_series_extended, nullptr);
  sicm_ode_set_horizon(o, period);
  double t = 0, y[2] = {1, 0};
  for (int i = 1; i <= 10; ++i) // stops in the middle of steps: dense output in long double
    ASSERT_EQ(sicm_ode_evolve(o, &t, period * i / 10, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  EXPECT_LT(std::fabs((double)(y[1] - want)), 1e-18) << y[1] << " vs " << (double)want;
  EXPECT_EQ(y[0], 1.0);
  sicm_ode_free(o);

  sicm_ode *d = taylor(2, oscillator_series, 1e-16);
  double u = 0, z[2] = {1, 0};
  ASSERT_EQ(sicm_ode_evolve(d, &u, period, z), SICM_SUCCESS);
  EXPECT_GT(std::fabs((double)(z[1] - want)), 1e-18); // what double cannot do
  sicm_ode_free(d);
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
