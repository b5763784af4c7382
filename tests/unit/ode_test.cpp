// Unit tests of the runtime's ODE integrators against analytic solutions: every adaptive stepper,
// stiff problems, failure messages, statistics, and the orders of the symplectic maps.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "capture_errors.hpp"
#include "sicm/runtime.h"

namespace {

std::string format(double x) {
  char buf[SICM_DOUBLE_BUFSIZE];
  sicm_format_double(buf, x);
  return buf;
}

int oscillator(double, const double *y, double *dy, void *) {
  dy[0] = y[1];
  dy[1] = -y[0];
  return 0;
}

double oscillator_error(double t, const double *y) {
  return std::fmax(std::fabs(y[0] - std::cos(t)), std::fabs(y[1] + std::sin(t)));
}

struct Stepper {
  const sicm_ode_step_type *type;
  double max_error; // global error allowed at t = 10 with tolerance 1e-10
  bool implicit;
};

// One-step methods keep the global error near the local tolerance on this problem; the
// multistep methods (GSL's msbdf, CVODE) control the error with an RMS norm and typically land
// at 2e-8 to 9e-8 after 10 time units at tolerance 1e-10, so they get a looser bound.
std::vector<Stepper> all_steppers() {
  return {{sicm_ode_step_rk8pd, 1e-8, false},    {sicm_ode_step_rkf45, 1e-8, false},
          {sicm_ode_step_rkck, 1e-8, false},     {sicm_ode_step_bs, 1e-8, false},
          {sicm_ode_step_msbdf, 3e-7, true},     {sicm_ode_step_cvode_adams, 3e-7, false},
          {sicm_ode_step_cvode_bdf, 3e-7, true}, {sicm_ode_step_qcrk4, 1e-8, false}};
}

TEST(Ode, HarmonicOscillatorEveryStepper) {
  for (const Stepper &s : all_steppers()) {
    SCOPED_TRACE(sicm_ode_step_type_name(s.type));
    sicm_ode *o = sicm_ode_alloc(s.type, 2, oscillator, nullptr, 1e-10, 1e-10);
    ASSERT_NE(o, nullptr);
    double t = 0, y[2] = {1, 0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, 10, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    EXPECT_EQ(t, 10);
    EXPECT_LT(oscillator_error(10, y), s.max_error);
    const sicm_ode_stats *st = sicm_ode_get_stats(o);
    EXPECT_GT(st->steps, 5u);
    EXPECT_LT(st->steps, 5000u);
    EXPECT_LT(st->rejected_steps, st->steps);
    EXPECT_GE(st->rhs_evals, st->steps);
    // Bulirsch-Stoer may spend up to 111 evaluations on one step attempt.
    EXPECT_LT(st->rhs_evals, 120 * (st->steps + st->rejected_steps) + 10);
    if (s.implicit)
      EXPECT_GT(st->jacobian_evals, 0u);
    else
      EXPECT_EQ(st->jacobian_evals, 0u);
    EXPECT_STREQ(sicm_ode_last_error(o), "");
    sicm_ode_free(o);
  }
}

TEST(Ode, BackwardsInTime) {
  for (const Stepper &s : all_steppers()) {
    SCOPED_TRACE(sicm_ode_step_type_name(s.type));
    sicm_ode *o = sicm_ode_alloc(s.type, 2, oscillator, nullptr, 1e-10, 1e-10);
    double t = 0, y[2] = {1, 0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, -10, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    EXPECT_EQ(t, -10);
    EXPECT_LT(oscillator_error(-10, y), s.max_error);
    // And forwards again from there: the direction change restarts the method.
    ASSERT_EQ(sicm_ode_evolve(o, &t, -5, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    EXPECT_LT(oscillator_error(-5, y), s.max_error);
    sicm_ode_free(o);
  }
}

unsigned long rhs_evals_to_10(const sicm_ode_step_type *type, double tol) {
  sicm_ode *o = sicm_ode_alloc(type, 2, oscillator, nullptr, tol, tol);
  double t = 0, y[2] = {1, 0};
  EXPECT_EQ(sicm_ode_evolve(o, &t, 10, y), SICM_SUCCESS);
  EXPECT_LT(oscillator_error(10, y), 1e-10);
  unsigned long n = sicm_ode_get_stats(o)->rhs_evals;
  sicm_ode_free(o);
  return n;
}

TEST(Ode, BulirschStoerIsCheapAtTightTolerance) {
  // Measured: about 670 evaluations for Bulirsch-Stoer and 4100 for rkf45.
  unsigned long bs = rhs_evals_to_10(sicm_ode_step_bs, 1e-12);
  unsigned long rkf45 = rhs_evals_to_10(sicm_ode_step_rkf45, 1e-12);
  EXPECT_LT(3 * bs, rkf45) << "bs " << bs << ", rkf45 " << rkf45;
}

// A monitor calling evolve in increments must not pay for restarting each time: the step
// size carries over between calls.
TEST(Ode, RepeatedShortCallsKeepTheStepSize) {
  const sicm_ode_step_type *types[] = {sicm_ode_step_rk8pd, sicm_ode_step_bs,
                                       sicm_ode_step_cvode_adams};
  for (const sicm_ode_step_type *type : types) {
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    sicm_ode *one = sicm_ode_alloc(type, 2, oscillator, nullptr, 1e-9, 1e-9);
    double t = 0, y[2] = {1, 0};
    ASSERT_EQ(sicm_ode_evolve(one, &t, 100, y), SICM_SUCCESS);
    const unsigned long single = sicm_ode_get_stats(one)->steps;
    const unsigned long single_evals = sicm_ode_get_stats(one)->rhs_evals;

    sicm_ode *many = sicm_ode_alloc(type, 2, oscillator, nullptr, 1e-9, 1e-9);
    t = 0, y[0] = 1, y[1] = 0;
    for (int k = 1; k <= 100; k++)
      ASSERT_EQ(sicm_ode_evolve(many, &t, k, y), SICM_SUCCESS);
    // At most about one extra (shortened) step per call, and no cascade of rejections: the
    // increments are close to the natural step, the case where re-choosing the order from each
    // shortened step used to cost Bulirsch-Stoer 3.4 times the work of one call.
    const sicm_ode_stats *st = sicm_ode_get_stats(many);
    EXPECT_LE(st->steps, single + 100 + single / 10);
    EXPECT_LE(st->rhs_evals, 2 * single_evals) << single_evals << " in one call";
    EXPECT_LT(oscillator_error(100, y), 1e-5);
    sicm_ode_free(one);
    sicm_ode_free(many);
  }
}

TEST(Ode, ChangingTheStateRestartsCleanly) {
  for (const Stepper &s : all_steppers()) {
    SCOPED_TRACE(sicm_ode_step_type_name(s.type));
    sicm_ode *o = sicm_ode_alloc(s.type, 2, oscillator, nullptr, 1e-10, 1e-10);
    double t = 0, a[2] = {1, 0}, b[2] = {1, 0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, 3, a), SICM_SUCCESS);
    t = 0; // same object, new initial condition: must give the same answer as the first run
    ASSERT_EQ(sicm_ode_evolve(o, &t, 3, b), SICM_SUCCESS);
    EXPECT_EQ(a[0], b[0]);
    EXPECT_EQ(a[1], b[1]);
    sicm_ode_free(o);
  }
}

// y' = -1000 (y - cos t), y(0) = 0: stiff, with the exact solution
// y = (1000^2 cos t + 1000 sin t - 1000^2 exp(-1000 t)) / (1000^2 + 1).
int stiff_linear(double t, const double *y, double *dy, void *) {
  dy[0] = -1000.0 * (y[0] - std::cos(t));
  return 0;
}

TEST(Ode, StiffLinearProblem) {
  const double k2 = 1e6, t1 = 10;
  const double exact =
      (k2 * std::cos(t1) + 1000 * std::sin(t1) - k2 * std::exp(-1000 * t1)) / (k2 + 1);
  unsigned long explicit_evals = 0;
  {
    sicm_ode *o = sicm_ode_alloc(sicm_ode_step_rk8pd, 1, stiff_linear, nullptr, 1e-8, 1e-8);
    double t = 0, y[1] = {0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, t1, y), SICM_SUCCESS);
    explicit_evals = sicm_ode_get_stats(o)->rhs_evals;
    sicm_ode_free(o);
  }
  for (const sicm_ode_step_type *type : {sicm_ode_step_msbdf, sicm_ode_step_cvode_bdf}) {
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    sicm_ode *o = sicm_ode_alloc(type, 1, stiff_linear, nullptr, 1e-8, 1e-8);
    double t = 0, y[1] = {0};
    ASSERT_EQ(sicm_ode_evolve(o, &t, t1, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    EXPECT_NEAR(y[0], exact, 1e-6);
    // Stability, not accuracy, limits the explicit method's step here.
    EXPECT_LT(5 * sicm_ode_get_stats(o)->rhs_evals, explicit_evals);
    sicm_ode_free(o);
  }
}

// Robertson's chemical kinetics, the classic stiff test. Reference values at t = 40 from
// Hairer and Wanner, "Solving ODEs II" (and the IVP test set):
// y = (0.7158270687, 9.185534764e-6, 0.2841637457).
int robertson(double, const double *y, double *dy, void *) {
  dy[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
  dy[1] = 0.04 * y[0] - 1e4 * y[1] * y[2] - 3e7 * y[1] * y[1];
  dy[2] = 3e7 * y[1] * y[1];
  return 0;
}

int robertson_jacobian(double, const double *y, double *J, double *dfdt, void *) {
  J[0] = -0.04, J[1] = 1e4 * y[2], J[2] = 1e4 * y[1];
  J[3] = 0.04, J[4] = -1e4 * y[2] - 6e7 * y[1], J[5] = -1e4 * y[1];
  J[6] = 0, J[7] = 6e7 * y[1], J[8] = 0;
  dfdt[0] = dfdt[1] = dfdt[2] = 0;
  return 0;
}

TEST(Ode, RobertsonWithAndWithoutJacobian) {
  const double ref[3] = {0.7158270687, 9.185534764e-6, 0.2841637457};
  for (const sicm_ode_step_type *type : {sicm_ode_step_msbdf, sicm_ode_step_cvode_bdf}) {
    for (bool analytic : {false, true}) {
      SCOPED_TRACE(std::string(sicm_ode_step_type_name(type)) + (analytic ? " J" : " FD"));
      sicm_ode *o = sicm_ode_alloc(type, 3, robertson, nullptr, 1e-12, 1e-8);
      if (analytic) sicm_ode_set_jacobian(o, robertson_jacobian);
      double t = 0, y[3] = {1, 0, 0};
      ASSERT_EQ(sicm_ode_evolve(o, &t, 40, y), SICM_SUCCESS) << sicm_ode_last_error(o);
      for (int i = 0; i < 3; i++)
        EXPECT_NEAR(y[i] / ref[i], 1.0, 2e-6) << "component " << i;
      const sicm_ode_stats *st = sicm_ode_get_stats(o);
      EXPECT_GT(st->jacobian_evals, 0u);
      EXPECT_LT(st->steps, 2000u);
      sicm_ode_free(o);
    }
  }
}

int blow_up(double, const double *y, double *dy, void *) {
  dy[0] = y[0] * y[0]; // y = 1/(1 - t): singular at t = 1
  return 0;
}

TEST(Ode, BlowUpFailsWithTimeAndState) {
  for (const Stepper &s : all_steppers()) {
    const sicm_ode_step_type *type = s.type;
    SCOPED_TRACE(sicm_ode_step_type_name(type));
    CaptureErrors capture;
    sicm_ode *o = sicm_ode_alloc(type, 1, blow_up, nullptr, 1e-10, 1e-10);
    double t = 0, y[1] = {1};
    int status = sicm_ode_evolve(o, &t, 2, y);
    EXPECT_NE(status, SICM_SUCCESS);
    EXPECT_NEAR(t, 1.0, 1e-6); // stuck at the singularity
    EXPECT_GT(y[0], 1e6);
    std::string msg = sicm_ode_last_error(o);
    EXPECT_NE(msg.find(sicm_ode_step_type_name(type)), std::string::npos) << msg;
    EXPECT_NE(msg.find("t = " + format(t)), std::string::npos) << msg;
    EXPECT_NE(msg.find("state [" + format(y[0]) + "]"), std::string::npos) << msg;
    ASSERT_EQ(CaptureErrors::messages().size(), 1u);
    EXPECT_EQ(CaptureErrors::messages()[0], msg);
    sicm_ode_free(o);
  }
}

TEST(Ode, TooManySteps) {
  CaptureErrors capture;
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_rk8pd, 2, oscillator, nullptr, 1e-10, 1e-10);
  sicm_ode_set_max_steps(o, 10);
  double t = 0, y[2] = {1, 0};
  EXPECT_EQ(sicm_ode_evolve(o, &t, 100, y), SICM_EMAXITER);
  EXPECT_GT(t, 0);
  EXPECT_LT(t, 100);
  EXPECT_LT(oscillator_error(t, y), 1e-8); // the last point reached is a valid state
  EXPECT_NE(std::string(sicm_ode_last_error(o)).find("too many steps"), std::string::npos);
  sicm_ode_free(o);
}

int stops_after_half(double t, const double *y, double *dy, void *) {
  if (t > 0.5) return 7;
  return oscillator(t, y, dy, nullptr);
}

TEST(Ode, RightHandSideStops) {
  for (const Stepper &s : all_steppers()) {
    SCOPED_TRACE(sicm_ode_step_type_name(s.type));
    CaptureErrors capture;
    sicm_ode *o = sicm_ode_alloc(s.type, 2, stops_after_half, nullptr, 1e-10, 1e-10);
    double t = 0, y[2] = {1, 0};
    EXPECT_EQ(sicm_ode_evolve(o, &t, 1, y), SICM_EUSER);
    EXPECT_LE(t, 0.5);
    EXPECT_LT(oscillator_error(t, y), 1e-6);
    EXPECT_NE(std::string(sicm_ode_last_error(o)).find("returned 7"), std::string::npos)
        << sicm_ode_last_error(o);
    sicm_ode_free(o);
  }
}

int nan_after_one(double t, const double *, double *dy, void *) {
  dy[0] = t > 1 ? NAN : 1.0;
  return 0;
}

TEST(Ode, NonFiniteDerivativeFails) {
  for (const Stepper &s : all_steppers()) {
    SCOPED_TRACE(sicm_ode_step_type_name(s.type));
    CaptureErrors capture;
    sicm_ode *o = sicm_ode_alloc(s.type, 1, nan_after_one, nullptr, 1e-8, 1e-8);
    double t = 0, y[1] = {0};
    int status = sicm_ode_evolve(o, &t, 2, y);
    EXPECT_TRUE(status == SICM_EBADFUNC || status == SICM_ESTEP) << status;
    EXPECT_LE(t, 1.0);
    EXPECT_GT(t, 0.99);
    EXPECT_NEAR(y[0], t, 1e-6);
    EXPECT_NE(std::string(sicm_ode_last_error(o)).find("state"), std::string::npos);
    sicm_ode_free(o);
  }
}

TEST(Ode, InvalidArguments) {
  CaptureErrors capture;
  EXPECT_EQ(sicm_ode_alloc(sicm_ode_step_rk8pd, 2, oscillator, nullptr, -1, 1e-6), nullptr);
  EXPECT_EQ(sicm_ode_alloc(sicm_ode_step_rk8pd, 2, oscillator, nullptr, 0, 0), nullptr);
  EXPECT_EQ(sicm_ode_alloc(sicm_ode_step_rk8pd, 0, oscillator, nullptr, 1e-6, 1e-6), nullptr);
  EXPECT_EQ(sicm_ode_alloc(nullptr, 2, oscillator, nullptr, 1e-6, 1e-6), nullptr);
  EXPECT_EQ(CaptureErrors::messages().size(), 4u);
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_bs, 2, oscillator, nullptr, 1e-6, 1e-6);
  double t = 0, y[2] = {NAN, 0};
  EXPECT_EQ(sicm_ode_evolve(o, &t, 1, y), SICM_EINVAL);
  EXPECT_EQ(sicm_ode_set_max_steps(o, 0), SICM_EINVAL);
  sicm_ode_free(o);
  sicm_ode_free(nullptr);
}

// ---- symplectic maps --------------------------------------------------------

// Kepler problem with GM = 1: H = |p|^2/2 - 1/|q|. Starting at perihelion of an orbit with
// semi-major axis 1 and eccentricity e, the period is 2 pi and after one period the state must
// return exactly to the start.
int kepler_force(double, const double *q, double *f, void *) {
  const double r2 = q[0] * q[0] + q[1] * q[1], r3 = r2 * std::sqrt(r2);
  f[0] = q[0] / r3;
  f[1] = q[1] / r3;
  return 0;
}

int unit_mass_velocity(const double *p, double *v, void *n) {
  for (int i = 0; i < *static_cast<int *>(n); i++)
    v[i] = p[i];
  return 0;
}

double kepler_energy(const double *q, const double *p) {
  return 0.5 * (p[0] * p[0] + p[1] * p[1]) - 1 / std::sqrt(q[0] * q[0] + q[1] * q[1]);
}

double kepler_period_error(const sicm_symplectic_type *T, double e, int steps) {
  int ndof = 2;
  const double v0 = std::sqrt((1 + e) / (1 - e));
  double q[2] = {1 - e, 0}, p[2] = {0, v0}, t = 0;
  const double period = 2 * M_PI;
  EXPECT_EQ(sicm_symplectic_evolve(T, 2, kepler_force, unit_mass_velocity, &ndof, &t, period,
                                   period / steps, q, p),
            SICM_SUCCESS);
  EXPECT_EQ(t, period);
  return std::fmax(std::fmax(std::fabs(q[0] - (1 - e)), std::fabs(q[1])),
                   std::fmax(std::fabs(p[0]), std::fabs(p[1] - v0)));
}

TEST(Symplectic, MeasuredOrdersOnKepler) {
  struct Case {
    const sicm_symplectic_type *T;
    int steps; // per period, coarse; the order is measured from steps -> 2 steps
  } cases[] = {{sicm_symplectic_verlet, 400},
               {sicm_symplectic_yoshida4, 400},
               {sicm_symplectic_yoshida6, 200},
               {sicm_symplectic_yoshida8, 400}};
  for (const Case &c : cases) {
    SCOPED_TRACE(sicm_symplectic_name(c.T));
    double coarse = kepler_period_error(c.T, 0.5, c.steps);
    double fine = kepler_period_error(c.T, 0.5, 2 * c.steps);
    double order = std::log2(coarse / fine);
    EXPECT_NEAR(order, sicm_symplectic_order(c.T), 0.3) << coarse << " -> " << fine;
  }
}

// Driven oscillator H = p^2/2 + q^2/2 - q cos 2t, q(0) = p(0) = 0, exact solution
// q = (cos t - cos 2t)/3: the orders must hold for time-dependent potentials too.
int driven_force(double t, const double *q, double *f, void *) {
  f[0] = q[0] - std::cos(2 * t);
  return 0;
}

TEST(Symplectic, MeasuredOrdersWithTimeDependentForce) {
  for (const sicm_symplectic_type *T :
       {sicm_symplectic_verlet, sicm_symplectic_yoshida4, sicm_symplectic_yoshida6}) {
    SCOPED_TRACE(sicm_symplectic_name(T));
    double err[2];
    for (int k = 0; k < 2; k++) {
      int ndof = 1;
      double q[1] = {0}, p[1] = {0}, t = 0;
      ASSERT_EQ(sicm_symplectic_evolve(T, 1, driven_force, unit_mass_velocity, &ndof, &t, 10,
                                       0.05 / (1 << k), q, p),
                SICM_SUCCESS);
      err[k] = std::fmax(std::fabs(q[0] - (std::cos(10.0) - std::cos(20.0)) / 3),
                         std::fabs(p[0] - (-std::sin(10.0) + 2 * std::sin(20.0)) / 3));
    }
    EXPECT_NEAR(std::log2(err[0] / err[1]), sicm_symplectic_order(T), 0.3)
        << err[0] << " -> " << err[1];
  }
}

TEST(Symplectic, KeplerEnergyStaysBoundedOver1000Periods) {
  int ndof = 2;
  const double e = 0.5, period = 2 * M_PI;
  double q[2] = {1 - e, 0}, p[2] = {0, std::sqrt((1 + e) / (1 - e))}, t = 0;
  const double e0 = kepler_energy(q, p);
  double first = 0, last = 0; // largest energy error in the first and last 100 periods
  for (int n = 1; n <= 1000; n++) {
    for (int k = 1; k <= 8; k++) { // sample eight times per period
      ASSERT_EQ(sicm_symplectic_evolve(sicm_symplectic_yoshida4, 2, kepler_force,
                                       unit_mass_velocity, &ndof, &t,
                                       period * (n - 1) + period * k / 8, period / 1000, q, p),
                SICM_SUCCESS);
      double de = std::fabs(kepler_energy(q, p) - e0);
      if (n <= 100) first = std::fmax(first, de);
      if (n > 900) last = std::fmax(last, de);
    }
  }
  // Measured: 1.6e-8 in both windows. No secular drift: the late error is not larger.
  EXPECT_LT(first, 1e-7);
  EXPECT_LT(last, 1.5 * first);
}

// Angular momentum L = q x p of a Kepler orbit (GM = 1) is conserved exactly by every
// splitting method (kicks are parallel to q, drifts to p), so what changes it is rounding. The
// force callback remembers q; the velocity callback, which comes next with the kicked p, takes
// the largest |L - L0| seen along the way.
struct AngularMomentumWatch {
  double q[2];
  double L0, max_error;
};

int watched_kepler_force(double t, const double *q, double *f, void *w) {
  auto *watch = static_cast<AngularMomentumWatch *>(w);
  watch->q[0] = q[0], watch->q[1] = q[1];
  return kepler_force(t, q, f, nullptr);
}

int watched_velocity(const double *p, double *v, void *w) {
  auto *watch = static_cast<AngularMomentumWatch *>(w);
  v[0] = p[0], v[1] = p[1];
  const double L = watch->q[0] * p[1] - watch->q[1] * p[0];
  watch->max_error = std::fmax(watch->max_error, std::fabs(L - watch->L0));
  return 0;
}

TEST(Symplectic, CompensatedSummationKeepsAngularMomentum) {
  const double e = 0.5, period = 2 * M_PI, h = period / 10000;
  const double steps = 2e6; // 200 periods in one call
  double q[2] = {1 - e, 0}, p[2] = {0, std::sqrt((1 + e) / (1 - e))}, t = 0;
  AngularMomentumWatch watch = {{0, 0}, q[0] * p[1] - q[1] * p[0], 0};
  ASSERT_EQ(sicm_symplectic_evolve(sicm_symplectic_verlet, 2, watched_kepler_force,
                                   watched_velocity, &watch, &t, 200 * period, h, q, p),
            SICM_SUCCESS);
  // Each step adds h F to p and h v to q. Added plainly, each sum is rounded to an ulp of q or
  // p, so L random-walks by about eps |q| |p| = eps |L| a step, eps |L| sqrt(steps) in all.
  // Compensated, only the roundings of the increments themselves remain, about
  // eps h (|q| |F| + |p| |v|) <= eps h S a step with S = 1/r + v^2, 5 at periapsis, which walk to
  // eps h S sqrt(steps); add a few ulps of L for the last rounding of q and p and for
  // computing L. Measured: 2.2e-16 compensated, 5.1e-14 plain (0.19 eps |L| sqrt(steps)).
  const double eps = 2.220446049250313e-16, S = 5;
  const double bound = 4 * eps * (std::fabs(watch.L0) + h * S * std::sqrt(steps)); // 4.7e-15
  EXPECT_LT(watch.max_error, bound);
  EXPECT_NEAR(t, 200 * period, 1e-12);
}

// The same orbit as a sicm_ode, y = (t, q, p), advanced by many short evolve calls, as evolve's
// monitor loop does: the compensations must carry from call to call, or each call's last
// rounding of q and p stays, eps |L| sqrt(calls) in all (measured 2.7e-14 here without).
int kepler_rhs(double, const double *y, double *f, void *) {
  const double r2 = y[1] * y[1] + y[2] * y[2], r3 = r2 * std::sqrt(r2);
  f[0] = 1, f[1] = y[3], f[2] = y[4], f[3] = -y[1] / r3, f[4] = -y[2] / r3;
  return 0;
}

TEST(Symplectic, CompensationCarriesAcrossEvolveCalls) {
  const double e = 0.5, period = 2 * M_PI, h = period / 10000;
  const int calls = 100000, steps_per_call = 10; // 100 periods
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_verlet, 5, kepler_rhs, nullptr, h, h);
  double y[5] = {0, 1 - e, 0, 0, std::sqrt((1 + e) / (1 - e))};
  const double L0 = y[1] * y[4] - y[2] * y[3];
  double t = 0, worst = 0;
  for (int k = 1; k <= calls; ++k) {
    ASSERT_EQ(sicm_ode_evolve(o, &t, k * steps_per_call * h, y), SICM_SUCCESS);
    worst = std::fmax(worst, std::fabs(y[1] * y[4] - y[2] * y[3] - L0));
  }
  // The bound of CompensatedSummationKeepsAngularMomentum, for the 1e6 steps.
  const double eps = 2.220446049250313e-16, S = 5;
  EXPECT_LT(worst, 4 * eps * (std::fabs(L0) + h * S * std::sqrt(calls * steps_per_call)));
  sicm_ode_free(o);
}

int stop_force(double t, const double *q, double *f, void *) {
  f[0] = q[0];
  return t > 1 ? 3 : 0;
}

TEST(Symplectic, LandsExactlyOnT1AndReportsFailures) {
  int ndof = 1;
  double q[1] = {1}, p[1] = {0}, t = 0;
  // 0.3 does not divide 1: four steps of 0.25.
  ASSERT_EQ(sicm_symplectic_evolve(sicm_symplectic_yoshida6, 1, driven_force, unit_mass_velocity,
                                   &ndof, &t, 1.0, 0.3, q, p),
            SICM_SUCCESS);
  EXPECT_EQ(t, 1.0);
  CaptureErrors capture;
  t = 0, q[0] = 1, p[0] = 0;
  EXPECT_EQ(sicm_symplectic_evolve(sicm_symplectic_verlet, 1, stop_force, unit_mass_velocity, &ndof,
                                   &t, 2.0, 0.1, q, p),
            SICM_EUSER);
  EXPECT_NEAR(t, 1.0, 1e-9);
  EXPECT_NEAR(q[0], std::cos(t), 1e-2);
  ASSERT_EQ(CaptureErrors::messages().size(), 1u);
  EXPECT_NE(CaptureErrors::messages()[0].find("t = " + format(t)), std::string::npos)
      << CaptureErrors::messages()[0];
  EXPECT_NE(CaptureErrors::messages()[0].find("state"), std::string::npos);
  EXPECT_EQ(sicm_symplectic_evolve(sicm_symplectic_verlet, 1, stop_force, unit_mass_velocity, &ndof,
                                   &t, 2.0, 0, q, p),
            SICM_EINVAL);
}

} // namespace
