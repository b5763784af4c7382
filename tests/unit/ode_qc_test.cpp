// Unit tests of scmutils' quality-controlled methods, qcrk4 and qcctrap2, against analytic
// solutions: the order of one extrapolated step, the cost of step doubling, accuracy at a
// tolerance, the relative error measure, failures and the stiffness watch.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

int growth(double, const double *y, double *dy, void *) {
  dy[0] = y[0];
  return 0;
}

int oscillator(double, const double *y, double *dy, void *) {
  dy[0] = y[1];
  dy[1] = -y[0];
  return 0;
}

double oscillator_error(double t, const double *y) {
  return std::fmax(std::fabs(y[0] - std::cos(t)), std::fabs(y[1] + std::sin(t)));
}

struct Outcome {
  int status;
  double t;
  std::vector<double> y;
  sicm_ode_stats stats;
  std::string message;
};

// A fresh integrator of the given type from (0, y) to t1.
Outcome integrate(const sicm_ode_step_type *type, sicm_ode_rhs f, std::vector<double> y, double tol,
                  double t1) {
  sicm_ode *o = sicm_ode_alloc(type, y.size(), f, nullptr, tol, tol);
  EXPECT_NE(o, nullptr);
  Outcome run;
  run.t = 0;
  run.status = sicm_ode_evolve(o, &run.t, t1, y.data());
  run.y = y;
  run.stats = *sicm_ode_get_stats(o);
  run.message = sicm_ode_last_error(o);
  sicm_ode_free(o);
  return run;
}

// The error of one step of size h from (0, y0) (a fresh integrator's first try is the whole
// interval, as scmutils' advancer tries the caller's dt first), which the loose tolerance lets
// through; exact is the solution at h.
double one_step_error(const sicm_ode_step_type *type, sicm_ode_rhs f, double y0, double h,
                      double exact) {
  Outcome run = integrate(type, f, {y0}, 1e-3, h);
  EXPECT_EQ(run.status, SICM_SUCCESS) << run.message;
  EXPECT_EQ(run.stats.steps, 1u);
  EXPECT_EQ(run.stats.rejected_steps, 0u);
  return std::fabs(run.y[0] - exact);
}

// Step doubling with local extrapolation raises the order by one: RK4's local error O(h^5)
// becomes O(h^6), so halving the step divides the error of a step by 2^6 = 64 (plain RK4: 32).
// On y' = y from 1 the solution is e^t.
TEST(OdeQc, Qcrk4StepHasLocalErrorOfOrderSix) {
  const double e1 = one_step_error(sicm_ode_step_qcrk4, growth, 1, 0.2, std::exp(0.2));
  const double e2 = one_step_error(sicm_ode_step_qcrk4, growth, 1, 0.1, std::exp(0.1));
  const double e3 = one_step_error(sicm_ode_step_qcrk4, growth, 1, 0.05, std::exp(0.05));
  EXPECT_GT(e3, 1e-13); // well above rounding, so that the ratios mean something
  EXPECT_NEAR(e1 / e2, 64, 6);
  EXPECT_NEAR(e2 / e3, 64, 6);
}

// y' = 5 (t + 1)^4, y(0) = 1: y = (t + 1)^5. On a quadrature the corrector converges at once
// (f does not depend on y), and the extrapolated trapezoid rule is Simpson's rule, whose error
// over a step is h^5 f''''/2880 = h^5 / 24 here (the trapezoid rule's alone is O(h^3)). On a
// true ODE the corrector stops at a tenth of the tolerance, short of convergence, which at the
// loose tolerance a single step needs hides the order; the oscillator test below covers that.
int quartic(double t, const double *, double *dy, void *) {
  dy[0] = 5 * std::pow(t + 1, 4);
  return 0;
}

