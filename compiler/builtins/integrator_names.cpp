// The integrators by name: the names a program may give evolve,
// state-advancer and crossings, the runtime's step type of each and its
// variable in generated C (see numerics_defaults.hpp), shared by sicm run
// and sicm build.
#include <string>

#include "builtins/numerics_defaults.hpp"

namespace sicm {

namespace {

struct IntegratorName {
  const char *name;
  const sicm_ode_step_type *const *type;
  const char *c_name;
};
const IntegratorName kIntegrators[] = {
    {"bulirsch-stoer", &sicm_ode_step_bs, "sicm_ode_step_bs"},
    {"bs", &sicm_ode_step_bs, "sicm_ode_step_bs"},
    {"rk8pd", &sicm_ode_step_rk8pd, "sicm_ode_step_rk8pd"},
    {"rkf45", &sicm_ode_step_rkf45, "sicm_ode_step_rkf45"},
    {"rkck", &sicm_ode_step_rkck, "sicm_ode_step_rkck"},
    // scmutils' quality-controlled RK4 and trapezoid rule (step doubling).
    {"qcrk4", &sicm_ode_step_qcrk4, "sicm_ode_step_qcrk4"},
    {"qcctrap2", &sicm_ode_step_qcctrap2, "sicm_ode_step_qcctrap2"},
    {"msbdf", &sicm_ode_step_msbdf, "sicm_ode_step_msbdf"},
    // scmutils' gear and explicit-gear are one method, Gear's: variable-order
    // BDF with Newton iteration on the Jacobian ("explicit" is the system
    // given as y' = f(y), against its implicit-gear). GSL's msbdf is an
    // implementation of that method (orders 1-5 where scmutils has 1-4).
    {"gear", &sicm_ode_step_msbdf, "sicm_ode_step_msbdf"},
    {"explicit-gear", &sicm_ode_step_msbdf, "sicm_ode_step_msbdf"},
    {"cvode-adams", &sicm_ode_step_cvode_adams, "sicm_ode_step_cvode_adams"},
    {"cvode-bdf", &sicm_ode_step_cvode_bdf, "sicm_ode_step_cvode_bdf"},
    // Fixed-step symplectic methods: the tolerance argument is the step size.
    {"verlet", &sicm_ode_step_verlet, "sicm_ode_step_verlet"},
    {"yoshida4", &sicm_ode_step_yoshida4, "sicm_ode_step_yoshida4"},
    {"yoshida6", &sicm_ode_step_yoshida6, "sicm_ode_step_yoshida6"},
    {"yoshida8", &sicm_ode_step_yoshida8, "sicm_ode_step_yoshida8"},
    // Taylor series from coefficients generated from the compiled derivative.
    {"taylor", &sicm_ode_step_taylor, "sicm_ode_step_taylor"},
    {"taylor-extended", &sicm_ode_step_taylor_extended, "sicm_ode_step_taylor_extended"},
};

const IntegratorName *find_integrator(const std::string &name) {
  for (const IntegratorName &i : kIntegrators)
    if (name == i.name) return &i;
  return nullptr;
}

// Integrators of scmutils that sicm does not provide, and what to use
// instead: naming one is an error that says so, never a substitution.
struct MissingIntegrator {
  const char *name;
  const char *instead;
};
const MissingIntegrator kNotProvided[] = {
    {"implicit-gear", "it takes a system given implicitly, by a corrector; for stiff systems "
                      "use gear (Gear's BDF method, GSL's msbdf) or cvode-bdf"},
    {"ntqc", "it is the trapezoid rule with Newton iteration; use qcctrap2 (the same rule with "
             "corrector iteration) or, for stiff systems, cvode-bdf"},
};

const char *const kIntegratorList =
    "bulirsch-stoer, rk8pd, rkf45, rkck, qcrk4, qcctrap2, msbdf, gear, explicit-gear, "
    "cvode-adams, cvode-bdf, verlet, yoshida4, yoshida6, yoshida8, taylor, taylor-extended";

} // namespace

std::string integrator_not_provided(const std::string &name) {
  for (const MissingIntegrator &m : kNotProvided)
    if (name == m.name)
      return "sicm does not provide the integrator " + name + " of scmutils: " + m.instead;
  return "";
}

const char *integrator_list() {
  return kIntegratorList;
}

const char *integrator_c_name(const std::string &name) {
  const IntegratorName *i = find_integrator(name);
  return i ? i->c_name : nullptr;
}

const sicm_ode_step_type *integrator_of_c_name(const std::string &c_name) {
  for (const IntegratorName &i : kIntegrators)
    if (c_name == i.c_name) return *i.type;
  return nullptr;
}

const sicm_ode_step_type *integrator_named(const std::string &name) {
  const IntegratorName *i = find_integrator(name);
  return i ? *i->type : nullptr;
}

bool integrator_is_fixed_step(const sicm_ode_step_type *T) {
  return T == sicm_ode_step_verlet || T == sicm_ode_step_yoshida4 || T == sicm_ode_step_yoshida6 ||
         T == sicm_ode_step_yoshida8;
}

} // namespace sicm
