// Evaluation form: Horner factoring and shared reciprocals for the C emitter (see
// evaluation_form.hpp).
//
// A polynomial is read from its canonical expression into a list of terms
// (a number node and a product of variable powers), rewritten, and built back
// with the raw constructors of expr.hpp, which keep what is built (a sum of
// two terms stays a sum; nothing is reordered or folded). Coefficients are
// number nodes of the arena, so no collected Value lives in these vectors.
//
// Greedy Horner: choose the variable that occurs in the most terms (ties to
// the smaller id, so the result does not depend on hashing), factor its
// smallest power among those terms out of them, and recurse on the quotient
// and on the rest. This is the usual greedy scheme for multivariate Horner
// forms; it is not optimal (finding the cheapest form is NP-hard), but it
// never costs more multiplications than the expanded form, and it turns the
// products of sines and cosines that Lagrange's equations produce into short
// nested sums.
//
// Numeric factors are taken out only where every coefficient is exact, so the
// factored form is the same number as the original before rounding: a flonum
// coefficient (from a program whose constants are not decimals) keeps its
// terms as they are, and only variables are factored.
#include "cas/evaluation_form.hpp"

#include <gmp.h>

#include <algorithm>
#include <map>
#include <unordered_map>

namespace sicm {

namespace {

// How many variables the Horner search compares at each level, and how many
// splits it may try in all (over one whole kernel) before it falls back to
// the greedy choice: the search is exponential in the depth, and kernels
// with hundreds of terms exist.
constexpr size_t kHornerChoices = 3;
constexpr size_t kHornerBudget = 20000;

struct Power {
  ExprId var;
  int64_t exp;
};

struct Term {
  ExprId coef; // a number node; exact 1 when the monomial has none
  std::vector<Power> powers;
};

using Poly = std::vector<Term>;

// An mpq_t that frees itself.
struct Rational {
  mpq_t q;
  Rational() { mpq_init(q); }
  ~Rational() { mpq_clear(q); }
  Rational(const Rational &) = delete;
  Rational &operator=(const Rational &) = delete;
};

ExprId one() {
  return expr_integer(1);
}

bool exact(ExprId number) {
  return expr_kind(number) == ExprKind::Rational;
}

// A factor of a canonical monomial: a variable or (expt variable n), n >= 2.
bool read_factor(ExprId f, Power *p) {
  int64_t n;
  if (expr_is_apply(f, Op::Expt) && expr_get_int64(expr_arg(f, 1), &n) && n >= 2 &&
      expr_is_variable(expr_arg(f, 0))) {
    *p = {expr_arg(f, 0), n};
    return true;
  }
  if (!expr_is_variable(f)) return false;
  *p = {f, 1};
  return true;
}

bool read_term(ExprId id, Term *t) {
  t->coef = one();
  t->powers.clear();
  if (expr_is_number(id)) {
    t->coef = id;
    return true;
  }
  Power p;
  if (read_factor(id, &p)) {
    t->powers.push_back(p);
    return true;
  }
  if (!expr_is_apply(id, Op::Mul)) return false;
  std::vector<ExprId> args = expr_arg_vector(id);
  size_t i = 0;
  if (expr_is_number(args[0])) t->coef = args[i++];
  for (; i < args.size(); ++i) {
    if (!read_factor(args[i], &p)) return false;
    t->powers.push_back(p);
  }
  return true;
}

// The terms of a canonical polynomial; false for any other shape.
bool read_polynomial(ExprId id, Poly *out) {
  out->clear();
  std::vector<ExprId> terms =
      expr_is_apply(id, Op::Add) ? expr_arg_vector(id) : std::vector<ExprId>{id};
  for (ExprId term : terms) {
    Term t;
    if (!read_term(term, &t)) return false;
    out->push_back(std::move(t));
  }
  return true;
}

// ---- building ---------------------------------------------------------------------

// The arguments of (op a b), with the arguments of a or b spliced in where
// that operand is itself an application of op.
std::vector<ExprId> flattened(Op op, ExprId a, ExprId b) {
  std::vector<ExprId> out;
  for (ExprId x : {a, b}) {
    if (expr_is_apply(x, op)) {
      std::vector<ExprId> xs = expr_arg_vector(x);
      out.insert(out.end(), xs.begin(), xs.end());
    } else {
      out.push_back(x);
    }
  }
  return out;
}

// (* a b) with products flattened and a number kept first.
ExprId multiply(ExprId a, ExprId b) {
  if (expr_is_exact_one(a)) return b;
  if (expr_is_exact_one(b)) return a;
  std::vector<ExprId> factors = flattened(Op::Mul, a, b);
  auto numbers = std::stable_partition(factors.begin(), factors.end(),
                                       [](ExprId f) { return expr_is_number(f); });
  // Exact numeric factors fold into one: c * (-1 * x) is -c * x.
  if (numbers - factors.begin() >= 2 &&
      std::all_of(factors.begin(), numbers, [](ExprId f) { return exact(f); })) {
    Rational product;
    mpq_set_ui(product.q, 1, 1);
    for (auto f = factors.begin(); f != numbers; ++f)
      mpq_mul(product.q, product.q, expr_rat(*f));
    factors.erase(factors.begin() + 1, numbers);
    factors[0] = expr_rational(product.q);
    if (expr_is_exact_one(factors[0]) && factors.size() > 1) factors.erase(factors.begin());
  }
  if (factors.size() == 1) return factors[0];
  return expr_apply(Op::Mul, factors.data(), factors.size());
}

// (+ a b) with sums flattened.
ExprId add(ExprId a, ExprId b) {
  std::vector<ExprId> terms = flattened(Op::Add, a, b);
  return expr_apply(Op::Add, terms.data(), terms.size());
}

// The positive rational c with every coefficient an integer multiple of it
// and their gcd 1 after division by it (the content); false when a
// coefficient is inexact.
bool content(const Poly &terms, Rational *c) {
  mpz_t num, den;
  mpz_init_set_ui(num, 0);
  mpz_init_set_ui(den, 1);
  bool ok = true;
  for (const Term &t : terms) {
    if (!exact(t.coef)) {
      ok = false;
      break;
    }
    mpq_srcptr q = expr_rat(t.coef);
    mpz_gcd(num, num, mpq_numref(q));
    mpz_lcm(den, den, mpq_denref(q));
  }
  if (ok) {
    mpz_set(mpq_numref(c->q), num);
    mpz_set(mpq_denref(c->q), den);
    mpq_canonicalize(c->q);
  }
  mpz_clear(num);
  mpz_clear(den);
  return ok && mpq_sgn(c->q) != 0;
}

// The content of terms, if taking it out pays: multiplying by it costs one
// operation, so it must turn at least two coefficients of monomials into 1
// or -1 (12 x + 12 y is 12 (x + y); 3 x + 5 y stays, and so does a content
// like 1e-31 that only rescales).
bool useful_content(const Poly &terms, Rational *c) {
  if (!content(terms, c) || mpq_cmp_ui(c->q, 1, 1) == 0) return false;
  size_t unit = 0;
  for (const Term &t : terms) {
    if (t.powers.empty()) continue;
    mpq_srcptr q = expr_rat(t.coef);
    if (mpz_cmpabs(mpq_numref(q), mpq_numref(c->q)) == 0 &&
        mpz_cmp(mpq_denref(q), mpq_denref(c->q)) == 0)
      ++unit;
  }
  return unit >= 2;
}

// The terms with every coefficient divided by c (exact coefficients only).
Poly divide(const Poly &terms, const Rational &c) {
  Poly out = terms;
  Rational q;
  for (Term &t : out) {
    mpq_div(q.q, expr_rat(t.coef), c.q);
    t.coef = expr_rational(q.q);
  }
  return out;
}

// The polynomials of a quotient (/ N D). When every coefficient is exact,
// both are divided by the content of D, so that D is primitive: denominators
// equal up to a numeric factor become equal. Inexact coefficients are left
// as they are. False for any other shape.
bool read_quotient(ExprId id, Poly *num, Poly *den) {
  if (!expr_is_apply(id, Op::Div)) return false;
  if (!read_polynomial(expr_arg(id, 0), num) || !read_polynomial(expr_arg(id, 1), den))
    return false;
  Rational c, n;
  if (content(*den, &c) && content(*num, &n)) {
    *num = divide(*num, c);
    *den = divide(*den, c);
  }
  return true;
}

class Rewriter {
public:
  ExprId rewrite(ExprId id);
  ExprId horner(Poly terms);
  ExprId monomial(const Term &t);
  ExprId sum_of_monomials(const Poly &terms);

private:
  ExprId kernel(ExprId id);
  size_t cost(const Poly &terms);
  ExprId cheapest_variable(const Poly &terms);
  std::unordered_map<ExprId, ExprId> memo_;
  size_t budget_ = kHornerBudget; // candidate splits the cost search may still try
};

ExprId Rewriter::monomial(const Term &t) {
  ExprId m = t.coef;
  for (const Power &p : t.powers) {
    ExprId v = rewrite(p.var);
    ExprId f = p.exp == 1 ? v : expr_apply(Op::Expt, {v, expr_integer(p.exp)});
    m = multiply(m, f);
  }
  return m;
}

ExprId Rewriter::sum_of_monomials(const Poly &terms) {
  if (terms.empty()) return expr_integer(0);
  ExprId s = monomial(terms[0]);
  for (size_t i = 1; i < terms.size(); ++i)
    s = add(s, monomial(terms[i]));
  return s;
}

// The variables of terms that occur in at least two of them, most frequent
// first (ties to the smaller id), at most kHornerChoices of them.
std::vector<ExprId> candidates(const Poly &terms) {
  std::map<ExprId, size_t> count;
  for (const Term &t : terms)
    for (const Power &p : t.powers)
      ++count[p.var];
  std::vector<std::pair<size_t, ExprId>> ranked;
  for (auto [var, n] : count)
    if (n >= 2) ranked.push_back({n, var});
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto &a, const auto &b) { return a.first > b.first; });
  std::vector<ExprId> out;
  for (size_t i = 0; i < ranked.size() && i < kHornerChoices; ++i)
    out.push_back(ranked[i].second);
  return out;
}

