// Unit tests of the Taylor emitter: the coefficients it generates against the analytic series.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "codegen/kernel.hpp"
#include "eval/interp.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

constexpr int kOrder = 20;

Value run(const std::string &text) {
  Value v;
  for (const ReadForm &f : read_all(register_source("<taylor_test>", text)))
    v = eval_toplevel(f.datum, f.loc);
  return v;
}

// The kernel of the system derivative `body` (in t = (ref s 0), x = (ref s 1)
// and y = (ref s 2) of a state s of three components), with its Taylor
// coefficients.
const Kernel *taylor_kernel(const std::string &body) {
  std::string ignored;
  Value proc = run("(lambda (s) (let ((t (ref s 0)) (x (ref s 1)) (y (ref s 2))) " + body + "))");
  return compile_kernel(proc, run("(list (up 0. 1. 1.))"), "taylor_test", &ignored,
                        KernelOptions{.taylor = true});
}

// Coefficients 0..kOrder of component i of the solution through `state`.
std::vector<double> series(const Kernel *k, std::vector<double> state, size_t i) {
  std::vector<double> c((kOrder + 1) * state.size());
  k->taylor(state.data(), kOrder, c.data(), nullptr);
  std::vector<double> out;
  for (int j = 0; j <= kOrder; ++j)
    out.push_back(c[j * state.size() + i]);
  return out;
}

void expect_series(const std::vector<double> &got, const std::vector<double> &want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t k = 0; k < got.size(); ++k)
    EXPECT_NEAR(got[k], want[k], 1e-14 * std::fmax(1.0, std::fabs(want[k]))) << "coefficient " << k;
}

// The series of x with x(0) = 0 and x' = g, from g's series.
std::vector<double> integral(const std::vector<double> &g) {
  std::vector<double> x{0.0};
  for (int k = 0; k < kOrder; ++k)
    x.push_back(g[k] / (k + 1));
  return x;
}

// The series of (1 + t)^a.
std::vector<double> binomial(double a) {
  std::vector<double> c{1.0};
  for (int k = 1; k <= kOrder; ++k)
    c.push_back(c.back() * (a - (k - 1)) / k);
  return c;
}

double factorial(int k) {
  return k == 0 ? 1.0 : k * factorial(k - 1);
}

TEST(TaylorEmitter, TimeComponentIsLinear) {
  const Kernel *k = taylor_kernel("(up 1 0 0)");
  ASSERT_NE(k, nullptr);
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> want(kOrder + 1, 0.0);
  want[0] = 2.5;
  want[1] = 1;
  expect_series(series(k, {2.5, 0, 0}, 0), want);
}

TEST(TaylorEmitter, Exp) {
  const Kernel *k = taylor_kernel("(up 1 (exp t) 0)");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> want;
  for (int j = 0; j <= kOrder; ++j)
    want.push_back(1 / factorial(j));
  expect_series(series(k, {0, 1, 0}, 1), want);
}

TEST(TaylorEmitter, SinAndCosTogether) {
  const Kernel *k = taylor_kernel("(up 1 (cos t) (* -1 (sin t)))");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> sin_series, cos_series;
  for (int j = 0; j <= kOrder; ++j) {
    double term = 1 / factorial(j) * ((j / 2) % 2 ? -1 : 1);
    sin_series.push_back(j % 2 ? term : 0);
    cos_series.push_back(j % 2 ? 0 : term);
  }
  expect_series(series(k, {0, 0, 1}, 1), sin_series);
  expect_series(series(k, {0, 0, 1}, 2), cos_series);
}

TEST(TaylorEmitter, QuotientAndSquareGiveOneOverOneMinusT) {
  std::vector<double> ones(kOrder + 1, 1.0);
  const Kernel *q = taylor_kernel("(up 1 (/ 1 (square (- 1 t))) 0)");
  ASSERT_NE(q->taylor, nullptr) << q->taylor_why_not;
  expect_series(series(q, {0, 1, 0}, 1), ones);
  const Kernel *s = taylor_kernel("(up 1 (square x) 0)"); // x' = x^2, x(0) = 1
  ASSERT_NE(s->taylor, nullptr) << s->taylor_why_not;
  expect_series(series(s, {0, 1, 0}, 1), ones);
}

