// Unit tests that Bulirsch-Stoer's results are smooth in the initial state: a Poincare map
// differentiated by central differences must agree with the same differences of a tight rk8pd.
#include <gtest/gtest.h>

#include <cmath>

#include "sicm/runtime.h"

namespace {

// The periodically driven pendulum of SICM section 3.6.1 (Figure 3.12): m = l = 1, g = 9.8,
// pivot at y_s(t) = A cos(omega t) with A = 0.05 and omega = 4.2 sqrt(g). State (t, theta, p),
// with p = theta' + sin(theta) y_s'(t) the momentum conjugate to theta.
constexpr double kG = 9.8, kA = 0.05;
const double kOmega = 4.2 * std::sqrt(kG);

int driven_pendulum(double t, const double *y, double *dy, void *) {
  const double ys_dot = -kA * kOmega * std::sin(kOmega * t);
  const double theta_dot = y[2] - std::sin(y[1]) * ys_dot;
  dy[0] = 1;
  dy[1] = theta_dot;
  dy[2] = std::cos(y[1]) * theta_dot * ys_dot - kG * std::sin(y[1]);
  return 0;
}

// The stroboscopic map: (theta, p) advanced over one drive period from t = 0, each call with a
// fresh integrator, as state-advancer does.
void section_map(const sicm_ode_step_type *type, double tol, double theta, double p,
                 double out[2]) {
  sicm_ode *o = sicm_ode_alloc(type, 3, driven_pendulum, nullptr, tol, tol);
  ASSERT_NE(o, nullptr);
  double t = 0, y[3] = {0, theta, p};
  ASSERT_EQ(sicm_ode_evolve(o, &t, 2 * M_PI / kOmega, y), SICM_SUCCESS) << sicm_ode_last_error(o);
  sicm_ode_free(o);
  out[0] = y[1];
  out[1] = y[2];
}

// The map's Jacobian by central differences with increment h, row-major.
void section_jacobian(const sicm_ode_step_type *type, double tol, double theta, double p, double h,
                      double J[4]) {
  double a[2], b[2], c[2], d[2];
  section_map(type, tol, theta + h, p, a);
  section_map(type, tol, theta - h, p, b);
  section_map(type, tol, theta, p + h, c);
  section_map(type, tol, theta, p - h, d);
  J[0] = (a[0] - b[0]) / (2 * h);
  J[1] = (c[0] - d[0]) / (2 * h);
  J[2] = (a[1] - b[1]) / (2 * h);
  J[3] = (c[1] - d[1]) / (2 * h);
}

// The book's check of Figure 3.12: central differences with h = 1e-6 of the map computed at
// tolerance 1e-12. A difference quotient over 2e-6 turns any jump of the map between
// neighbouring initial states into an error of jump / 2e-6, so the entries are right to 1e-7
// only if the map is smooth to 2e-13, five times below the tolerance. The reference is the same
// differences of rk8pd at 1e-14. The points include starts from rest (p = 0), where the first
// step's error estimate is pure rounding noise; before the noise floor and Bulirsch's sequence,
// entries there were off by up to 4e-6 and determinants by up to 2e-6.
TEST(OdeBsSmoothness, DrivenPendulumMapJacobianMatchesReference) {
  const double points[][2] = {{0.5, 0}, {1, 3},    {0, 10},  {0.3, 0}, {1.2, 0}, {2, 0},  {-0.7, 0},
                              {2.5, 0}, {-1.5, 0}, {0.1, 0}, {3, -5},  {-2, 7},  {1, -10}};
  const double h = 1e-6;
  for (const auto &pt : points) {
    SCOPED_TRACE(testing::Message() << "theta = " << pt[0] << ", p = " << pt[1]);
    double J[4], R[4];
    section_jacobian(sicm_ode_step_bs, 1e-12, pt[0], pt[1], h, J);
    section_jacobian(sicm_ode_step_rk8pd, 1e-14, pt[0], pt[1], h, R);
    for (int k = 0; k < 4; k++)
      EXPECT_NEAR(J[k], R[k], 5e-7) << "entry " << k;
    // Area preservation, as the book's program checks it.
    EXPECT_NEAR(J[0] * J[3] - J[1] * J[2], 1.0, 1e-6);
  }
}

// The same along a line of nearby starts: consecutive maps from states 2e-7 apart must differ
// from the reference's by no more than a small fraction of the tolerance. Jumps of about the
// tolerance (3.5e-12) used to occur between most neighbours here.
TEST(OdeBsSmoothness, NearbyStartsGiveNearbyErrors) {
  double prev[2] = {0, 0};
  for (int i = 0; i <= 40; i++) {
    const double p = -4e-6 + i * 2e-7;
    double bs[2], ref[2];
    section_map(sicm_ode_step_bs, 1e-12, 0.5, p, bs);
    section_map(sicm_ode_step_rk8pd, 1e-14, 0.5, p, ref);
    const double err[2] = {bs[0] - ref[0], bs[1] - ref[1]};
    // The error itself is bounded by the tolerance times the size of the state, about 2.
    EXPECT_LT(std::fabs(err[0]), 5e-12);
    EXPECT_LT(std::fabs(err[1]), 5e-12);
    if (i > 0) {
      EXPECT_LT(std::fabs(err[0] - prev[0]), 2e-13) << "between p = " << p - 2e-7 << " and " << p;
      EXPECT_LT(std::fabs(err[1] - prev[1]), 2e-13) << "between p = " << p - 2e-7 << " and " << p;
    }
    prev[0] = err[0];
    prev[1] = err[1];
  }
}

} // namespace