TEST(OdeQc, Qcctrap2StepIsSimpsonsRuleOnAQuadrature) {
  for (double h : {0.04, 0.02, 0.01}) {
    SCOPED_TRACE(h);
    const double e = one_step_error(sicm_ode_step_qcctrap2, quartic, 1, h, std::pow(1 + h, 5));
    EXPECT_NEAR(e, std::pow(h, 5) / 24, 0.01 * std::pow(h, 5) / 24);
  }
}

// One accepted qcrk4 step costs 11 evaluations: f at the start (shared by the first half and
// the whole step), 3 more for the first half, 4 for the second and 3 for the whole step.
TEST(OdeQc, Qcrk4StepDoublingCount) {
  Outcome run = integrate(sicm_ode_step_qcrk4, growth, {1.0}, 1e-3, 0.1);
  ASSERT_EQ(run.status, SICM_SUCCESS) << run.message;
  EXPECT_EQ(run.stats.steps, 1u);
  EXPECT_EQ(run.stats.rhs_evals, 11u);
  // A rejected try costs 10 (f at the start is kept); the first try here, the whole interval
  // of 10 time units, is far too long. Under 100 steps the stiffness watch, which costs
  // evaluations of its own, makes no check.
  Outcome longer = integrate(sicm_ode_step_qcrk4, oscillator, {1.0, 0.0}, 1e-5, 10);
  ASSERT_EQ(longer.status, SICM_SUCCESS) << longer.message;
  EXPECT_LT(longer.stats.steps, 100u);
  EXPECT_GT(longer.stats.rejected_steps, 0u);
  EXPECT_EQ(longer.stats.rhs_evals, 11 * longer.stats.steps + 10 * longer.stats.rejected_steps);
}

// At tolerance eps the error of each step is far below eps relative to the solution (the
// accepted difference of the two results is at most 2 eps, and extrapolation removes its
// leading term), so over 10 time units (1400 steps at 1e-12) the global error stays below eps,
// as in the book's figure 2.2. (Measured: 0.065 eps for qcrk4, 0.002 to 0.01 eps for
// qcctrap2; GSL's rkf45, with the usual test abs_tol + rel_tol |y|, makes about 6 eps.)
TEST(OdeQc, Qcrk4HarmonicOscillatorWithinTolerance) {
  for (double tol : {1e-8, 1e-10, 1e-12}) {
    SCOPED_TRACE(tol);
    Outcome run = integrate(sicm_ode_step_qcrk4, oscillator, {1.0, 0.0}, tol, 10);
    ASSERT_EQ(run.status, SICM_SUCCESS) << run.message;
    EXPECT_EQ(run.t, 10);
    EXPECT_LT(oscillator_error(10, run.y.data()), tol);
    EXPECT_LT(run.stats.rejected_steps, run.stats.steps);
  }
}

TEST(OdeQc, Qcctrap2HarmonicOscillatorWithinTolerance) {
  for (double tol : {1e-6, 1e-8}) {
    SCOPED_TRACE(tol);
    Outcome run = integrate(sicm_ode_step_qcctrap2, oscillator, {1.0, 0.0}, tol, 10);
    ASSERT_EQ(run.status, SICM_SUCCESS) << run.message;
    EXPECT_LT(oscillator_error(10, run.y.data()), tol);
  }
}

// scmutils measures the difference relative to the size of the solution: scaling the problem
// by a power of two (exact in floating point) changes neither the steps nor the relative error.
// (The usual test abs_tol + rel_tol |y| would take more steps for the larger solution.)
TEST(OdeQc, ErrorIsMeasuredRelativeToTheSolution) {
  for (const sicm_ode_step_type *type : {sicm_ode_step_qcrk4, sicm_ode_step_qcctrap2}) {
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    const double scale = 1024.0 * 1024.0;
    Outcome unit = integrate(type, oscillator, {1.0, 0.0}, 1e-8, 3);
    Outcome big = integrate(type, oscillator, {scale, 0.0}, 1e-8, 3);
    ASSERT_EQ(unit.status, SICM_SUCCESS) << unit.message;
    ASSERT_EQ(big.status, SICM_SUCCESS) << big.message;
    // Only the breakpoint of 1e-10, below which the measure turns absolute, does not scale:
    // it moves the error estimates by about 1e-10 of themselves.
    EXPECT_EQ(unit.stats.steps, big.stats.steps);
    EXPECT_NEAR(big.y[0] / scale, unit.y[0], 1e-14);
    EXPECT_NEAR(big.y[1] / scale, unit.y[1], 1e-14);
  }
}