// Sums of squares are one recurrence (sum_sq3, and sum_sq2 in twos):
// x' = sin^2 t + e^(2t) + (1 + t)^2, y' = cos^2 t + (2 + t)^2 + (3 + t)^2 + e^(-2t).
TEST(TaylorEmitter, SumsOfSquares) {
  const Kernel *k = taylor_kernel(
      "(up 1 (+ (square (sin t)) (square (exp t)) (square (+ 1 t))) "
      "(+ (+ (square (cos t)) (square (+ 2 t))) (+ (square (+ 3 t)) (square (exp (- t))))))");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> x(kOrder + 1, 0.0), y(kOrder + 1, 0.0);
  for (int n = 0; n <= kOrder; ++n) {
    double cos2 = n % 2 ? 0 : ((n / 2) % 2 ? -1 : 1) * std::pow(2.0, n) / factorial(n); // cos 2t
    double sin_sq = n == 0 ? 0 : -cos2 / 2, cos_sq = (n == 0 ? 0.5 : 0) + cos2 / 2;
    x[n] = sin_sq + std::pow(2.0, n) / factorial(n);
    y[n] = cos_sq + std::pow(-2.0, n) / factorial(n);
  }
  x[0] += 1, x[1] += 2, x[2] += 1;   // (1 + t)^2
  y[0] += 13, y[1] += 10, y[2] += 2; // (2 + t)^2 + (3 + t)^2
  expect_series(series(k, {0, 0, 0}, 1), integral(x));
  expect_series(series(k, {0, 0, 0}, 2), integral(y));
}

// Products sharing their later factor are computed together (product2):
// x' = (1 + t) e^t, y' = (2 + t) e^t, so x = t e^t and y = (1 + t) e^t - 1.
TEST(TaylorEmitter, ProductsOfOneSharedFactor) {
  const Kernel *k =
      taylor_kernel("(let* ((a (+ 1 t)) (b (+ 2 t)) (e (exp t))) (up 1 (* a e) (* 3 b e)))");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> x{0.0}, y{0.0};
  for (int n = 1; n <= kOrder; ++n) {
    x.push_back(1 / factorial(n - 1));
    y.push_back(3 * (1 / factorial(n) + 1 / factorial(n - 1)));
  }
  expect_series(series(k, {0, 0, 0}, 1), x);
  expect_series(series(k, {0, 0, 0}, 2), y);
}

TEST(TaylorEmitter, Sqrt) {
  const Kernel *k = taylor_kernel("(up 1 (/ 1 (* 2 (sqrt (+ 1 t)))) 0)");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  expect_series(series(k, {0, 1, 0}, 1), binomial(0.5));
}

TEST(TaylorEmitter, RealAndNegativePowers) {
  const Kernel *k = taylor_kernel("(up 1 (expt (+ 1 t) 1/3) (expt (+ 1 t) -3))");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  expect_series(series(k, {0, 0, 0}, 1), integral(binomial(1.0 / 3)));
  expect_series(series(k, {0, 0, 0}, 2), integral(binomial(-3)));
}

TEST(TaylorEmitter, Log) {
  const Kernel *k = taylor_kernel("(up 1 (log (+ 1 t)) 0)");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> g{0.0};
  for (int j = 1; j <= kOrder; ++j)
    g.push_back((j % 2 ? 1.0 : -1.0) / j);
  expect_series(series(k, {0, 0, 0}, 1), integral(g));
}

