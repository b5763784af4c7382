// Rational functions over FLINT's fmpq_mpoly, and their canonical expressions.
//
// Arithmetic follows Knuth (and scmutils' rcf.scm): sums and products take
// gcds of the operands' parts before multiplying, so intermediate results
// stay reduced and small; denominators are kept monic so equal denominators
// are recognized by equality and a constant denominator is always 1 (the
// common case: most expressions of mechanics are polynomials in their
// kernels, and then every operation is a plain FLINT polynomial operation).
#include "cas/polynomial.hpp"

#include <flint/fmpq.h>
#include <flint/fmpq_mpoly_factor.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <new>
#include <string>

#include "base/error.hpp"
#include "base/limits.hpp"
#include "base/number.hpp"

namespace sicm {

// ---- rings and polynomials ---------------------------------------------------

PolyRing::PolyRing(std::vector<ExprId> sorted_vars) : vars_(std::move(sorted_vars)) {
  for (size_t i = 0; i < vars_.size(); i++)
    index_.emplace(vars_[i], static_cast<int>(i));
  // FLINT wants at least one variable; a spare one is never used.
  fmpq_mpoly_ctx_init(ctx_, static_cast<slong>(std::max<size_t>(vars_.size(), 1)), ORD_DEGLEX);
}

PolyRing::~PolyRing() {
  fmpq_mpoly_ctx_clear(ctx_);
}

int PolyRing::index_of(ExprId v) const {
  auto it = index_.find(v);
  return it == index_.end() ? -1 : it->second;
}

Poly::Poly(const PolyRing &r) : ring_(&r), p_(new fmpq_mpoly_struct) {
  fmpq_mpoly_init(p_, ctx());
}

Poly::Poly(const Poly &o) : Poly(*o.ring_) {
  fmpq_mpoly_set(p_, o.p_, ctx());
}

Poly::Poly(Poly &&o) noexcept : ring_(o.ring_), p_(o.p_) {
  o.p_ = nullptr;
}

Poly &Poly::operator=(const Poly &o) {
  if (this != &o) fmpq_mpoly_set(p_, o.p_, ctx());
  return *this;
}

Poly &Poly::operator=(Poly &&o) noexcept {
  std::swap(p_, o.p_);
  std::swap(ring_, o.ring_);
  return *this;
}

Poly::~Poly() {
  if (p_) {
    fmpq_mpoly_clear(p_, ctx());
    delete p_;
  }
}

bool Poly::is_zero() const {
  return fmpq_mpoly_is_zero(p_, ctx());
}

bool Poly::is_one() const {
  return fmpq_mpoly_is_one(p_, ctx());
}

long Poly::length() const {
  return fmpq_mpoly_length(p_, ctx());
}

namespace {

// A denominator can become zero only through the identities the simplifier
// applies ((/ 1 (- (square (sqrt x)) x))): the user divided by zero.
[[noreturn]] void division_by_zero() {
  num_div(Value::fixnum(1), Value::fixnum(0)); // raises MIT's error
  SICM_ASSERT(false);
  std::abort();
}

Poly poly_one(const PolyRing &r) {
  Poly p(r);
  fmpq_mpoly_one(p.get(), r.ctx());
  return p;
}

Poly poly_add(const Poly &a, const Poly &b) {
  Poly c(a.ring());
  fmpq_mpoly_add(c.get(), a.get(), b.get(), a.ctx());
  return c;
}

namespace {

// Upper bounds on the number of terms of an expansion, so that one that
// would not fit the expression size limit is refused before FLINT spends
// minutes (or gigabytes) on it: a product has at most the product of its
// factors' numbers of terms, a power p^n of a t-term p at most the
// multinomial count C(n + t - 1, t - 1), and either at most the number of
// monomials within its degree in each variable. The bounds are in floating
// point, as they can pass any integer type.

// The monomials within degree n * deg_v(a) + deg_v(b) in each variable v
// (b may be absent).
double dense_terms(const Poly &a, double n, const Poly *b) {
  const fmpq_mpoly_ctx_struct *ctx = a.ctx();
  slong vars = fmpq_mpoly_ctx_nvars(ctx);
  std::vector<slong> da(static_cast<size_t>(vars)), db(static_cast<size_t>(vars), 0);
  // Degrees that do not fit a word: no bound from this side.
  if (!fmpq_mpoly_degrees_fit_si(a.get(), ctx)) return HUGE_VAL;
  fmpq_mpoly_degrees_si(da.data(), a.get(), ctx);
  if (b) {
    if (!fmpq_mpoly_degrees_fit_si(b->get(), ctx)) return HUGE_VAL;
    fmpq_mpoly_degrees_si(db.data(), b->get(), ctx);
  }
  double terms = 1;
  for (size_t v = 0; v < da.size(); ++v)
    terms *= n * static_cast<double>(std::max<slong>(da[v], 0)) +
             static_cast<double>(std::max<slong>(db[v], 0)) + 1;
  return terms;
}

// Products whose bound is below this are not examined further: the cost
// of the check stays out of the common case.
constexpr double kSmallExpansion = 1e4;

void check_product_size(const Poly &a, const Poly &b) {
  double terms = static_cast<double>(a.length()) * static_cast<double>(b.length());
  if (terms < kSmallExpansion) return;
  check_expression_growth(std::min(terms, dense_terms(a, 1, &b)), "expanding a product");
}

// A product's degree in each variable is the sum of its factors'. Past
// kMaxExpandedPower the canonical form has no power for it (C3 in
// cas/expr.hpp): y x^60000 x^60000 gave (* y (expt x 120000)), which
// failed the simplifier's own check (an internal error), so such a product
// is an error, as a power of that degree is (check_power_degree).
void check_product_degree(const Poly &a, const Poly &b) {
  const fmpq_mpoly_ctx_struct *ctx = a.ctx();
  if (!fmpq_mpoly_total_degree_fits_si(a.get(), ctx) ||
      !fmpq_mpoly_total_degree_fits_si(b.get(), ctx) ||
      fmpq_mpoly_total_degree_si(a.get(), ctx) + fmpq_mpoly_total_degree_si(b.get(), ctx) >
          kMaxExpandedPower) {
    slong vars = fmpq_mpoly_ctx_nvars(ctx);
    std::vector<slong> da(static_cast<size_t>(vars)), db(static_cast<size_t>(vars));
    bool fit = fmpq_mpoly_degrees_fit_si(a.get(), ctx) && fmpq_mpoly_degrees_fit_si(b.get(), ctx);
    if (fit) {
      fmpq_mpoly_degrees_si(da.data(), a.get(), ctx);
      fmpq_mpoly_degrees_si(db.data(), b.get(), ctx);
    }
    for (size_t v = 0; fit && v < da.size(); ++v)
      fit = std::max<slong>(da[v], 0) + std::max<slong>(db[v], 0) <= kMaxExpandedPower;
    if (!fit)
      runtime_error(current_call_loc(), "simplify: a product would have degree above " +
                                            std::to_string(kMaxExpandedPower) +
                                            " in one of its variables");
  }
}

void check_power_size(const Poly &p, int64_t n) {
  double t = static_cast<double>(p.length());
  if (t <= 1) return;
  // C(n + t - 1, k) with k = min(n, t - 1), stopping once it is huge.
  double k = std::min(static_cast<double>(n), t - 1), terms = 1;
  for (double i = 1; i <= k && terms < 1e300; ++i)
    terms = terms * (static_cast<double>(n) + t - i) / i;
  if (terms < kSmallExpansion) return;
  check_expression_growth(std::min(terms, dense_terms(p, static_cast<double>(n), nullptr)),
                          "expanding a power of a sum");
}

// GMP aborts the process when a number outgrows its size field, and a
// coefficient of more than this many bits (32 MiB) is a mistake, not a
// computation: the bound expt has for exact numbers (base/number.cpp).
constexpr double kMaxCoefficientBits = 268435456.0;

// The coefficients of p^n have at most n times the bits of p's content and
// of its largest integral coefficient, and n log2(t) more from the
// multinomial counts. A power of an exact constant of 53 bits nested
// fourteen deep, ((c^-4)^-4)..., is 14 billion bits.
void check_power_bits(const Poly &p, int64_t n) {
  const fmpq_mpoly_struct *a = p.get();
  double content = static_cast<double>(
      std::max(fmpz_bits(fmpq_numref(a->content)), fmpz_bits(fmpq_denref(a->content))));
  double integral = static_cast<double>(std::abs(fmpz_mpoly_max_bits(a->zpoly)));
  double bits =
      static_cast<double>(n) * (content + integral + std::log2(static_cast<double>(p.length())));
  if (bits > kMaxCoefficientBits)
    runtime_error(current_call_loc(),
                  "simplify: expanding a power would give coefficients of more than 268435456 "
                  "bits; use inexact numbers (exact->inexact) for a flonum result");
}

} // namespace

Poly poly_mul(const Poly &a, const Poly &b) {
  if (a.is_one()) return b;
  if (b.is_one()) return a;
  check_product_size(a, b);
  check_product_degree(a, b);
  Poly c(a.ring());
  fmpq_mpoly_mul(c.get(), a.get(), b.get(), a.ctx());
  return c;
}

Poly poly_gcd(const Poly &a, const Poly &b) {
  Poly g(a.ring());
  if (a.is_one() || b.is_one()) {
    fmpq_mpoly_one(g.get(), a.ctx());
    return g;
  }
  // FLINT's gcd only fails on exponent overflow; 1 is then a safe (if
  // unreduced) answer.
  if (!fmpq_mpoly_gcd(g.get(), a.get(), b.get(), a.ctx())) fmpq_mpoly_one(g.get(), a.ctx());
  return g;
}

// a / b, which must be exact.
Poly poly_divexact(const Poly &a, const Poly &b) {
  if (b.is_one()) return a;
  Poly q(a.ring());
  int ok = fmpq_mpoly_divides(q.get(), a.get(), b.get(), a.ctx());
  SICM_ASSERT(ok);
  return q;
}

// Make d monic, scaling n alike; a constant d becomes 1.
void normalize_den(Poly &n, Poly &d) {
  if (d.is_one()) return;
  fmpq_t lc;
  fmpq_init(lc);
  fmpq_mpoly_get_term_coeff_fmpq(lc, d.get(), 0, d.ctx());
  if (!fmpq_is_one(lc)) {
    fmpq_mpoly_scalar_div_fmpq(n.get(), n.get(), lc, n.ctx());
    fmpq_mpoly_scalar_div_fmpq(d.get(), d.get(), lc, d.ctx());
  }
  fmpq_clear(lc);
}

RatFun make_reduced(Poly n, Poly d) {
  RatFun f(n.ring());
  f.num = std::move(n);
  f.den = std::move(d);
  normalize_den(f.num, f.den);
  return f;
}

} // namespace

// ---- rational functions --------------------------------------------------------

RatFun::RatFun(const PolyRing &r) : num(r), den(poly_one(r)) {}

RatFun::RatFun(Poly n, Poly d) : num(std::move(n)), den(std::move(d)) {
  if (den.is_zero()) division_by_zero();
  if (num.is_zero()) {
    den = poly_one(num.ring());
    return;
  }
  Poly g = poly_gcd(num, den);
  if (!g.is_one()) {
    num = poly_divexact(num, g);
    den = poly_divexact(den, g);
  }
  normalize_den(num, den);
}

RatFun rf_constant(const PolyRing &r, mpq_srcptr q) {
  RatFun f(r);
  fmpq_t c;
  fmpq_init(c);
  fmpq_set_mpq(c, q);
  fmpq_mpoly_set_fmpq(f.num.get(), c, r.ctx());
  fmpq_clear(c);
  return f;
}

RatFun rf_variable(const PolyRing &r, int index) {
  RatFun f(r);
  fmpq_mpoly_gen(f.num.get(), index, r.ctx());
  return f;
}

RatFun rf_neg(const RatFun &a) {
  RatFun f = a;
  fmpq_mpoly_neg(f.num.get(), f.num.get(), f.num.ctx());
  return f;
}

RatFun rf_add(const RatFun &a, const RatFun &b) {
  if (a.is_zero()) return b;
  if (b.is_zero()) return a;
  if (a.is_polynomial() && b.is_polynomial()) {
    RatFun f(a.num.ring());
    f.num = poly_add(a.num, b.num);
    return f;
  }
  const PolyRing &r = a.num.ring();
  if (fmpq_mpoly_equal(a.den.get(), b.den.get(), r.ctx())) {
    Poly n = poly_add(a.num, b.num);
    if (n.is_zero()) return RatFun(r);
    return RatFun(std::move(n), Poly(a.den));
  }
  Poly d1 = poly_gcd(a.den, b.den);
  if (d1.is_one())
    return make_reduced(poly_add(poly_mul(a.num, b.den), poly_mul(a.den, b.num)),
                        poly_mul(a.den, b.den));
  Poly a_over = poly_divexact(a.den, d1);
  Poly t = poly_add(poly_mul(a.num, poly_divexact(b.den, d1)), poly_mul(a_over, b.num));
  if (t.is_zero()) return RatFun(r);
  Poly d2 = poly_gcd(t, d1);
  return make_reduced(poly_divexact(t, d2), poly_mul(a_over, poly_divexact(b.den, d2)));
}

RatFun rf_mul(const RatFun &a, const RatFun &b) {
  const PolyRing &r = a.num.ring();
  if (a.is_zero() || b.is_zero()) return RatFun(r);
  if (a.is_polynomial() && b.is_polynomial()) {
    RatFun f(r);
    f.num = poly_mul(a.num, b.num);
    return f;
  }
  Poly g1 = poly_gcd(a.num, b.den), g2 = poly_gcd(b.num, a.den);
  return make_reduced(poly_mul(poly_divexact(a.num, g1), poly_divexact(b.num, g2)),
                      poly_mul(poly_divexact(a.den, g2), poly_divexact(b.den, g1)));
}

RatFun rf_inv(const RatFun &a) {
  if (a.is_zero()) division_by_zero();
  return make_reduced(Poly(a.den), Poly(a.num));
}

RatFun rf_div(const RatFun &a, const RatFun &b) {
  return rf_mul(a, rf_inv(b));
}

namespace {

// Total degree of p, or LONG_MAX when it does not fit a word.
long total_degree(const Poly &p) {
  if (!fmpq_mpoly_total_degree_fits_si(p.get(), p.ctx())) return LONG_MAX;
  return static_cast<long>(fmpq_mpoly_total_degree_si(p.get(), p.ctx()));
}

// Nested powers multiply degrees: (expt (expt x 12) 12) eighteen deep has
// degree 12^18, each power being below kMaxExpandedPower. Expanded, such a
// power needs exponents wider than a word (FLINT then aborts the process)
// or gigabytes of terms, so a power whose degree would pass the limit that
// a single exponent has is an error instead.
void check_power_degree(const RatFun &a, int64_t n) {
  long degree = std::max(total_degree(a.num), total_degree(a.den));
  if (degree <= 0) return;
  if (degree > kMaxExpandedPower || n > kMaxExpandedPower / degree)
    runtime_error(current_call_loc(),
                  "simplify: expanding a power would give a polynomial of degree above " +
                      std::to_string(kMaxExpandedPower) + " (nested powers multiply degrees)");
}

} // namespace

RatFun rf_pow(const RatFun &a, int64_t n) {
  const PolyRing &r = a.num.ring();
  if (n == 0) {
    RatFun one(r);
    fmpq_mpoly_one(one.num.get(), r.ctx());
    return one;
  }
  if (n < 0) return rf_pow(rf_inv(a), -n);
  if (n == 1) return a;
  check_power_degree(a, n);
  check_power_size(a.num, n);
  check_power_size(a.den, n);
  check_power_bits(a.num, n);
  check_power_bits(a.den, n);
  RatFun f(r);
  // A power of a coprime pair is coprime, and a power of a monic polynomial is monic.
  SICM_ASSERT(fmpq_mpoly_pow_ui(f.num.get(), a.num.get(), static_cast<ulong>(n), r.ctx()));
  SICM_ASSERT(fmpq_mpoly_pow_ui(f.den.get(), a.den.get(), static_cast<ulong>(n), r.ctx()));
  return f;
}

void poly_split_square(const Poly &p, fmpq_t constant, Poly *root, Poly *rest) {
  const fmpq_mpoly_ctx_struct *ctx = p.ctx();
  fmpq_mpoly_one(root->get(), ctx);
  fmpq_mpoly_one(rest->get(), ctx);
  fmpq_mpoly_factor_t f;
  fmpq_mpoly_factor_init(f, ctx);
  if (p.is_zero() || !fmpq_mpoly_factor_squarefree(f, p.get(), ctx)) {
    // Nothing to split (FLINT fails only on exponent overflow).
    fmpq_mpoly_factor_clear(f, ctx);
    fmpq_one(constant);
    fmpq_mpoly_set(rest->get(), p.get(), ctx);
    return;
  }
  fmpq_set(constant, f->constant);
  Poly power(p.ring());
  for (slong i = 0; i < f->num; i++) {
    ulong e = fmpz_get_ui(f->exp + i);
    if (e / 2) {
      fmpq_mpoly_pow_ui(power.get(), f->poly + i, e / 2, ctx);
      fmpq_mpoly_mul(root->get(), root->get(), power.get(), ctx);
    }
    if (e % 2) fmpq_mpoly_mul(rest->get(), rest->get(), f->poly + i, ctx);
  }
  fmpq_mpoly_factor_clear(f, ctx);
}

void poly_split_root_factors(const Poly &p, fmpq_t constant, Poly *root, Poly *monomial,
                             Poly *rest) {
  const fmpq_mpoly_ctx_struct *ctx = p.ctx();
  poly_split_square(p, constant, root, rest);
  fmpq_mpoly_one(monomial->get(), ctx);
  if (rest->is_zero() || rest->is_one()) return;
  fmpq_mpoly_term_content(monomial->get(), rest->get(), ctx);
  fmpq_mpoly_divides(rest->get(), rest->get(), monomial->get(), ctx);
  fmpq_t c;
  fmpq_init(c);
  if (fmpq_mpoly_is_fmpq(rest->get(), ctx)) {
    fmpq_mpoly_get_fmpq(c, rest->get(), ctx);
    fmpq_mpoly_one(rest->get(), ctx);
  } else {
    fmpq_mpoly_content(c, rest->get(), ctx); // positive
    fmpq_t lead;
    fmpq_init(lead);
    fmpq_mpoly_get_term_coeff_fmpq(lead, rest->get(), 0, ctx);
    if (fmpq_sgn(lead) < 0) fmpq_neg(c, c);
    fmpq_clear(lead);
    fmpq_mpoly_scalar_div_fmpq(rest->get(), rest->get(), c, ctx);
  }
  fmpq_mul(constant, constant, c);
  fmpq_clear(c);
}

long poly_degree_in(const Poly &p, int v) {
  if (p.is_zero()) return 0;
  return fmpq_mpoly_degree_si(p.get(), v, p.ctx());
}

RatFun rf_reduce_square(const Poly &p, int v, const RatFun &square) {
  const PolyRing &r = p.ring();
  RatFun result(r);
  if (poly_degree_in(p, v) < 2) {
    result.num = p;
    return result;
  }
  fmpq_mpoly_univar_t u;
  fmpq_mpoly_univar_init(u, r.ctx());
  fmpq_mpoly_to_univar(u, p.get(), v, r.ctx());
  // Powers of `square` by need: p's degree in v is small in practice.
  std::vector<RatFun> powers;
  powers.push_back(rf_pow(square, 0));
  RatFun var = rf_variable(r, v);
  for (slong i = 0; i < u->length; i++) {
    slong k = fmpq_mpoly_univar_get_term_exp_si(u, i, r.ctx());
    RatFun coeff(r);
    fmpq_mpoly_univar_get_term_coeff(coeff.num.get(), u, i, r.ctx());
    while (static_cast<slong>(powers.size()) <= k / 2)
      powers.push_back(rf_mul(powers.back(), square));
    RatFun term = rf_mul(coeff, powers[k / 2]);
    if (k % 2) term = rf_mul(term, var);
    result = rf_add(result, term);
  }
  fmpq_mpoly_univar_clear(u, r.ctx());
  return result;
}

RatFun rf_reduce_square(const RatFun &f, int v, const RatFun &square) {
  if (poly_degree_in(f.num, v) < 2 && poly_degree_in(f.den, v) < 2) return f;
  RatFun n = rf_reduce_square(f.num, v, square);
  if (f.den.is_one()) return n;
  return rf_div(n, rf_reduce_square(f.den, v, square));
}

// ---- back to expressions ----------------------------------------------------------

namespace {

// A coefficient as a GMP rational, for the two conversions written with GMP
// (to a double, to the arena), freed at the end of the full expression.
struct GmpRational {
  mpq_t q;
  explicit GmpRational(const fmpq_t c) {
    mpq_init(q);
    fmpq_get_mpq(q, c);
  }
  ~GmpRational() { mpq_clear(q); }
  GmpRational(const GmpRational &) = delete;
  GmpRational &operator=(const GmpRational &) = delete;
};

// The flonum a coefficient is written as (GMP's conversion, as before).
double coefficient_double(const fmpq_t c) {
  return mpq_get_d(GmpRational(c).q);
}

ExprId coefficient_expr(const fmpq_t c, bool inexact) {
  if (inexact) return expr_flonum(coefficient_double(c));
  return expr_canonical_rational(GmpRational(c).q); // FLINT's rationals are canonical
}

// The canonical expression of p, its coefficients first multiplied by `scale`.
ExprId poly_to_expr(const Poly &p, const fmpq_t scale, bool inexact) {
  const PolyRing &r = p.ring();
  slong len = p.length();
  if (len == 0) return expr_integer(0);
  std::vector<ulong> exps(std::max<size_t>(r.nvars(), 1));
  std::vector<ExprId> terms, factors;
  fmpq_t c;
  fmpq_init(c);
  for (slong i = 0; i < len; i++) {
    fmpq_mpoly_get_term_coeff_fmpq(c, p.get(), i, r.ctx());
    fmpq_mul(c, c, scale);
    fmpq_mpoly_get_term_exp_ui(exps.data(), p.get(), i, r.ctx());
    factors.clear();
    for (size_t v = 0; v < r.nvars(); v++) {
      if (exps[v] == 0) continue;
      ExprId var = r.var(v);
      factors.push_back(
          exps[v] == 1 ? var
                       : expr_apply(Op::Expt, {var, expr_integer(static_cast<int64_t>(exps[v]))}));
    }
    if (factors.empty()) {
      terms.push_back(coefficient_expr(c, inexact));
      continue;
    }
    // A coefficient is 1 or -1 as written: an inexact one that rounds to
    // 1. is left out as the exact 1 is (and -1. is the exact -1), so that
    // the result is a fixed point (fuzz simplify-5: five times .2 is
    // 1.0000000000000000555 exactly, written 1., which a second pass dropped).
    ExprId coef = coefficient_expr(c, inexact);
    bool one = fmpq_is_one(c) || (inexact && expr_node(coef).d == 1.0);
    bool minus_one = (fmpz_equal_si(fmpq_numref(c), -1) && fmpz_is_one(fmpq_denref(c))) ||
                     (inexact && expr_node(coef).d == -1.0);
    if (minus_one) coef = expr_integer(-1);
    if (!one) factors.insert(factors.begin(), coef);
    terms.push_back(factors.size() == 1 ? factors[0]
                                        : expr_apply(Op::Mul, factors.data(), factors.size()));
  }
  fmpq_clear(c);
  if (terms.size() == 1) return terms[0];
  // scmutils' sum constructor puts a number first: (+ -1 (expt x 2)).
  if (expr_is_constant(terms.back())) std::rotate(terms.begin(), terms.end() - 1, terms.end());
  return expr_apply(Op::Add, terms.data(), terms.size());
}

// Does every coefficient of p scaled by `scale` round to a finite, nonzero
// double?
bool scaled_coefficients_fit(const Poly &p, const fmpq_t scale) {
  fmpq_t c;
  fmpq_init(c);
  bool fit = true;
  for (slong i = 0; fit && i < p.length(); i++) {
    fmpq_mpoly_get_term_coeff_fmpq(c, p.get(), i, p.ring().ctx());
    fmpq_mul(c, c, scale);
    double d = coefficient_double(c);
    fit = d != 0 && std::isfinite(d);
  }
  fmpq_clear(c);
  return fit;
}

// Sets scale to 1 / (den's leading coefficient) if, so scaled, every
// coefficient of den and num is a finite nonzero double; otherwise (a
// coefficient under- or overflows) returns false and leaves scale alone.
bool monic_scale(const Poly &den, const Poly &num, fmpq_t scale) {
  fmpq_t lead;
  fmpq_init(lead);
  fmpq_mpoly_get_term_coeff_fmpq(lead, den.get(), 0, den.ring().ctx());
  fmpq_inv(lead, lead);
  bool fit = scaled_coefficients_fit(den, lead) && scaled_coefficients_fit(num, lead);
  if (fit) fmpq_set(scale, lead);
  fmpq_clear(lead);
  return fit;
}

} // namespace

ExprId rf_to_expr(const RatFun &f, bool inexact) {
  fmpq_t scale;
  fmpq_init(scale);
  fmpq_one(scale);
  if (f.is_polynomial()) {
    ExprId e = poly_to_expr(f.num, scale, inexact);
    fmpq_clear(scale);
    return e;
  }
  ExprId num, den;
  if (f.den.length() == 1) {
    // A monic monomial denominator: the numbers are already divided through
    // into the numerator, as scmutils' divide-numbers-through leaves them.
    num = poly_to_expr(f.num, scale, inexact);
    den = poly_to_expr(f.den, scale, false);
  } else if (inexact && monic_scale(f.den, f.num, scale)) {
    // Flonum coefficients: the denominator is made monic (its leading
    // term's coefficient 1, which rounding leaves alone), as scmutils
    // writes (/ 1 (+ x .6)). Made integers, as exact ones are below, they
    // were scaled by the exact denominators of the flonums (2^52 and its
    // powers), and by different ones when simplified again (fuzz simplify-1).
    num = poly_to_expr(f.num, scale, inexact);
    den = poly_to_expr(f.den, scale, inexact);
  } else {
    // FLINT keeps a polynomial as content * primitive integer polynomial with
    // a positive leading coefficient. With r = content(num)/content(den) = p/q
    // in lowest terms, num/den = (p * prim(num)) / (q * prim(den)): integer
    // coefficients, no common integer factor, den's first term positive.
    fmpq_t r, p, q, sn, sd;
    fmpq_init(r);
    fmpq_init(p);
    fmpq_init(q);
    fmpq_init(sn);
    fmpq_init(sd);
    fmpq_div(r, f.num.get()->content, f.den.get()->content);
    fmpz_set(fmpq_numref(p), fmpq_numref(r));
    fmpz_set(fmpq_numref(q), fmpq_denref(r));
    fmpq_div(sn, p, f.num.get()->content);
    fmpq_div(sd, q, f.den.get()->content);
    num = poly_to_expr(f.num, sn, inexact);
    den = poly_to_expr(f.den, sd, inexact);
    fmpq_clear(r);
    fmpq_clear(p);
    fmpq_clear(q);
    fmpq_clear(sn);
    fmpq_clear(sd);
  }
  fmpq_clear(scale);
  return expr_apply(Op::Div, {num, den});
}

} // namespace sicm
