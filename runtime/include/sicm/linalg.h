/* sicm runtime: dense linear algebra over Eigen (runtime/src/linalg_eigen.cpp).
 *
 * The functions are C; their implementation is C++17 and uses Eigen, so a
 * program that calls them must be linked with the C++ runtime (-lstdc++, or
 * by linking with a C++ compiler). Programs that do not call them need
 * nothing more: the object that holds them is a separate member of
 * libsicmrt.a, which the linker leaves out when nothing refers to it. */
#ifndef SICM_LINALG_H
#define SICM_LINALG_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* sicm_linalg_eigenvalues computes the n eigenvalues of the real n x n
 * matrix a (row-major: a[i * n + j] is the entry in row i, column j) and
 * stores their real parts in re[0..n-1] and imaginary parts in im[0..n-1].
 * They are ordered by decreasing modulus, equal moduli by decreasing real
 * part and then decreasing imaginary part, so a complex conjugate pair comes
 * with its positive imaginary part first. A real eigenvalue has an imaginary
 * part of exactly 0. The method is Eigen's EigenSolver (reduction to real
 * Schur form by the shifted QR algorithm), accurate to about the machine
 * epsilon times the norm of a for well-conditioned eigenvalues; a defective
 * eigenvalue of multiplicity k is accurate only to about eps^(1/k).
 *
 * Returns SICM_SUCCESS; SICM_EINVAL when n is 0 or an entry is not finite;
 * SICM_ENOMEM when memory could not be allocated; SICM_ECONV when the QR
 * iteration did not converge. On failure re and im are left unspecified
 * and the reason is reported through the error hook (sicm/error.h). */
int sicm_linalg_eigenvalues(size_t n, const double *a, double *re, double *im);

#ifdef __cplusplus
}
#endif

#endif /* SICM_LINALG_H */
