// Unit tests of events located inside the integrator (sicm_ode_set_events), against analytic
// crossing times: two close roots, a root of odd multiplicity, a tangency, the zeros of a
// harmonic oscillator, terminal events and resuming from them.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

int unit_rate(double, const double *, double *dy, void *) {
  dy[0] = 1;
  return 0;
}

int oscillator(double, const double *y, double *dy, void *) {
  dy[0] = y[1];
  dy[1] = -y[0];
  return 0;
}

// g(t, y) = (y - 0.5)(y - 0.6) on y = t.
double two_roots(double, const double *y, void *) {
  return (y[0] - 0.5) * (y[0] - 0.6);
}

// g = x^3 for x = y - 1: a root of multiplicity three, where g is flat.
double cubic(double, const double *y, void *) {
  const double x = y[0] - 1;
  return x * x * x;
}

// g = (y - 1)^2: touches 0 at y = 1 without changing sign.
double touching(double, const double *y, void *) {
  return (y[0] - 1) * (y[0] - 1);
}

double position(double, const double *y, void *) {
  return y[0];
}

// The dimension of the system whose events record() records.
size_t event_dim = 1;

struct Located {
  size_t event;
  double t;
  std::vector<double> y;
};

int record(size_t event, double t, const double *y, void *data) {
  auto *out = static_cast<std::vector<Located> *>(data);
  out->push_back({event, t, std::vector<double>(y, y + event_dim)});
  return 0;
}