TEST(TaylorEmitter, AtanOfOneAndTwoArguments) {
  const Kernel *k = taylor_kernel("(up 1 (atan t) (atan (sin t) (cos t)))");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  std::vector<double> g;
  for (int j = 0; j <= kOrder; ++j)
    g.push_back(j % 2 ? ((j / 2) % 2 ? -1.0 : 1.0) / j : 0.0);
  expect_series(series(k, {0, 0, 0}, 1), integral(g));
  std::vector<double> half_t_squared(kOrder + 1, 0.0); // atan2(sin t, cos t) = t
  half_t_squared[2] = 0.5;
  expect_series(series(k, {0, 0, 0}, 2), half_t_squared);
}

// (expt (sqrt u) a) is one power recurrence of u at a/2 (the Kepler
// problem's r^-3): the series of (1 + t)^(-3/2).
TEST(TaylorEmitter, PowerOfARoot) {
  const Kernel *k = taylor_kernel("(up 1 (expt (sqrt (+ 1 t)) -3) 0)");
  ASSERT_NE(k->taylor, nullptr) << k->taylor_why_not;
  EXPECT_EQ(k->c_source.find("sicm_tc_sqrt(v"), std::string::npos) << "no square root left";
  expect_series(series(k, {0, 0, 0}, 1), integral(binomial(-1.5)));
}

// ---- taylor-extended: the same recurrences in long double ----

std::vector<long double> series_extended(const Kernel *k, std::vector<long double> state,
                                         size_t i) {
  std::vector<long double> c((kOrder + 1) * state.size());
  k->taylor_extended(state.data(), kOrder, c.data(), nullptr);
  std::vector<long double> out;
  for (int j = 0; j <= kOrder; ++j)
    out.push_back(c[j * state.size() + i]);
  return out;
}

// Agreement to a few roundings of long double (5.4e-20), far below double's.
void expect_series_extended(const std::vector<long double> &got,
                            const std::vector<long double> &want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t k = 0; k < got.size(); ++k)
    EXPECT_LE(fabsl(got[k] - want[k]), 1e-18L * fmaxl(1.0L, fabsl(want[k])))
        << "coefficient " << k << ": " << (double)got[k] << " vs " << (double)want[k];
}

TEST(TaylorEmitter, ExtendedExpAndPowers) {
  const Kernel *k = taylor_kernel("(up 1 (exp t) (expt (sqrt (+ 1 t)) -3))");
  ASSERT_NE(k->taylor_extended, nullptr) << k->taylor_why_not;
  std::vector<long double> exp_series, power_series{0.0L};
  long double term = 1, binomial_term = 1;
  for (int j = 0; j <= kOrder; ++j) {
    exp_series.push_back(term);
    term /= j + 1;
    if (j < kOrder) power_series.push_back(binomial_term / (j + 1)); // integral of (1+t)^-1.5
    binomial_term *= (-1.5L - j) / (j + 1);
  }
  expect_series_extended(series_extended(k, {0, 1, 0}, 1), exp_series);
  expect_series_extended(series_extended(k, {0, 1, 0}, 2), power_series);
}

// Exact constants are long double constants: 1/3 to long double's
// rounding, not double's (1/3 as a double is off by 1.9e-17). (A flonum,
// such as (sqrt 2) evaluated by the program, is the double it is.)
TEST(TaylorEmitter, ExtendedConstants) {
  const Kernel *k = taylor_kernel("(up 1 (* 1/3 (+ t 1)) 0)");
  ASSERT_NE(k->taylor_extended, nullptr) << k->taylor_why_not;
  std::vector<long double> third = series_extended(k, {0, 0, 0}, 1);
  EXPECT_LE(fabsl(third[1] - 1.0L / 3), 1e-19L);
}

TEST(TaylorEmitter, OperationsWithoutRecurrencesAreNamed) {
  const Kernel *k = taylor_kernel("(up 1 (tan t) 0)");
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k->taylor, nullptr);
  EXPECT_NE(k->taylor_why_not.find("tan"), std::string::npos) << k->taylor_why_not;
}

} // namespace
