/* sicm runtime: dense linear algebra: eigenvalues over Eigen
 * (runtime/src/linalg_eigen.cpp), and linear solves in C
 * (runtime/src/linalg_solve.c).
 *
 * The eigenvalue function is C; its implementation is C++17 and uses Eigen, so a
 * program that calls it must be linked with the C++ runtime (-lstdc++, or
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

/* sicm_linalg_solve_as_interpreted stores in x[0..n-1] the solution of
 * A x = b for the n x n matrix a (row-major), computed exactly as sicm's
 * interpreter divides a structure of flonums by a matrix of flonums
 * (compiler/algebra/structure.cpp): Gauss-Jordan elimination on [A | I]
 * choosing in each column the pivot of largest magnitude (the first of
 * equals), then x_i = sum over k of inverse(i, k) b_k, added left to right.
 * A program built by `sicm build` calls it where a division by a matrix of
 * run-time values was left for run time outside a kernel, so that the
 * executable prints what `sicm run` prints to the last bit. (Kernels
 * factor their matrices with LDL^T or LU instead, the same way in both.)
 * C, no Eigen. Returns SICM_SUCCESS, or SICM_ESINGULAR (x then NaN) when a
 * column has no nonzero pivot; nothing is reported through the error hook. */
int sicm_linalg_solve_as_interpreted(size_t n, const double *a, const double *b, double *x);

#ifdef __cplusplus
}
#endif

#endif /* SICM_LINALG_H */