// Factor var's smallest power among the terms that have it out of them:
// terms = var^k * with + without.
int64_t split(const Poly &terms, ExprId var, Poly *with, Poly *without) {
  int64_t k = INT64_MAX;
  for (const Term &t : terms)
    for (const Power &p : t.powers)
      if (p.var == var) k = std::min(k, p.exp);
  for (Term t : terms) {
    auto p = std::find_if(t.powers.begin(), t.powers.end(),
                          [&](const Power &x) { return x.var == var; });
    if (p == t.powers.end()) {
      without->push_back(std::move(t));
      continue;
    }
    if ((p->exp -= k) == 0) t.powers.erase(p);
    with->push_back(std::move(t));
  }
  return k;
}

// Multiplications and additions of a monomial written out: one per factor
// after the first, n - 1 for a power v^n, one for a coefficient other than 1.
size_t monomial_cost(const Term &t) {
  size_t cost = t.powers.empty() ? 0 : t.powers.size() - 1;
  for (const Power &p : t.powers)
    cost += static_cast<size_t>(p.exp - 1);
  if (!expr_is_exact_one(t.coef) && !t.powers.empty()) ++cost;
  return cost;
}

ExprId Rewriter::horner(Poly terms) {
  if (terms.size() <= 1) return terms.empty() ? expr_integer(0) : monomial(terms[0]);
  Rational c;
  if (useful_content(terms, &c)) return multiply(expr_rational(c.q), horner(divide(terms, c)));
  ExprId var = cheapest_variable(terms);
  if (var == kNoExpr) return sum_of_monomials(terms);
  Poly with, without;
  int64_t k = split(terms, var, &with, &without);
  ExprId v = rewrite(var);
  ExprId factor = k == 1 ? v : expr_apply(Op::Expt, {v, expr_integer(k)});
  ExprId head = multiply(horner(std::move(with)), factor);
  return without.empty() ? head : add(head, horner(std::move(without)));
}