TEST(OdeQc, BackwardsAndInShortCalls) {
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_qcrk4, 2, oscillator, nullptr, 1e-12, 1e-12);
  double t = 0, y[2] = {1, 0};
  ASSERT_EQ(sicm_ode_evolve(o, &t, -10, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  EXPECT_EQ(t, -10);
  EXPECT_LT(oscillator_error(-10, y), 1e-12);
  // Forwards again in steps of 0.1, as evolve's monitor loop calls it.
  for (int k = 1; k <= 100; k++) {
    ASSERT_EQ(sicm_ode_evolve(o, &t, -10 + 0.1 * k, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  }
  EXPECT_LT(oscillator_error(t, y), 2e-12);
  sicm_ode_free(o);
}

// y' = y^2 from y = 1 is 1 / (1 - t), which has a pole at t = 1.
int blowup(double, const double *y, double *dy, void *) {
  dy[0] = y[0] * y[0];
  return 0;
}

TEST(OdeQc, FailureAtASingularityNamesTheMethod) {
  for (const sicm_ode_step_type *type : {sicm_ode_step_qcrk4, sicm_ode_step_qcctrap2}) {
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    CaptureErrors capture;
    Outcome run = integrate(type, blowup, {1.0}, 1e-8, 2);
    EXPECT_EQ(run.status, SICM_ESTEP);
    // Up to the pole, which the errors of the steps move by some 1e-11.
    EXPECT_NEAR(run.t, 1, 1e-9);
    EXPECT_NE(run.message.find("step size too small"), std::string::npos) << run.message;
    EXPECT_EQ(run.message.rfind(std::string(sicm_ode_step_type_name(type)) + ": ", 0), 0u)
        << run.message;
    ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  }
}

// The book's states carry the time as a component, y = (t, x, v).
int timed_oscillator(double, const double *y, double *dy, void *) {
  dy[0] = 1;
  dy[1] = y[2];
  dy[2] = -y[1];
  return 0;
}

// Two results of a step differ by rounding alone by some 1e-16 of their size (the time
// component reached by t + h/2 + h/2 and by t + h, for one), so a relative tolerance of 1e-17
// cannot be met at any step size; the failure says so (scmutils would shrink the step for ever).
TEST(OdeQc, ToleranceBelowRoundingIsExplained) {
  CaptureErrors capture;
  Outcome run = integrate(sicm_ode_step_qcrk4, timed_oscillator, {0.0, 1.0, 0.0}, 1e-17, 10);
  EXPECT_EQ(run.status, SICM_ESTEP);
  EXPECT_NE(run.message.find("a relative tolerance of 1e-17 is below the rounding errors"),
            std::string::npos)
      << run.message;
  // 1e-15 can be met, and gives the oscillator to within rounding.
  Outcome tight = integrate(sicm_ode_step_qcrk4, timed_oscillator, {0.0, 1.0, 0.0}, 1e-15, 10);
  ASSERT_EQ(tight.status, SICM_SUCCESS) << tight.message;
  EXPECT_LT(oscillator_error(10, tight.y.data() + 1), 1e-13);
}

int stop_at_half(double t, const double *y, double *dy, void *) {
  dy[0] = y[0];
  return t > 0.5 ? 7 : 0;
}

TEST(OdeQc, UserStopIsReported) {
  CaptureErrors capture;
  Outcome run = integrate(sicm_ode_step_qcrk4, stop_at_half, {1.0}, 1e-10, 1);
  EXPECT_EQ(run.status, SICM_EUSER);
  EXPECT_LE(run.t, 0.5);
  EXPECT_NE(run.message.find("a user function returned 7"), std::string::npos) << run.message;
}

// The trapezoid rule's corrector is iterated, not solved by Newton's method (as in scmutils):
// the iteration converges only for h |lambda| < 2, so on y' = -1000 y the steps stay near
// 2e-3 however smooth the solution (until it underflows to 0), and the result is still right.
int fast_decay(double, const double *y, double *dy, void *) {
  dy[0] = -1000 * y[0];
  return 0;
}

TEST(OdeQc, Qcctrap2CorrectorLimitsTheStep) {
  Outcome run = integrate(sicm_ode_step_qcctrap2, fast_decay, {1.0}, 1e-6, 1);
  ASSERT_EQ(run.status, SICM_SUCCESS) << run.message;
  EXPECT_LT(std::fabs(run.y[0]), 1e-12);
  // Down to where y underflows (e^-709, at t = 0.709), at h < 2e-3.
  EXPECT_GT(run.stats.steps, 350u);
  EXPECT_GT(run.stats.rejected_steps, 0u);
}

// y' = -1000 (y - 2 - cos t): a real stiff eigenvalue. At tolerance 1e-6 the step is held by
// stability (qcrk4) or by the corrector's convergence (qcctrap2), and the watch stops both.
// (The spring pendulum of ode_stiffness_test.cpp does not do for these methods: their measure,
// relative to each component, resolves the spring's vibration in the small radial velocity, so
// accuracy holds the step; nor does a solution cos t, whose zeros do the same.)
int forced_decay(double t, const double *y, double *dy, void *) {
  dy[0] = -1000.0 * (y[0] - 2 - std::cos(t));
  return 0;
}

TEST(OdeQc, ForcedDecayStopsAsStiff) {
  for (const sicm_ode_step_type *type : {sicm_ode_step_qcrk4, sicm_ode_step_qcctrap2}) {
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    CaptureErrors capture;
    Outcome run = integrate(type, forced_decay, {3.0}, 1e-6, 1e4);
    ASSERT_EQ(run.status, SICM_ESTIFF) << run.message;
    EXPECT_LT(run.stats.rhs_evals, 100000u);
    EXPECT_NE(run.message.find("use 'cvode-bdf"), std::string::npos) << run.message;
  }
}

const double kG = 9.8;

int pendulum(double, const double *y, double *dy, void *) {
  dy[0] = y[1];
  dy[1] = -kG * std::sin(y[0]);
  return 0;
}

int kepler(double, const double *y, double *dy, void *) {
  const double r2 = y[0] * y[0] + y[1] * y[1], r3 = r2 * std::sqrt(r2);
  dy[0] = y[2];
  dy[1] = y[3];
  dy[2] = -y[0] / r3;
  dy[3] = -y[1] / r3;
  return 0;
}

TEST(OdeQc, PendulumAndOrbitAreNeverStiff) {
  const double e = 0.9;
  for (const sicm_ode_step_type *type : {sicm_ode_step_qcrk4, sicm_ode_step_qcctrap2}) {
    for (double tol : {1e-2, 1e-4, 1e-6, 1e-9}) {
      SCOPED_TRACE(std::string(sicm_ode_step_type_name(type)) + " at " + std::to_string(tol));
      CaptureErrors capture;
      sicm_ode *o = sicm_ode_alloc(type, 2, pendulum, nullptr, tol, tol);
      sicm_ode_set_max_steps(o, 30000);
      double t = 0, y[2] = {1, 0};
      int s = sicm_ode_evolve(o, &t, 1e7, y);
      EXPECT_TRUE(s == SICM_EMAXITER || s == SICM_SUCCESS) << sicm_ode_last_error(o);
      sicm_ode_free(o);
      Outcome orbit =
          integrate(type, kepler, {1 - e, 0, 0, std::sqrt((1 + e) / (1 - e))}, tol, 20 * 2 * M_PI);
      EXPECT_NE(orbit.status, SICM_ESTIFF) << orbit.message;
    }
  }
}

} // namespace
