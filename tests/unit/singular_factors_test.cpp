// Unit tests of what kernels divide by (compiler/codegen/singular_factors.cpp)
// and of the tests that name it when an integration fails (sicm_ode_set_singularity_probe).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "algebra/symbolic.hpp"
#include "capture_errors.hpp"
#include "cas/expr.hpp"
#include "codegen/kernel_form.hpp"
#include "codegen/singular_factors.hpp"
#include "eval/interp.hpp"
#include "sicm/runtime.h"
#include "syntax/reader.hpp"

namespace sicm {
namespace {

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<singular_factors_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

ExprId traced(const std::string &prefix) {
  return leaf_expr(datum_to_expression(run("'" + prefix)));
}

// The texts of the singular factors of the outputs, x named "(ref state 1)",
// sorted (their order follows node ids, which depend on what was built before).
std::string name_of(Symbol *s) {
  return std::string(s->name) == "x" ? std::string("(ref state 1)") : std::string();
}
std::vector<std::string> texts(const std::vector<std::string> &prefixes) {
  std::vector<ExprId> outputs;
  for (const std::string &p : prefixes)
    outputs.push_back(traced(p));
  std::vector<std::string> out = singular_factors(outputs, name_of).texts;
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SingularFactors, DivisorsSplitIntoTheirFactors) {
  EXPECT_EQ(texts({"(* a (expt (* 2 (sin x) (expt r 2)) -1))"}),
            (std::vector<std::string>{"(sin (ref state 1))", "r"}));
}

TEST(SingularFactors, QuotientsAndLogarithms) {
  EXPECT_EQ(texts({"(/ a (+ x 1))", "(log y)"}),
            (std::vector<std::string>{"(+ (ref state 1) 1)", "y"}));
}

TEST(SingularFactors, EachFactorOnce) {
  EXPECT_EQ(texts({"(expt r -3)", "(* 2 (expt r -1))"}), (std::vector<std::string>{"r"}));
}

TEST(SingularFactors, NoDivisionNoFactors) {
  EXPECT_TRUE(texts({"(* a (sin x))", "(expt r 2)"}).empty());
}

// y' = -1/(2y) from y = 1 at t = 0: y = sqrt(1 - t) reaches 0, where the
// derivative is infinite, at t = 1.
int towards_zero(double, const double *y, double *dydt, void *) {
  dydt[0] = -0.5 / y[0];
  return 0;
}
void probe_y(const double *y, double *values, const double *) {
  values[0] = y[0];
}

TEST(SingularityProbe, NamesTheFactorThatWentToZero) {
  const char *const names[] = {"(ref state 0)"};
  for (const sicm_ode_step_type *T : {sicm_ode_step_bs, sicm_ode_step_rk8pd}) {
    SCOPED_TRACE(sicm_ode_step_type_name(T));
    CaptureErrors capture;
    sicm_ode *o = sicm_ode_alloc(T, 1, towards_zero, nullptr, 1e-10, 1e-10);
    ASSERT_EQ(sicm_ode_set_singularity_probe(o, probe_y, nullptr, 1, names), SICM_SUCCESS);
    double t = 0, y[1] = {1};
    EXPECT_NE(sicm_ode_evolve(o, &t, 2, y), SICM_SUCCESS);
    std::string message = sicm_ode_last_error(o);
    EXPECT_NE(message.find("divides by (ref state 0), which went from 1. at t = 0. to "),
              std::string::npos)
        << message;
    EXPECT_NEAR(t, 1.0, 1e-6);
    sicm_ode_free(o);
  }
}

TEST(SingularityProbe, SilentWhenNothingShrank) {
  // The same failure, but the probe's quantity stays put: no claim is made.
  const char *const names[] = {"c"};
  CaptureErrors capture;
  sicm_ode *o = sicm_ode_alloc(sicm_ode_step_bs, 1, towards_zero, nullptr, 1e-10, 1e-10);
  ASSERT_EQ(sicm_ode_set_singularity_probe(
                o, [](const double *, double *v, const double *) { v[0] = 1; }, nullptr, 1, names),
            SICM_SUCCESS);
  double t = 0, y[1] = {1};
  EXPECT_NE(sicm_ode_evolve(o, &t, 2, y), SICM_SUCCESS);
  EXPECT_EQ(std::string(sicm_ode_last_error(o)).find("divides by"), std::string::npos);
  sicm_ode_free(o);
}

} // namespace
} // namespace sicm
