// Dense linear algebra over Eigen: the C functions of sicm/linalg.h.
//
// C++17, the one runtime file that is not C11: it is compiled with
// -std=c++17 and Eigen's headers (Makefile). No exception leaves it: the
// only one Eigen can raise is std::bad_alloc, which becomes SICM_ENOMEM.
#include <algorithm>
#include <cmath>
#include <complex>
#include <new>
#include <vector>

#include <Eigen/Dense>

#include "sicm/linalg.h"
#include "sicm/runtime.h"

namespace {

// The order of sicm_linalg_eigenvalues: decreasing modulus, then decreasing
// real part, then decreasing imaginary part.
bool comes_first(const std::complex<double> &a, const std::complex<double> &b) {
  double ma = std::abs(a), mb = std::abs(b);
  if (ma != mb) return ma > mb;
  if (a.real() != b.real()) return a.real() > b.real();
  return a.imag() > b.imag();
}

} // namespace

extern "C" int sicm_linalg_eigenvalues(size_t n, const double *a, double *re, double *im) {
  static const char who[] = "sicm_linalg_eigenvalues";
  if (n == 0) return sicm_error(SICM_EINVAL, "%s: the matrix is empty", who);
  for (size_t k = 0; k < n * n; ++k)
    if (!std::isfinite(a[k]))
      return sicm_error(SICM_EINVAL, "%s: the entry (%zu, %zu) is %g, not a finite number", who,
                        k / n, k % n, a[k]);
  try {
    using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    Eigen::Map<const Matrix> m(a, static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    Eigen::EigenSolver<Eigen::MatrixXd> solver(Eigen::MatrixXd(m), false);
    if (solver.info() != Eigen::Success)
      return sicm_error(SICM_ECONV, "%s: the QR iteration did not converge (%zu x %zu matrix)", who,
                        n, n);
    const auto &values = solver.eigenvalues();
    std::vector<std::complex<double>> sorted(values.data(), values.data() + n);
    // Real eigenvalues have an imaginary part of exactly 0 in Eigen's real
    // Schur form; keep it so (no -0.).
    for (auto &z : sorted)
      if (z.imag() == 0) z = std::complex<double>(z.real(), 0.0);
    std::stable_sort(sorted.begin(), sorted.end(), comes_first);
    for (size_t k = 0; k < n; ++k) {
      re[k] = sorted[k].real();
      im[k] = sorted[k].imag();
    }
    return SICM_SUCCESS;
  } catch (const std::bad_alloc &) {
    return sicm_error(SICM_ENOMEM, "%s: out of memory (%zu x %zu matrix)", who, n, n);
  }
}