// The operations of terms' Horner form when at each level the cheapest of
// the candidate variables is factored out (the greedy choice alone once the
// search budget is spent).
size_t Rewriter::cost(const Poly &terms) {
  if (terms.size() <= 1) return terms.empty() ? 0 : monomial_cost(terms[0]);
  Rational c;
  if (useful_content(terms, &c)) return 1 + cost(divide(terms, c));
  std::vector<ExprId> vars = candidates(terms);
  if (vars.empty()) {
    size_t sum = terms.size() - 1;
    for (const Term &t : terms)
      sum += monomial_cost(t);
    return sum;
  }
  if (budget_ == 0) vars.resize(1);
  size_t best = SIZE_MAX;
  for (ExprId var : vars) {
    if (budget_ > 0) --budget_;
    Poly with, without;
    int64_t k = split(terms, var, &with, &without);
    size_t c_var = cost(with) + 1 + static_cast<size_t>(k - 1);
    if (!without.empty()) c_var += 1 + cost(without);
    best = std::min(best, c_var);
  }
  return best;
}

ExprId Rewriter::cheapest_variable(const Poly &terms) {
  std::vector<ExprId> vars = candidates(terms);
  if (vars.size() <= 1) return vars.empty() ? kNoExpr : vars[0];
  ExprId best = vars[0];
  size_t best_cost = SIZE_MAX;
  for (ExprId var : vars) {
    Poly with, without;
    int64_t k = split(terms, var, &with, &without);
    size_t c = cost(with) + 1 + static_cast<size_t>(k - 1);
    if (!without.empty()) c += 1 + cost(without);
    if (c < best_cost) best = var, best_cost = c;
  }
  return best;
}

