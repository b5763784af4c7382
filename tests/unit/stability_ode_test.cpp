// Long-run stability of the ODE integrators: energy conservation of a pendulum over t = 1000.
#include <gtest/gtest.h>

#include <cmath>

#include "sicm/runtime.h"

namespace {

// Pendulum theta'' = -sin theta (unit length, mass and g), E = p^2/2 - cos theta.
int pendulum(double, const double *y, double *dy, void *) {
  dy[0] = y[1];
  dy[1] = -std::sin(y[0]);
  return 0;
}

double energy(const double *y) {
  return 0.5 * y[1] * y[1] - std::cos(y[0]);
}

// The energy is sampled every time unit through repeated evolve calls, the way a monitor
// would; an adaptive method drifts slowly, so the largest relative deviation over the whole
// run is what is checked.
double max_energy_drift(const sicm_ode_step_type *type, double tol, unsigned long *evals) {
  sicm_ode *o = sicm_ode_alloc(type, 2, pendulum, nullptr, tol, tol);
  double t = 0, y[2] = {1.0, 0.0};
  const double e0 = energy(y);
  double drift = 0;
  for (int k = 1; k <= 1000; k++) {
    EXPECT_EQ(sicm_ode_evolve(o, &t, k, y), SICM_SUCCESS) << sicm_ode_last_error(o);
    drift = std::fmax(drift, std::fabs((energy(y) - e0) / e0));
  }
  *evals = sicm_ode_get_stats(o)->rhs_evals;
  sicm_ode_free(o);
  return drift;
}

TEST(StabilityOde, PendulumEnergyRk8pd) {
  unsigned long evals = 0;
  double drift = max_energy_drift(sicm_ode_step_rk8pd, 1e-12, &evals);
  EXPECT_LT(drift, 1e-8) << evals << " evaluations";
}

TEST(StabilityOde, PendulumEnergyBulirschStoer) {
  unsigned long evals = 0;
  double drift = max_energy_drift(sicm_ode_step_bs, 1e-12, &evals);
  EXPECT_LT(drift, 1e-8) << evals << " evaluations";
}

// A large swing (amplitude 3 rad, close to the separatrix at pi) with the symplectic map: no
// secular drift, only a bounded oscillation of the energy.
int pendulum_force(double, const double *q, double *f, void *) {
  f[0] = std::sin(q[0]);
  return 0;
}

int unit_velocity(const double *p, double *v, void *) {
  v[0] = p[0];
  return 0;
}

TEST(StabilityOde, PendulumEnergySymplecticNearSeparatrix) {
  double q[1] = {3.0}, p[1] = {0}, t = 0;
  const double e0 = 0.5 * p[0] * p[0] - std::cos(q[0]);
  double first = 0, last = 0;
  for (int k = 1; k <= 1000; k++) {
    ASSERT_EQ(sicm_symplectic_evolve(sicm_symplectic_yoshida6, 1, pendulum_force, unit_velocity,
                                     nullptr, &t, k, 0.05, q, p),
              SICM_SUCCESS);
    double de = std::fabs(0.5 * p[0] * p[0] - std::cos(q[0]) - e0);
    if (k <= 100) first = std::fmax(first, de);
    if (k > 900) last = std::fmax(last, de);
  }
  EXPECT_LT(first, 1e-7);
  EXPECT_LT(last, 2 * first);
}

} // namespace
