// The linear solves kernels emit (LDL^T in a loop, compiler/codegen/emit_c.cpp)
// against Eigen's LDLT (dynamic size, mapped on the same array), on the mass matrices of
// pendulum chains: which should a kernel call? Run by bench/linear-solve-vs-eigen,
// which extracts the emitted helpers into solve_support.h first.
//
// For each n, R rounds alternate the three; each round factors and solves
// CALLS matrices (a chain's mass matrix at random angles, rebuilt every
// call so that nothing is hoisted) and reports ns per factor+solve, the
// matrix's construction included in both. Medians of the rounds and the
// ratio emitted/Eigen are printed.
#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

extern "C" {
#include "solve_support.h"
}

namespace {

// M_jk = mu_max(j,k) l_j l_k cos(th_j - th_k), mu_j = sum_{i >= j} m_i.
void chain_mass_matrix(int n, const double *th, double *a) {
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) {
      double mu = 0;
      for (int i = std::max(j, k); i < n; ++i)
        mu += 1.0 + 0.1 * i;
      a[j * n + k] = mu * (1 - 0.02 * j) * (1 - 0.02 * k) * std::cos(th[j] - th[k]);
    }
}

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <typename F> double time_calls(int calls, F f) {
  double t0 = now();
  for (int c = 0; c < calls; ++c)
    f(c);
  return (now() - t0) / calls * 1e9;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

} // namespace

int main(int argc, char **argv) {
  int rounds = argc > 1 ? std::atoi(argv[1]) : 9;
  std::printf("%4s %12s %12s %10s\n", "n", "emitted ns", "eigen ns", "ratio");
  for (int n : {2, 4, 8, 12, 16, 24}) {
    std::mt19937 rng(n);
    std::uniform_real_distribution<double> angle(-1.5, 1.5);
    const int kStates = 64;
    std::vector<double> th(kStates * n), rhs(kStates * n);
    for (double &x : th)
      x = angle(rng);
    for (double &x : rhs)
      x = angle(rng);
    int calls = std::max(2000, 4000000 / (n * n * n));
    std::vector<double> a(n * n), x(n);
    double sink = 0, check = 0;
    std::vector<double> t_emit, t_dyn;
    for (int r = 0; r < rounds; ++r) {
      t_emit.push_back(time_calls(calls, [&](int c) {
        int s = c % kStates;
        chain_mass_matrix(n, &th[s * n], a.data());
        std::copy(&rhs[s * n], &rhs[s * n] + n, x.begin());
        sicm_ldlt_factor(n, a.data());
        sicm_ldlt_solve(n, a.data(), x.data());
        sink += x[0];
      }));
      t_dyn.push_back(time_calls(calls, [&](int c) {
        int s = c % kStates;
        chain_mass_matrix(n, &th[s * n], a.data());
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> m(
            a.data(), n, n);
        Eigen::Map<const Eigen::VectorXd> b(&rhs[s * n], n);
        Eigen::VectorXd y = m.ldlt().solve(b);
        sink += y[0];
      }));
    }
    // The two agree (a sanity check, not a timing).
    chain_mass_matrix(n, &th[0], a.data());
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> m(a.data(),
                                                                                        n, n);
    Eigen::VectorXd y = m.ldlt().solve(Eigen::Map<const Eigen::VectorXd>(&rhs[0], n));
    std::copy(&rhs[0], &rhs[0] + n, x.begin());
    sicm_ldlt_factor(n, a.data());
    sicm_ldlt_solve(n, a.data(), x.data());
    for (int i = 0; i < n; ++i)
      check = std::max(check, std::fabs(x[i] - y[i]) / std::max(1.0, std::fabs(y[i])));
    double e = median(t_emit), d = median(t_dyn);
    std::printf("%4d %12.1f %12.1f %10.3f   (max rel diff %.1e, sink %g)\n", n, e, d, e / d, check,
                sink);
  }
  return 0;
}