// A kernel ((sin u), (sqrt u), ...) with its arguments rewritten.
ExprId Rewriter::kernel(ExprId id) {
  if (expr_kind(id) != ExprKind::Apply) return id;
  std::vector<ExprId> args = expr_arg_vector(id);
  bool changed = false;
  for (ExprId &a : args) {
    ExprId r = rewrite(a);
    changed = changed || r != a;
    a = r;
  }
  return changed ? expr_apply(expr_node(id).op, args.data(), args.size()) : id;
}

ExprId Rewriter::rewrite(ExprId id) {
  auto hit = memo_.find(id);
  if (hit != memo_.end()) return hit->second;
  ExprId out = id;
  Poly terms;
  if (expr_is_number(id) || expr_kind(id) == ExprKind::Symbol) {
    out = id;
  } else if (expr_is_apply(id, Op::Div)) {
    Poly num, den;
    if (read_quotient(id, &num, &den))
      out = expr_apply(Op::Div, {horner(std::move(num)), horner(std::move(den))});
  } else if (expr_is_variable(id)) {
    out = kernel(id);
  } else if (read_polynomial(id, &terms)) {
    out = horner(std::move(terms));
  }
  memo_[id] = out;
  return out;
}

} // namespace

void to_evaluation_form(std::vector<ExprId> &outputs) {
  Rewriter r;
  // Outputs that are quotients, grouped by their denominator made primitive.
  std::map<ExprId, std::vector<size_t>> by_denominator;
  std::vector<Poly> numerators(outputs.size()), denominators(outputs.size());
  for (size_t j = 0; j < outputs.size(); ++j)
    if (read_quotient(outputs[j], &numerators[j], &denominators[j]))
      by_denominator[r.sum_of_monomials(denominators[j])].push_back(j);
  for (auto &[key, js] : by_denominator) {
    (void)key;
    ExprId den = r.horner(denominators[js[0]]);
    if (js.size() == 1) {
      outputs[js[0]] = expr_apply(Op::Div, {r.horner(numerators[js[0]]), den});
      continue;
    }
    ExprId reciprocal = expr_apply(Op::Expt, {den, expr_integer(-1)});
    for (size_t j : js)
      outputs[j] = multiply(r.horner(numerators[j]), reciprocal);
  }
  for (size_t j = 0; j < outputs.size(); ++j)
    if (denominators[j].empty()) outputs[j] = r.rewrite(outputs[j]);
}

} // namespace sicm