std::vector<Located> run(const sicm_ode_step_type *T, sicm_ode_rhs f, size_t dim,
                         sicm_ode_event event, double *y, double t1, double tol) {
  std::vector<Located> found;
  event_dim = dim;
  sicm_ode *o = sicm_ode_alloc(T, dim, f, nullptr, tol, tol);
  EXPECT_NE(o, nullptr);
  EXPECT_EQ(sicm_ode_set_events(o, &event, 1, record, &found), SICM_SUCCESS);
  double t = 0;
  EXPECT_EQ(sicm_ode_evolve(o, &t, t1, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  EXPECT_EQ(t, t1);
  EXPECT_EQ(sicm_ode_stopping_event(o), -1);
  EXPECT_EQ(sicm_ode_get_event_stats(o)->located, found.size());
  sicm_ode_free(o);
  return found;
}

// Two roots 0.1 apart: after a start to 0.4 the methods' steps on y' = 1 (which they integrate
// exactly) are long, a few to cover [0.4, 10]; the sampled interpolant finds both roots.
TEST(OdeEvents, TwoCloseRootsBothFound) {
  for (const sicm_ode_step_type *T : {sicm_ode_step_rk8pd, sicm_ode_step_qcrk4, sicm_ode_step_bs}) {
    SCOPED_TRACE(sicm_ode_step_type_name(T));
    std::vector<Located> found;
    event_dim = 1;
    sicm_ode *o = sicm_ode_alloc(T, 1, unit_rate, nullptr, 1e-10, 1e-10);
    sicm_ode_event event = {two_roots, nullptr, SICM_ODE_EVENT_BOTH, 0};
    ASSERT_EQ(sicm_ode_set_events(o, &event, 1, record, &found), SICM_SUCCESS);
    double t = 0, y[1] = {0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, 0.4, y), SICM_SUCCESS);
    const unsigned long steps0 = sicm_ode_get_stats(o)->steps;
    ASSERT_EQ(sicm_ode_evolve(o, &t, 10, y), SICM_SUCCESS);
    EXPECT_LE(sicm_ode_get_stats(o)->steps - steps0, 6u);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_NEAR(found[0].t, 0.5, 2e-16);
    EXPECT_NEAR(found[1].t, 0.6, 2e-16);
    EXPECT_NEAR(found[0].y[0], 0.5, 2e-16);
    EXPECT_NEAR(y[0], 10, 1e-13);
    sicm_ode_free(o);
  }
}

TEST(OdeEvents, DirectionChoosesTheCrossings) {
  double y[1] = {0};
  auto up = run(sicm_ode_step_rk8pd, unit_rate, 1, {two_roots, nullptr, SICM_ODE_EVENT_UP, 0}, y,
                10, 1e-10);
  ASSERT_EQ(up.size(), 1u);
  EXPECT_NEAR(up[0].t, 0.6, 1e-15);
  y[0] = 0;
  auto down = run(sicm_ode_step_bs, unit_rate, 1, {two_roots, nullptr, SICM_ODE_EVENT_DOWN, 0}, y,
                  10, 1e-10);
  ASSERT_EQ(down.size(), 1u);
  EXPECT_NEAR(down[0].t, 0.5, 1e-15);
}

TEST(OdeEvents, RootOfOddMultiplicity) {
  double y[1] = {0};
  auto found =
      run(sicm_ode_step_rk8pd, unit_rate, 1, {cubic, nullptr, SICM_ODE_EVENT_BOTH, 0}, y, 5, 1e-10);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NEAR(found[0].t, 1, 1e-14);
}

TEST(OdeEvents, TangencyIsNoCrossing) {
  for (const sicm_ode_step_type *T : {sicm_ode_step_rk8pd, sicm_ode_step_qcrk4}) {
    double y[1] = {0};
    auto found = run(T, unit_rate, 1, {touching, nullptr, SICM_ODE_EVENT_BOTH, 0}, y, 5, 1e-10);
    EXPECT_EQ(found.size(), 0u) << sicm_ode_step_type_name(T);
  }
}

// x = sin t crosses 0 at k pi; every adaptive method finds each crossing once, at its time to
// the accuracy of the integration (the one-step methods at 1e-14 to within 1e-12).
TEST(OdeEvents, OscillatorZerosAtMultiplesOfPi) {
  struct Case {
    const sicm_ode_step_type *type;
    double tol, max_error;
  };
  for (Case c :
       {Case{sicm_ode_step_rk8pd, 1e-14, 1e-12}, Case{sicm_ode_step_bs, 1e-14, 1e-12},
        Case{sicm_ode_step_qcrk4, 1e-14, 1e-12}, Case{sicm_ode_step_cvode_adams, 1e-12, 1e-8}}) {
    SCOPED_TRACE(sicm_ode_step_type_name(c.type));
    double y[2] = {0, 1};
    auto found = run(c.type, oscillator, 2, {position, nullptr, SICM_ODE_EVENT_BOTH, 0}, y,
                     10 * M_PI + 1, c.tol);
    ASSERT_EQ(found.size(), 10u); // not the start, where x = 0 already
    for (size_t k = 0; k < found.size(); k++) {
      EXPECT_NEAR(found[k].t, (k + 1) * M_PI, c.max_error) << k;
      EXPECT_LT(std::fabs(found[k].y[0]), c.max_error) << k;
      EXPECT_NEAR(found[k].y[1], k % 2 ? 1 : -1, c.max_error) << k;
    }
  }
}

// x' = v, v' = -x as Taylor coefficients.
void oscillator_series(const double *y, int order, double *c, const double *) {
  c[0] = y[0];
  c[1] = y[1];
  for (int k = 0; k < order; ++k) {
    c[(k + 1) * 2 + 0] = c[k * 2 + 1] / (k + 1);
    c[(k + 1) * 2 + 1] = -c[k * 2 + 0] / (k + 1);
  }
}

// The Taylor method keeps its steps to itself (o->h stays 0): the events are sought over spans
// the driver chooses, and found as with the other methods.
TEST(OdeEvents, TaylorMethodFindsTheZeros) {
  std::vector<Located> found;
  event_dim = 2;
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_taylor, 2, oscillator, nullptr, 1e-14, 1e-14);
  ASSERT_NE(o, nullptr);
  sicm_ode_set_taylor(o, oscillator_series, nullptr);
  sicm_ode_event event = {position, nullptr, SICM_ODE_EVENT_UP, 0};
  ASSERT_EQ(sicm_ode_set_events(o, &event, 1, record, &found), SICM_SUCCESS);
  double t = 0, y[2] = {0, 1};
  ASSERT_EQ(sicm_ode_evolve(o, &t, 10 * M_PI + 1, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  ASSERT_EQ(found.size(), 5u); // upward at 2 pi, 4 pi, ..., 10 pi
  for (size_t k = 0; k < found.size(); k++)
    EXPECT_NEAR(found[k].t, 2 * (k + 1) * M_PI, 1e-12) << k;
  sicm_ode_free(o);
}

// Backwards in time, "up" is still from negative to positive as the integration proceeds: x = sin
// t, negative just before t = 0, goes up through 0 at -pi, -3 pi, ... (where v = cos t = -1).
TEST(OdeEvents, BackwardsIntegration) {
  for (const sicm_ode_step_type *T : {sicm_ode_step_rk8pd, sicm_ode_step_bs}) {
    SCOPED_TRACE(sicm_ode_step_type_name(T));
    std::vector<Located> found;
    event_dim = 2;
    sicm_ode *o = sicm_ode_alloc(T, 2, oscillator, nullptr, 1e-14, 1e-14);
    sicm_ode_event event = {position, nullptr, SICM_ODE_EVENT_UP, 0};
    ASSERT_EQ(sicm_ode_set_events(o, &event, 1, record, &found), SICM_SUCCESS);
    double t = 0, y[2] = {0, 1};
    ASSERT_EQ(sicm_ode_evolve(o, &t, -10 * M_PI - 1, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    ASSERT_EQ(found.size(), 5u);
    for (size_t k = 0; k < found.size(); k++) {
      EXPECT_NEAR(found[k].t, -(2.0 * k + 1) * M_PI, 1e-12) << k;
      EXPECT_NEAR(found[k].y[1], -1, 1e-12) << k;
    }
    sicm_ode_free(o);
  }
}

// A terminal event stops the integration at the crossing; an integration resumed from there
// does not find it again, and stops at the next one.
TEST(OdeEvents, TerminalEventStopsAndResumes) {
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_rk8pd, 2, oscillator, nullptr, 1e-14, 1e-14);
  ASSERT_NE(o, nullptr);
  sicm_ode_event down = {position, nullptr, SICM_ODE_EVENT_BOTH, 1};
  ASSERT_EQ(sicm_ode_set_events(o, &down, 1, nullptr, nullptr), SICM_SUCCESS);
  double t = 0, y[2] = {0, 1};
  for (int k = 1; k <= 3; k++) {
    ASSERT_EQ(sicm_ode_evolve(o, &t, 100, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    EXPECT_EQ(sicm_ode_stopping_event(o), 0);
    EXPECT_NEAR(t, k * M_PI, 1e-12);
  }
  sicm_ode_free(o);
}

TEST(OdeEvents, BadEventIsRefused) {
  CaptureErrors capture;
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_rk8pd, 1, unit_rate, nullptr, 1e-10, 1e-10);
  sicm_ode_event bad = {position, nullptr, 0, 0};
  EXPECT_EQ(sicm_ode_set_events(o, &bad, 1, nullptr, nullptr), SICM_EINVAL);
  ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  EXPECT_NE(CaptureErrors::messages()[0].find("event 0"), std::string::npos);
  sicm_ode_free(o);
}

} // namespace
