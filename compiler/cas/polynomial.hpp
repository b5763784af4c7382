// Polynomials and rational functions with rational coefficients over a fixed, ordered
// list of variables (symbols and kernels), built on FLINT's fmpq_mpoly.
//
// The simplifier turns an expression into a RatFun over the variables it
// contains, lets FLINT do the arithmetic and the gcds, and turns the result
// back into a canonical expression (cas/expr.hpp, C4-C6). The ring's
// variables are sorted by expr_compare and FLINT's variable i is the ring's
// i-th variable, so FLINT's degree-lexicographic term order (variable 0 most
// significant) is the order in which terms are printed (but for a constant
// term, which scmutils prints first).
//
// Everything here is malloc'd FLINT memory, released by destructors: no Values.
#pragma once

#include <flint/fmpq_mpoly.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "cas/expr.hpp"

namespace sicm {

class PolyRing {
public:
  explicit PolyRing(std::vector<ExprId> sorted_vars);
  ~PolyRing();
  PolyRing(const PolyRing &) = delete;
  PolyRing &operator=(const PolyRing &) = delete;

  size_t nvars() const { return vars_.size(); }
  ExprId var(size_t i) const { return vars_[i]; }
  // Index of a variable, or -1.
  int index_of(ExprId v) const;
  const fmpq_mpoly_ctx_struct *ctx() const { return ctx_; }

private:
  std::vector<ExprId> vars_;
  std::unordered_map<ExprId, int> index_;
  fmpq_mpoly_ctx_t ctx_;
};

// A polynomial of a ring (owning, movable).
class Poly {
public:
  explicit Poly(const PolyRing &r);
  Poly(const Poly &o);
  Poly(Poly &&o) noexcept;
  Poly &operator=(const Poly &o);
  Poly &operator=(Poly &&o) noexcept;
  ~Poly();

  fmpq_mpoly_struct *get() { return p_; }
  const fmpq_mpoly_struct *get() const { return p_; }
  const PolyRing &ring() const { return *ring_; }
  const fmpq_mpoly_ctx_struct *ctx() const { return ring_->ctx(); }
  bool is_zero() const;
  bool is_one() const;
  long length() const;

private:
  const PolyRing *ring_;
  fmpq_mpoly_struct *p_;
};

// num/den with gcd(num, den) = 1 and den monic (leading coefficient 1), so a
// constant denominator is 1. Every operation keeps this form.
struct RatFun {
  Poly num, den;
  explicit RatFun(const PolyRing &r); // zero
  RatFun(Poly n, Poly d);             // normalizes; d = 0 is MIT's division-by-zero error
  bool is_zero() const { return num.is_zero(); }
  bool is_polynomial() const { return den.is_one(); }
};

RatFun rf_constant(const PolyRing &r, mpq_srcptr q);
RatFun rf_variable(const PolyRing &r, int index);
RatFun rf_add(const RatFun &a, const RatFun &b);
RatFun rf_neg(const RatFun &a);
RatFun rf_mul(const RatFun &a, const RatFun &b);
RatFun rf_inv(const RatFun &a); // of zero: MIT's "Division by zero signalled by /."
RatFun rf_div(const RatFun &a, const RatFun &b);
RatFun rf_pow(const RatFun &a, int64_t n); // negative powers of zero as rf_inv

// Replace v^2 by `square` (a rational function free of v) in p until v occurs
// at most to the first power: p = sum_k p_k v^k becomes
// sum_k p_k square^(k div 2) v^(k mod 2). Used for sqrt(u)^2 = u and
// cos^2 = 1 - sin^2.
RatFun rf_reduce_square(const Poly &p, int v, const RatFun &square);
// The same for a rational function, numerator and denominator separately.
RatFun rf_reduce_square(const RatFun &f, int v, const RatFun &square);
// p = constant * root^2 * rest, with root as large as squarefree
// factorization finds: rest is the product of the factors of p of odd
// multiplicity; root and rest have no constant factor of their own.
void poly_split_square(const Poly &p, fmpq_t constant, Poly *root, Poly *rest);
// p = constant * root^2 * monomial * rest: poly_split_square's split, then
// rest's monomial factor (the gcd of its terms, coefficient 1, each variable
// to the first power) taken out of it and rest made primitive with integer
// coefficients and a positive leading coefficient, its content and sign going
// into constant. So rest is 1 or a polynomial of two terms or more.
void poly_split_root_factors(const Poly &p, fmpq_t constant, Poly *root, Poly *monomial,
                             Poly *rest);

// Highest power of variable v in p (0 if absent).
long poly_degree_in(const Poly &p, int v);

// The canonical expression of f (expr.hpp, C4-C6). When `inexact`, every
// coefficient becomes a flonum except the implicit 1 and the -1 of a monomial
// with variables, as a flonum in the input makes the whole result inexact.
ExprId rf_to_expr(const RatFun &f, bool inexact);

} // namespace sicm
