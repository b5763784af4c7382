// The simplifier: rational canonical form over kernels, with scmutils' trig, sqrt and exp/log
// rules.
//
// Approach. An expression is a rational function of "variables": symbols and
// kernels, the maximal subexpressions that + - * / and integer powers cannot
// see into ((sin x), (f t), (sqrt u), (exp u), (expt u 1/3), ...). To simplify
// one:
//   1. walk its rational skeleton and simplify every kernel first: simplify
//      the kernel's arguments (recursively, memoized), then apply the kernel's
//      rules (below); a rule may turn a kernel into a rational expression of
//      other kernels ((exp (log x)) is x, (expt (sqrt u) 3) is u (sqrt u)),
//      whose variables then join the set;
//   2. sort the variables (expr_compare: symbols by name, then kernels) and
//      build the rational function in FLINT over them, keeping numerator and
//      denominator coprime at every step (polynomial.cpp);
//   3. rewrite with the algebraic relations between variables that a
//      polynomial ring does not know: sqrt(u)^2 = u (and u / sqrt(u) =
//      sqrt(u)), and sin(x)^2 + cos(x)^2 = 1, by a small search for the form
//      with the fewest terms (Pass::reduce_trig explains it);
//   4. read the canonical expression back (polynomial.cpp, rf_to_expr): terms
//      in graded lexicographic order, numbers divided through a monomial
//      denominator, integer coefficients over a polynomial one.
//
// Kernel rules (a subset of scmutils' rules.scm, chosen for what mechanics
// produces): numbers fold only when the result is exact or an argument is
// inexact, so (sin 0) is 0 and (sqrt 4) is 2 but (sqrt 2) stays symbolic
// (and squares to 2); sin, cos and tan move a negative sign out of their
// argument ((cos (- x)) = (cos x), (sin (- x)) = (- (sin x))); inverse pairs
// cancel ((exp (log x)), (log (exp x)), (sin (asin x)), (asin (sin x)), ...:
// scmutils' simplifier "lives dangerously" by default and so does this one);
// exp of a sum is a product of exps, exp of a negative quantity the
// reciprocal of exp of its negation, exp of n x a power of (exp x)
// (scmutils' exp-expand, so equal values get one form and products of
// exponentials cancel); (log (sqrt x)) is
// (* 1/2 (log x)); (expt u p/2) is a power of (sqrt u); (sqrt (* f^2 g)) is
// (* f (sqrt g)); the root of a product or quotient is the product or
// quotient of the roots of its factors, as scmutils' sqrt-expand leaves it
// (split_root), so products and quotients of roots combine; atan's two
// arguments lose their common factor.
//
// Flonums. Coefficients are computed exactly (a flonum is the rational it
// denotes) and, when the rational skeleton of the input contained a flonum,
// every coefficient of the result is made a flonum again (inexactness is
// contagious, as in Scheme; the implicit 1 and the -1 of (* -1 x) stay exact).
// Flonums inside kernel arguments affect only those arguments.
//
// Limits. No factorization: a numerator or denominator is an expanded
// polynomial, as in scmutils. Like scmutils (sqrt-expt-simplify, its
// default) square factors leave square roots on the assumption that they are
// non-negative: (sqrt (expt r 2)) is r; and (sqrt-factor-simplify) that
// the factors of a radicand are: (sqrt (* x y)) is (* (sqrt x) (sqrt y)).
// Trig identities other than sin^2 + cos^2 = 1 (multiple angles, tan as
// sin/cos) are not applied. The memo table only grows; it is indexed by id.
#include "cas/simplify.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "base/error.hpp"
#include "base/number.hpp"
#include "cas/polynomial.hpp"

namespace sicm {
namespace {

// The normal-form search of the trig rules tries 2^n forms for n angles;
// beyond this many angles only the greedy search runs.
constexpr size_t kMaxTrigAngles = 4;
// Rewriting cos^2 as 1 - sin^2 in a polynomial of degree d in cos expands
// (1 - sin^2)^(d/2): its powers are kept, so the work and memory grow as d^3
// times the coefficients' bits. An angle whose sine or cosine appears to a
// higher degree than this is left as it is (emit-4 in
// fuzz/crashes-found/README.md: cos(1/3) to the 12,800th took gigabytes).
// No identity needs more: a form that the rewrite shortens has low degree.
constexpr long kMaxTrigDegree = 64;
// exp of a sum becomes the product of the exps of its terms, each a new
// variable of the rational function, and every operation on a monomial
// costs the number of variables: exp of a 20,351-term sum took 24 s
// (emit-9 in fuzz/crashes-found/README.md). exp of a longer sum than this
// stays as it is; the cancellations the rule is for involve short sums.
constexpr size_t kMaxExpSumTerms = 64;

std::vector<ExprId> g_memo; // id -> canonical form, kNoExpr when not known yet

ExprId memo_get(ExprId id) {
  return id < g_memo.size() ? g_memo[id] : kNoExpr;
}

void memo_put(ExprId id, ExprId value) {
  if (g_memo.size() <= std::max(id, value)) g_memo.resize(expr_count() + 1024, kNoExpr);
  g_memo[id] = value;
  g_memo[value] = value;
}

ExprId simplify_kernel(ExprId id);
bool root_out_squares(ExprId x, ExprId *out);
bool split_root(ExprId x, ExprId *out);
bool root_of_rational(ExprId x, ExprId *out);
bool atan_common_factor(ExprId y, ExprId x, ExprId *out);

// ---- kernels -------------------------------------------------------------------

// Fold an operator applied to numbers, when Scheme's answer keeps exactness:
// the result is exact, or some argument was already inexact. Errors (sqrt of a
// negative number, log of 0) leave the application symbolic.
bool fold_numbers(Op op, const std::vector<ExprId> &args, ExprId *out) {
  bool inexact = false;
  Value v[2];
  for (size_t i = 0; i < args.size(); i++) {
    if (!expr_is_number(args[i])) return false;
    v[i] = expr_number_value(args[i]);
    inexact = inexact || v[i].is(Tag::Flonum);
  }
  Value r;
  try {
    switch (op) {
    case Op::Sqrt:
      if (num_sign(v[0]) < 0) return false;
      r = num_sqrt(v[0]);
      break;
    case Op::Exp: r = num_exp(v[0]); break;
    case Op::Log:
      if (num_sign(v[0]) <= 0) return false;
      r = num_log(v[0]);
      break;
    case Op::Sin: r = num_sin(v[0]); break;
    case Op::Cos: r = num_cos(v[0]); break;
    case Op::Tan: r = num_tan(v[0]); break;
    case Op::Asin: r = num_asin(v[0]); break;
    case Op::Acos: r = num_acos(v[0]); break;
    case Op::Atan: r = args.size() == 2 ? num_atan2(v[0], v[1]) : num_atan(v[0]); break;
    case Op::Abs: r = num_abs(v[0]); break;
    case Op::Expt:
      if (num_sign(v[0]) < 0 && !is_exact_integer(v[1])) return false;
      r = num_expt(v[0], v[1]);
      break;
    case Op::Sinh:
      r = num_is_zero(v[0]) && !inexact ? Value::fixnum(0)
                                        : Value::flonum(std::sinh(to_double(v[0])));
      break;
    case Op::Cosh:
      r = num_is_zero(v[0]) && !inexact ? Value::fixnum(1)
                                        : Value::flonum(std::cosh(to_double(v[0])));
      break;
    default: return false;
    }
  } catch (const Error &) {
    return false;
  }
  if (!inexact && !is_exact(r)) return false;
  if (is_recnum(r)) return false; // (asin 2): expressions are over the reals
  *out = expr_from_number(r);
  return true;
}

// The sign of the leading coefficient of a canonical expression: of its
// first term that is not a number (as scmutils' angular-parity rules look at
// the first product of a sum).
int leading_sign(ExprId x) {
  while (true) {
    if (expr_is_constant(x)) return expr_number_sign(x);
    if (expr_is_apply(x, Op::Add)) {
      x = expr_arg(x, expr_is_constant(expr_arg(x, 0)) ? 1 : 0);
      continue;
    }
    if (expr_is_apply(x, Op::Div)) {
      x = expr_arg(x, 0);
      continue;
    }
    if (expr_is_apply(x, Op::Mul) && expr_is_constant(expr_arg(x, 0)))
      return expr_number_sign(expr_arg(x, 0));
    return 1;
  }
}

ExprId negate(ExprId x) {
  return simplify_expr(expr_apply(Op::Mul, {expr_integer(-1), x}));
}

// Move a negative sign out of the argument of sin, cos, tan and abs.
bool apply_parity(Op op, ExprId x, ExprId *out) {
  bool odd = op == Op::Sin || op == Op::Tan;
  bool even = op == Op::Cos || op == Op::Abs;
  if ((!odd && !even) || leading_sign(x) >= 0) return false;
  ExprId k = simplify_expr(expr_apply(op, {negate(x)}));
  *out = odd ? negate(k) : k;
  return true;
}

bool is_op1(ExprId x, Op op) {
  return expr_is_apply(x, op) && expr_node(x).nargs == 1;
}

// exp of a sum is the product of the exps of its terms (up to
// kMaxExpSumTerms of them), exp of a negative quantity the reciprocal of exp
// of its negation, exp of n x with an integer n > 1 a power of (exp x), and
// exp of n (log y) is y^n: so equal values get one form and products of
// exponentials cancel ((* (exp x) (exp (- x))) is 1).
bool expand_exp(ExprId x, ExprId *out) {
  if (is_op1(x, Op::Log)) {
    *out = expr_arg(x, 0);
    return true;
  }
  std::vector<ExprId> xs = expr_arg_vector(x);
  // A constant term would become a transcendental number; such a sum, and a
  // long one, stays whole (and may still be negative, below).
  if (expr_is_apply(x, Op::Add) && xs.size() <= kMaxExpSumTerms &&
      std::none_of(xs.begin(), xs.end(), expr_is_number)) {
    std::vector<ExprId> factors;
    for (ExprId term : xs)
      factors.push_back(expr_apply(Op::Exp, {term}));
    *out = simplify_expr(expr_apply(Op::Mul, factors.data(), factors.size()));
    return true;
  }
  int64_t c;
  bool integer = expr_is_apply(x, Op::Mul) && expr_get_int64(xs[0], &c);
  if (integer && xs.size() == 2 && is_op1(xs[1], Op::Log)) {
    *out = simplify_expr(expr_apply(Op::Expt, {expr_arg(xs[1], 0), expr_integer(c)}));
    return true;
  }
  if (!expr_is_number(x) && leading_sign(x) < 0) {
    *out =
        simplify_expr(expr_apply(Op::Expt, {expr_apply(Op::Exp, {negate(x)}), expr_integer(-1)}));
    return true;
  }
  if (!integer || c <= 1 || c > kMaxExpandedPower) return false;
  std::vector<ExprId> rest(xs.begin() + 1, xs.end());
  ExprId base = rest.size() == 1 ? rest[0] : expr_apply(Op::Mul, rest.data(), rest.size());
  *out = simplify_expr(expr_apply(Op::Expt, {expr_apply(Op::Exp, {base}), expr_integer(c)}));
  return true;
}

// The rules of one kernel, its arguments already canonical. Returns a
// canonical expression: the kernel itself when no rule applies.
ExprId kernel_rules(Op op, const std::vector<ExprId> &args) {
  ExprId out;
  if (fold_numbers(op, args, &out)) return out;
  ExprId x = args[0];
  switch (op) {
  case Op::Sin:
    if (is_op1(x, Op::Asin)) return expr_arg(x, 0);
    break;
  case Op::Cos:
    if (is_op1(x, Op::Acos)) return expr_arg(x, 0);
    break;
  case Op::Tan:
    if (is_op1(x, Op::Atan)) return expr_arg(x, 0);
    break;
  case Op::Asin:
    if (is_op1(x, Op::Sin)) return expr_arg(x, 0);
    break;
  case Op::Acos:
    if (is_op1(x, Op::Cos)) return expr_arg(x, 0);
    break;
  case Op::Atan:
    if (args.size() == 1 && is_op1(x, Op::Tan)) return expr_arg(x, 0);
    if (args.size() == 2 && is_op1(x, Op::Sin) && is_op1(args[1], Op::Cos) &&
        expr_arg(x, 0) == expr_arg(args[1], 0))
      return expr_arg(x, 0);
    if (args.size() == 2 && atan_common_factor(x, args[1], &out)) return out;
    break;
  case Op::Sqrt:
    if (root_of_rational(x, &out) || split_root(x, &out) || root_out_squares(x, &out)) return out;
    break;
  case Op::Exp:
    if (expand_exp(x, &out)) return out;
    break;
  case Op::Log:
    if (is_op1(x, Op::Exp)) return expr_arg(x, 0);
    if (is_op1(x, Op::Sqrt)) {
      mpq_t half;
      mpq_init(half);
      mpq_set_ui(half, 1, 2);
      ExprId h = expr_rational(half);
      mpq_clear(half);
      return simplify_expr(expr_apply(Op::Mul, {h, expr_apply(Op::Log, {expr_arg(x, 0)})}));
    }
    break;
  case Op::Expt: {
    ExprId e = args[1];
    ExprId power = expr_apply(Op::Expt, {x, e});
    if (expr_is_polynomial_power(power)) return simplify_expr(power);
    if (expr_kind(e) == ExprKind::Rational && mpz_cmp_ui(mpq_denref(expr_rat(e)), 2) == 0 &&
        mpz_fits_slong_p(mpq_numref(expr_rat(e)))) {
      int64_t p = mpz_get_si(mpq_numref(expr_rat(e)));
      ExprId root = simplify_expr(expr_apply(Op::Sqrt, {x}));
      return simplify_expr(expr_apply(Op::Expt, {root, expr_integer(p)}));
    }
    break;
  }
  default: break;
  }
  if (args.size() == 1 && apply_parity(op, x, &out)) return out;
  return expr_apply(op, args.data(), args.size());
}

// The index list of a (partial i ...) operator, or false.
bool partial_indices(ExprId op, std::vector<int64_t> *indices) {
  const ExprNode &n = expr_node(op);
  if (n.kind != ExprKind::Call) return false;
  const ExprNode &h = expr_node(n.head);
  if (h.kind != ExprKind::Symbol || h.sym->name != "partial") return false;
  indices->clear();
  for (ExprId i : expr_arg_vector(op)) {
    int64_t v;
    if (!expr_get_int64(i, &v)) return false;
    indices->push_back(v);
  }
  return true;
}

// A derived-function head ((partial i) ((partial j) f)) with the partials
// sorted, smaller index lists outside, so mixed partials that differ only in
// the order of differentiation are one kernel (scmutils' canonicalize-partials,
// with commute-partials on: it holds for the smooth functions of mechanics).
ExprId canonical_partials(ExprId head) {
  std::vector<int64_t> outer, inner;
  const ExprNode &n = expr_node(head);
  if (n.kind != ExprKind::Call || n.nargs != 1 || !partial_indices(n.head, &outer)) return head;
  ExprId outer_op = n.head;
  ExprId f = canonical_partials(expr_arg(head, 0));
  const ExprNode &fn = expr_node(f);
  if (fn.kind == ExprKind::Call && fn.nargs == 1 && partial_indices(fn.head, &inner) &&
      std::lexicographical_compare(inner.begin(), inner.end(), outer.begin(), outer.end())) {
    ExprId inner_op = fn.head, g = expr_arg(f, 0);
    ExprId swapped = canonical_partials(expr_call(outer_op, &g, 1));
    return expr_call(inner_op, &swapped, 1);
  }
  return expr_call(outer_op, &f, 1);
}

ExprId simplify_kernel(ExprId id) {
  const ExprNode &n = expr_node(id);
  bool is_call = n.kind == ExprKind::Call;
  ExprId head = is_call ? n.head : kNoExpr;
  Op op = n.op;
  std::vector<ExprId> args = expr_arg_vector(id);
  for (ExprId &a : args)
    a = simplify_expr(a);
  if (is_call) return expr_call(canonical_partials(head), args.data(), args.size());
  return kernel_rules(op, args);
}

// ---- rational skeleton ---------------------------------------------------------

bool is_skeleton(ExprId id) {
  const ExprNode &n = expr_node(id);
  if (n.kind != ExprKind::Apply) return false;
  return op_is_rational(n.op) || expr_is_polynomial_power(id);
}

// The terms of a polynomial by exponent vector, for the local trig merges.
class TermTable {
public:
  explicit TermTable(const Poly &p) : ring_(p.ring()), nvars_(std::max<size_t>(ring_.nvars(), 1)) {
    slong n = p.length();
    std::vector<ulong> e(nvars_);
    fmpq_t c;
    fmpq_init(c);
    for (slong i = 0; i < n; i++) {
      fmpq_mpoly_get_term_exp_ui(e.data(), p.get(), i, ring_.ctx());
      fmpq_mpoly_get_term_coeff_fmpq(c, p.get(), i, ring_.ctx());
      add(e, c);
    }
    fmpq_clear(c);
  }
  ~TermTable() {
    for (Term &t : terms_)
      fmpq_clear(t.coeff);
  }
  TermTable(const TermTable &) = delete;
  TermTable &operator=(const TermTable &) = delete;

  size_t size() const { return terms_.size(); }
  bool alive(size_t i) const { return !fmpq_is_zero(terms_[i].coeff); }

  // a X + (-a) X u^2 -> a X v^2, for term i = a X.
  bool merge(size_t i, int u, int v) {
    std::vector<ulong> e = terms_[i].exps;
    e[u] += 2;
    long j = find(e);
    if (j < 0 || !negatives(i, j)) return false;
    e[u] -= 2;
    e[v] += 2;
    return replace(i, j, e);
  }

  // a X s^2 + a X c^2 -> a X, for term i = a X s^2.
  bool flush(size_t i, int s, int c) {
    std::vector<ulong> e = terms_[i].exps;
    if (e[s] < 2) return false;
    e[s] -= 2;
    e[c] += 2;
    long j = find(e);
    if (j < 0 || !fmpq_equal(terms_[i].coeff, terms_[j].coeff)) return false;
    e[c] -= 2;
    return replace(i, j, e);
  }

  // Built from integer terms over the denominators' lcm and put in order
  // once: setting the terms one by one re-normalizes the whole polynomial
  // each time, quadratic in its length (emit-9 spent a minute there).
  Poly to_poly() const {
    fmpz_t lcm, scaled;
    fmpz_init_set_ui(lcm, 1);
    fmpz_init(scaled);
    for (const Term &t : terms_)
      if (!fmpq_is_zero(t.coeff)) fmpz_lcm(lcm, lcm, fmpq_denref(t.coeff));
    Poly p(ring_);
    for (const Term &t : terms_) {
      if (fmpq_is_zero(t.coeff)) continue;
      fmpz_divexact(scaled, lcm, fmpq_denref(t.coeff));
      fmpz_mul(scaled, scaled, fmpq_numref(t.coeff));
      fmpq_mpoly_push_term_fmpz_ui(p.get(), scaled, t.exps.data(), ring_.ctx());
    }
    fmpq_mpoly_sort_terms(p.get(), ring_.ctx());
    fmpq_mpoly_combine_like_terms(p.get(), ring_.ctx());
    fmpq_mpoly_scalar_div_fmpz(p.get(), p.get(), lcm, ring_.ctx());
    fmpz_clear(scaled);
    fmpz_clear(lcm);
    return p;
  }

private:
  struct Term {
    std::vector<ulong> exps;
    fmpq_t coeff; // zero: removed
  };

  long find(const std::vector<ulong> &e) const {
    auto it = index_.find(e);
    if (it == index_.end() || fmpq_is_zero(terms_[it->second].coeff)) return -1;
    return static_cast<long>(it->second);
  }

  bool negatives(size_t i, size_t j) const {
    fmpq_t s;
    fmpq_init(s);
    fmpq_add(s, terms_[i].coeff, terms_[j].coeff);
    bool zero = fmpq_is_zero(s);
    fmpq_clear(s);
    return zero;
  }

  // Terms i and j give way to a term of exponents e with i's coefficient.
  bool replace(size_t i, size_t j, const std::vector<ulong> &e) {
    fmpq_t c;
    fmpq_init(c);
    fmpq_set(c, terms_[i].coeff);
    fmpq_zero(terms_[i].coeff);
    fmpq_zero(terms_[j].coeff);
    add(e, c);
    fmpq_clear(c);
    return true;
  }

  void add(const std::vector<ulong> &e, const fmpq_t c) {
    auto it = index_.find(e);
    if (it != index_.end()) {
      fmpq_add(terms_[it->second].coeff, terms_[it->second].coeff, c);
      return;
    }
    index_.emplace(e, terms_.size());
    terms_.emplace_back();
    terms_.back().exps = e;
    fmpq_init(terms_.back().coeff);
    fmpq_set(terms_.back().coeff, c);
  }

  const PolyRing &ring_;
  size_t nvars_;
  std::deque<Term> terms_; // a deque: Terms hold fmpq structs that must not move
  std::map<std::vector<ulong>, size_t> index_;
};

// Does id hold a flonum that is not finite?
bool holds_nonfinite(ExprId id) {
  std::unordered_set<ExprId> seen;
  std::vector<ExprId> todo{id};
  while (!todo.empty()) {
    ExprId e = todo.back();
    todo.pop_back();
    if (!seen.insert(e).second) continue;
    const ExprNode &n = expr_node(e);
    if (n.kind == ExprKind::Flonum && !std::isfinite(n.d)) return true;
    if (n.kind == ExprKind::Apply || n.kind == ExprKind::Call)
      for (ExprId a : expr_arg_vector(e))
        todo.push_back(a);
  }
  return false;
}

// One simplification of a rational skeleton: its variables, its ring, the
// rational functions of its subexpressions.
class Pass {
public:
  // Gather the variables below `id` (step 1).
  void collect(ExprId id) {
    if (uses_[id]++) return;
    const ExprNode &n = expr_node(id);
    switch (n.kind) {
    case ExprKind::Rational: return;
    case ExprKind::Flonum:
      if (std::isfinite(n.d))
        inexact_ = true;
      else
        add_variable(id);
      return;
    case ExprKind::Symbol: add_variable(id); return;
    case ExprKind::Apply:
    case ExprKind::Call: break;
    }
    if (is_skeleton(id)) {
      for (ExprId a : expr_arg_vector(id))
        collect(a);
      return;
    }
    ExprId k = simplify_expr(id);
    if (expr_is_variable(k)) {
      add_variable(k);
      // sqrt(u)^2 is rewritten to u, so u's variables belong to the ring.
      if (is_op1(k, Op::Sqrt)) collect(expr_arg(k, 0));
    } else {
      collect(k);
    }
  }

  const PolyRing &make_ring() {
    std::sort(vars_.begin(), vars_.end(),
              [](ExprId a, ExprId b) { return expr_compare(a, b) < 0; });
    ring_ = std::make_unique<PolyRing>(vars_);
    return *ring_;
  }

  // The rational function of a node (step 2), memoized for nodes used more
  // than once in the skeleton (most are used once: storing those would cost
  // more allocation than it saves).
  RatFun convert(ExprId id) {
    auto it = memo_.find(id);
    if (it != memo_.end()) return it->second;
    RatFun f = compute(id);
    auto u = uses_.find(id);
    if (u != uses_.end() && u->second > 1) memo_.emplace(id, f);
    return f;
  }

  // sqrt(u)^2 = u, outermost square roots first (their radicands may hold
  // inner ones, which have smaller ids).
  RatFun reduce_roots(RatFun f) {
    std::vector<ExprId> roots;
    for (ExprId v : vars_)
      if (is_op1(v, Op::Sqrt)) roots.push_back(v);
    std::sort(roots.rbegin(), roots.rend());
    for (ExprId s : roots) {
      int i = ring_->index_of(s);
      if (poly_degree_in(f.num, i) < 2 && poly_degree_in(f.den, i) < 2) continue;
      f = rf_reduce_square(f, i, convert(expr_arg(s, 0)));
    }
    return f;
  }

  // u / sqrt(u) = sqrt(u): a denominator divisible by s = sqrt(u) over a
  // numerator divisible by u (a polynomial) moves s up, as scmutils' simsqrt
  // rules do; other square roots stay in denominators.
  RatFun lift_roots(RatFun f) {
    for (ExprId s : vars_) {
      if (!is_op1(s, Op::Sqrt) || f.is_polynomial()) continue;
      RatFun u = convert(expr_arg(s, 0));
      if (!u.is_polynomial() || u.is_zero()) continue;
      const PolyRing &r = *ring_;
      Poly root = rf_variable(r, r.index_of(s)).num;
      Poly n(r), d(r);
      while (fmpq_mpoly_divides(d.get(), f.den.get(), root.get(), r.ctx()) &&
             fmpq_mpoly_divides(n.get(), f.num.get(), u.num.get(), r.ctx())) {
        fmpq_mpoly_mul(n.get(), n.get(), root.get(), r.ctx());
        f = RatFun(n, d);
        if (f.is_polynomial()) break;
      }
    }
    return f;
  }

  // sin^2 + cos^2 = 1. A search for the form with the fewest terms, from
  // three kinds of candidates:
  //  - local merges (scmutils' sincos-flush-ones and sincos-random rules):
  //    a X s^2 + a X c^2 -> a X, a X - a X s^2 -> a X c^2 and
  //    a X - a X c^2 -> a X s^2, for s and c the sine and cosine of one angle;
  //    each merge removes a term, and mixed forms such as
  //    (+ (* A (expt (sin x) 2)) (* C (expt (cos x) 2))) are left alone;
  //  - greedy substitution: for each angle try cos^2 = 1 - sin^2 and
  //    sin^2 = 1 - cos^2 everywhere, keep a rewrite with fewer terms, over all
  //    angles until none helps;
  //  - normal forms: for up to kMaxTrigAngles angles, every choice of
  //    eliminating cos^2 or sin^2 per angle. They depend only on the value
  //    modulo the identities, so an expression equal to 0 becomes 0, and
  //    merging them finds the compact forms of expressions that arrive
  //    expanded (the rigid body's kinetic energy from its rotation matrices).
  // A candidate replaces the current form only when it is strictly smaller,
  // and the search repeats until nothing changes: the result is a fixpoint,
  // so simplifying it again changes nothing.
  RatFun reduce_trig(RatFun f) {
    std::vector<Angle> angles;
    for (ExprId s : vars_) {
      if (!is_op1(s, Op::Sin)) continue;
      Angle a{ring_->index_of(s), ring_->index_of(partner(s)), RatFun(*ring_), RatFun(*ring_)};
      if (max_degree(f, a.sin) > kMaxTrigDegree || max_degree(f, a.cos) > kMaxTrigDegree) continue;
      if (degree2(f, a.sin) || degree2(f, a.cos)) {
        a.one_minus_sin2 =
            rf_add(rf_constant_int(1), rf_neg(rf_pow(rf_variable(*ring_, a.sin), 2)));
        a.one_minus_cos2 =
            rf_add(rf_constant_int(1), rf_neg(rf_pow(rf_variable(*ring_, a.cos), 2)));
        angles.push_back(std::move(a));
      }
    }
    if (angles.empty()) return f;
    while (true) {
      long before = size(f);
      f = merge_sincos(f, angles);
      RatFun g = merge_sincos(greedy_trig(f, angles), angles);
      if (size(g) < size(f)) f = std::move(g);
      if (angles.size() <= kMaxTrigAngles) {
        RatFun start = f;
        normal_forms(start, angles, 0, &f);
      }
      if (size(f) == before) return f;
    }
  }

  bool inexact() const { return inexact_; }

private:
  void add_variable(ExprId v) {
    if (!var_set_.insert(v).second) return;
    vars_.push_back(v);
    // A sine brings its cosine into the ring and vice versa, so that
    // reduce_trig can rewrite (- 1 (expt (sin x) 2)) as (expt (cos x) 2).
    if (is_op1(v, Op::Sin) || is_op1(v, Op::Cos)) add_variable(partner(v));
  }

  // (cos x) for (sin x) and (sin x) for (cos x).
  static ExprId partner(ExprId v) {
    return expr_apply(is_op1(v, Op::Sin) ? Op::Cos : Op::Sin, {expr_arg(v, 0)});
  }

  static long size(const RatFun &f) { return f.num.length() + f.den.length(); }

  struct Angle {
    int sin, cos;                          // ring indices of (sin x) and (cos x)
    RatFun one_minus_sin2, one_minus_cos2; // what cos^2 and sin^2 become
  };

  static long max_degree(const RatFun &f, int v) {
    return std::max(poly_degree_in(f.num, v), poly_degree_in(f.den, v));
  }

  static bool degree2(const RatFun &f, int v) { return max_degree(f, v) >= 2; }

  RatFun greedy_trig(RatFun f, const std::vector<Angle> &angles) {
    bool improved = true;
    while (improved) {
      improved = false;
      for (const Angle &a : angles) {
        if (!degree2(f, a.sin) && !degree2(f, a.cos)) continue;
        RatFun x = rf_reduce_square(f, a.cos, a.one_minus_sin2);
        RatFun y = rf_reduce_square(f, a.sin, a.one_minus_cos2);
        long now = size(f), sx = size(x), sy = size(y);
        if (sx < now && sx <= sy) {
          f = std::move(x);
          improved = true;
        } else if (sy < now) {
          f = std::move(y);
          improved = true;
        }
      }
    }
    return f;
  }

  // Try both eliminations for angles[i..] of f, keeping in *best the
  // smallest merged result that is smaller than it.
  void normal_forms(const RatFun &f, const std::vector<Angle> &angles, size_t i, RatFun *best) {
    if (i == angles.size()) {
      RatFun m = merge_sincos(f, angles);
      if (size(m) < size(*best)) *best = std::move(m);
      return;
    }
    const Angle &a = angles[i];
    normal_forms(rf_reduce_square(f, a.cos, a.one_minus_sin2), angles, i + 1, best);
    normal_forms(rf_reduce_square(f, a.sin, a.one_minus_cos2), angles, i + 1, best);
  }

  RatFun merge_sincos(const RatFun &f, const std::vector<Angle> &angles) {
    Poly n = merge_sincos(f.num, angles);
    if (f.den.is_one()) {
      RatFun g(*ring_);
      g.num = std::move(n);
      return g;
    }
    return RatFun(std::move(n), merge_sincos(f.den, angles));
  }

  // The local merges of reduce_trig on one polynomial.
  Poly merge_sincos(const Poly &p, const std::vector<Angle> &angles) {
    TermTable t(p);
    bool merged = false;
    for (bool again = true; again;) {
      again = false;
      for (size_t i = 0; i < t.size(); i++) {
        if (!t.alive(i)) continue;
        for (const Angle &a : angles) {
          if (t.merge(i, a.sin, a.cos) || t.merge(i, a.cos, a.sin) || t.flush(i, a.sin, a.cos)) {
            again = merged = true;
            break;
          }
        }
      }
    }
    return merged ? t.to_poly() : p;
  }

  RatFun rf_constant_int(int64_t n) {
    mpq_t q;
    mpq_init(q);
    mpq_set_si(q, static_cast<long>(n), 1);
    RatFun f = rf_constant(*ring_, q);
    mpq_clear(q);
    return f;
  }

  RatFun compute(ExprId id) {
    const ExprNode &n = expr_node(id);
    switch (n.kind) {
    case ExprKind::Rational: return rf_constant(*ring_, expr_rat(id));
    case ExprKind::Flonum:
      if (std::isfinite(n.d)) {
        mpq_t q;
        mpq_init(q);
        mpq_set_d(q, n.d);
        RatFun f = rf_constant(*ring_, q);
        mpq_clear(q);
        return f;
      }
      return variable(id);
    case ExprKind::Symbol: return variable(id);
    case ExprKind::Apply:
    case ExprKind::Call: break;
    }
    if (!is_skeleton(id)) {
      ExprId k = simplify_expr(id);
      if (expr_is_variable(k)) return variable(k);
      return convert(k);
    }
    Op op = n.op;
    std::vector<ExprId> args = expr_arg_vector(id);
    switch (op) {
    case Op::Add: {
      // Summed pairwise: adding a term to an n-term polynomial costs O(n)
      // (FLINT rescales every coefficient to the common content), so adding
      // the terms of a canonical sum one by one is quadratic. Negating a
      // simplified 46,376-term sum took 18 s that way (emit-4's timeouts,
      // fuzz/crashes-found/README.md).
      std::vector<RatFun> terms;
      terms.reserve(args.size());
      for (ExprId a : args)
        terms.push_back(convert(a));
      for (size_t width = 1; width < terms.size(); width *= 2)
        for (size_t i = 0; i + width < terms.size(); i += 2 * width)
          terms[i] = rf_add(terms[i], terms[i + width]);
      return std::move(terms[0]);
    }
    case Op::Mul: {
      // Multiplied pairwise, as sums are added: multiplying factor by factor
      // into a growing product is quadratic in the factors, and exp of a
      // 20,351-term sum is a product of as many powers of exponentials
      // (emit-9's second input: 34 s). A zero factor ends the product
      // before the factors after it are converted, as it always did.
      std::vector<RatFun> factors;
      factors.reserve(args.size());
      for (ExprId a : args) {
        factors.push_back(convert(a));
        if (factors.back().is_zero()) return std::move(factors.back());
      }
      for (size_t width = 1; width < factors.size(); width *= 2)
        for (size_t i = 0; i + width < factors.size(); i += 2 * width)
          factors[i] = rf_mul(factors[i], factors[i + width]);
      return std::move(factors[0]);
    }
    case Op::Div: {
      RatFun d = convert(args[1]);
      return rf_div(convert(args[0]), d);
    }
    case Op::Expt: {
      int64_t e;
      SICM_ASSERT(expr_get_int64(args[1], &e)); // exponents beyond int64 are hopeless anyway
      // (u^a)^b is u^(ab) for nonzero integers a and b and u not zero:
      // one power of u costs far less than a power of u^a expanded, which
      // is a polynomial of many terms ((x + y + .002)^12 has 91; raising
      // it to the 18th took 40 s where u^216 takes 0.1 s). A zero u keeps
      // the chain, whose negative powers divide by zero: ((u^-1)^-1) is
      // an error, u^1 would not be.
      ExprId base = args[0];
      int64_t inner, product, combined = e;
      // Only through polynomial powers: a power past kMaxExpandedPower is
      // a variable of the ring, its base not (emit-17: (expt (expt x
      // 200000) -9) reached a base collect had not seen, and aborted).
      while (combined != 0 && expr_is_polynomial_power(base) &&
             expr_get_int64(expr_arg(base, 1), &inner) && inner != 0 &&
             !__builtin_mul_overflow(combined, inner, &product)) {
        combined = product;
        base = expr_arg(base, 0);
      }
      if (base != args[0]) {
        RatFun u = convert(base);
        if (!u.is_zero()) return rf_pow(u, combined);
      }
      RatFun b = convert(args[0]);
      if (b.is_zero() && e >= 0) return e == 0 ? rf_constant_int(1) : RatFun(*ring_);
      return rf_pow(b, e);
    }
    default: break;
    }
    SICM_ASSERT(false); // is_skeleton covers exactly the cases above
    return RatFun(*ring_);
  }

  RatFun variable(ExprId v) {
    int i = ring_->index_of(v);
    SICM_ASSERT(i >= 0);
    return rf_variable(*ring_, i);
  }

  std::unordered_map<ExprId, uint32_t> uses_; // skeleton nodes seen by collect, with use counts
  std::unordered_set<ExprId> var_set_;
  std::vector<ExprId> vars_;
  std::unique_ptr<PolyRing> ring_;
  std::unordered_map<ExprId, RatFun> memo_;
  bool inexact_ = false;
};

// (sqrt (* f^2 g)) = (* f (sqrt g)) for the square factors f of the radicand
// (numerator and denominator), as scmutils' root-out-squares does with
// sqrt-expt-simplify on (its default): this assumes f >= 0, so
// (sqrt (expt r 2)) is r.
bool root_out_squares(ExprId x, ExprId *out) {
  if (expr_is_number(x) || expr_is_variable(x)) return false;
  Pass pass;
  pass.collect(x);
  const PolyRing &ring = pass.make_ring();
  RatFun f = pass.convert(x);
  Poly num_root(ring), num_rest(ring), den_root(ring), den_rest(ring);
  fmpq_t c, cd;
  fmpq_init(c);
  fmpq_init(cd);
  poly_split_square(f.num, c, &num_root, &num_rest);
  poly_split_square(f.den, cd, &den_root, &den_rest);
  // The constant factor as a whole leaves the root only if it is the square
  // of a positive rational (so each rewrite shrinks the radicand, and this ends).
  fmpq_div(c, c, cd);
  bool square = fmpq_sgn(c) > 0 && !fmpq_is_one(c) && fmpz_is_square(fmpq_numref(c)) &&
                fmpz_is_square(fmpq_denref(c));
  bool changed = square || !num_root.is_one() || !den_root.is_one();
  if (changed) {
    if (square) {
      fmpz_sqrt(fmpq_numref(c), fmpq_numref(c));
      fmpz_sqrt(fmpq_denref(c), fmpq_denref(c));
      fmpq_mpoly_scalar_mul_fmpq(num_root.get(), num_root.get(), c, ring.ctx());
    } else {
      fmpq_mpoly_scalar_mul_fmpq(num_rest.get(), num_rest.get(), c, ring.ctx());
    }
    ExprId outside = rf_to_expr(RatFun(std::move(num_root), std::move(den_root)), pass.inexact());
    ExprId inside = rf_to_expr(RatFun(std::move(num_rest), std::move(den_rest)), pass.inexact());
    *out = simplify_expr(expr_apply(Op::Mul, {outside, expr_apply(Op::Sqrt, {inside})}));
  }
  fmpq_clear(c);
  fmpq_clear(cd);
  return changed;
}

// scmutils' simplifier ends its work on square roots (new-simplify in
// simplify/rules.scm: sqrt-contract until stable, root-out-squares, then
// sqrt-expand until stable) with them expanded: (sqrt (* x y)) is
// (* (sqrt x) (sqrt y)) and (sqrt (/ x y)) is (/ (sqrt x) (sqrt y)), on its
// assumption (sqrt-factor-simplify, on by default) that the factors are
// non-negative. This is that final form, reached in one step: the radicand,
// its square factors taken out (root-out-squares), is
//   c * v1 ... vk * P / (w1 ... wl * Q)
// with c a positive rational, the v and w variables (symbols or kernels)
// and P and Q polynomials of two terms or more with no monomial factor,
// and its root is the product (sqrt c) (sqrt v1) ... (sqrt P) over
// (sqrt w1) ... (sqrt Q). Every product or quotient of square roots then
// contracts in the rational function as sqrt(u)^2 = u does:
// (* (sqrt (* 2 I alpha)) (sqrt (/ (* 2 I) alpha))) is (* 2 I), which is
// what contracting with sqrt-contract and rooting out the square gives.
// The sign of c goes into P (or Q): (sqrt (- 1 (expt x 2))) stays whole.
// A radicand whose sign is its monomial's, (sqrt (* -1 x)), is not split
// (scmutils' rule does not split a negative factor off), nor one with
// flonums (whose numeric root would be a flonum kernel).
// The value is unchanged up to the sign of each root of the input, and
// equal under scmutils' assumption; every root of the input becomes one
// product of roots, so a choice of signs of the input's roots gives the
// output's value (the fuzz target's property 5).
bool split_root(ExprId x, ExprId *out) {
  if (expr_is_number(x) || expr_is_variable(x)) return false;
  Pass pass;
  pass.collect(x);
  const PolyRing &ring = pass.make_ring();
  if (pass.inexact()) return false;
  RatFun f = pass.convert(x);
  Poly num_root(ring), num_mono(ring), num_rest(ring);
  Poly den_root(ring), den_mono(ring), den_rest(ring);
  fmpq_t c, cd;
  fmpq_init(c);
  fmpq_init(cd);
  poly_split_root_factors(f.num, c, &num_root, &num_mono, &num_rest);
  poly_split_root_factors(f.den, cd, &den_root, &den_mono, &den_rest);
  fmpq_div(c, c, cd);
  bool split = true;
  if (fmpq_sgn(c) < 0) {
    Poly *signed_rest = !num_rest.is_one() ? &num_rest : !den_rest.is_one() ? &den_rest : nullptr;
    if (signed_rest)
      fmpq_mpoly_neg(signed_rest->get(), signed_rest->get(), ring.ctx());
    else
      split = false;
    fmpq_neg(c, c);
  }
  // The roots over and under the line.
  std::vector<ExprId> up, down;
  auto roots_of = [&](const Poly &mono, const Poly &rest, std::vector<ExprId> *roots) {
    std::vector<ulong> e(std::max<size_t>(ring.nvars(), 1));
    if (!mono.is_one()) {
      fmpq_mpoly_get_term_exp_ui(e.data(), mono.get(), 0, ring.ctx());
      for (size_t i = 0; i < ring.nvars(); i++) {
        if (e[i] > 1) split = false; // not squarefree: cannot happen, but be safe
        if (e[i] == 1) roots->push_back(expr_apply(Op::Sqrt, {ring.var(i)}));
      }
    }
    if (!rest.is_one()) {
      Poly one(ring);
      fmpq_mpoly_one(one.get(), ring.ctx());
      roots->push_back(expr_apply(Op::Sqrt, {rf_to_expr(RatFun(rest, std::move(one)), false)}));
    }
  };
  roots_of(num_mono, num_rest, &up);
  roots_of(den_mono, den_rest, &down);
  if (!fmpq_is_one(c)) {
    mpq_t q;
    mpq_init(q);
    fmpq_get_mpq(q, c);
    up.push_back(expr_apply(Op::Sqrt, {expr_rational(q)}));
    mpq_clear(q);
  }
  bool whole = num_root.is_one() && den_root.is_one() && down.empty() && up.size() <= 1;
  fmpq_clear(c);
  fmpq_clear(cd);
  if (!split || whole) return false;
  ExprId outside = rf_to_expr(RatFun(std::move(num_root), std::move(den_root)), false);
  up.push_back(outside);
  ExprId over = up.size() == 1 ? up[0] : expr_apply(Op::Mul, up.data(), up.size());
  if (!down.empty()) {
    ExprId under = down.size() == 1 ? down[0] : expr_apply(Op::Mul, down.data(), down.size());
    over = expr_apply(Op::Div, {over, under});
  }
  *out = simplify_expr(over);
  return true;
}

// (atan (* g y) (* g x)) is (atan y x) for g the greatest common divisor of
// two polynomials (monic, so a number is never divided out), as scmutils'
// atan rule divides by (gcd y x) with aggressive-atan-simplify on (its
// default): this assumes g > 0, which keeps the quadrant. So
// (atan (* r (sin phi)) (* r (cos phi))) is phi.
bool atan_common_factor(ExprId y, ExprId x, ExprId *out) {
  if (expr_is_number(y) || expr_is_number(x)) return false;
  Pass pass;
  pass.collect(y);
  pass.collect(x);
  const PolyRing &ring = pass.make_ring();
  RatFun fy = pass.convert(y), fx = pass.convert(x);
  if (!fy.is_polynomial() || !fx.is_polynomial() || fy.is_zero() || fx.is_zero()) return false;
  Poly g(ring);
  if (!fmpq_mpoly_gcd(g.get(), fy.num.get(), fx.num.get(), ring.ctx()) ||
      fmpq_mpoly_is_fmpq(g.get(), ring.ctx()))
    return false;
  Poly qy(ring), qx(ring), one(ring);
  fmpq_mpoly_div(qy.get(), fy.num.get(), g.get(), ring.ctx());
  fmpq_mpoly_div(qx.get(), fx.num.get(), g.get(), ring.ctx());
  fmpq_mpoly_one(one.get(), ring.ctx());
  ExprId ny = rf_to_expr(RatFun(std::move(qy), one), pass.inexact());
  ExprId nx = rf_to_expr(RatFun(std::move(qx), std::move(one)), pass.inexact());
  *out = simplify_expr(expr_apply(Op::Atan, {ny, nx}));
  return true;
}

// The square root of a positive exact rational that is not a square, as
// scmutils' root-out-squares leaves it and then some: its denominator moved
// out, sqrt(p/q) = sqrt(pq)/q, and the squares of small primes taken out of
// pq, so (sqrt 8) is (* 2 (sqrt 2)) and (sqrt 1/2) is (* 1/2 (sqrt 2)), and
// (* (sqrt 8) (sqrt 2)) is 4. (Larger square factors stay inside: finding
// them is factoring.)
constexpr unsigned long kMaxRootTrialDivisor = 1000;
bool root_of_rational(ExprId x, ExprId *out) {
  if (expr_kind(x) != ExprKind::Rational || mpq_sgn(expr_rat(x)) <= 0) return false;
  mpz_t n, outside, d2;
  mpz_init(n);
  mpz_init_set_ui(outside, 1);
  mpz_init(d2);
  mpz_mul(n, mpq_numref(expr_rat(x)), mpq_denref(expr_rat(x)));
  for (unsigned long d = 2; d <= kMaxRootTrialDivisor; d++) {
    mpz_set_ui(d2, d * d);
    if (mpz_cmp(d2, n) > 0) break;
    while (mpz_divisible_p(n, d2)) {
      mpz_divexact(n, n, d2);
      mpz_mul_ui(outside, outside, d);
    }
  }
  bool changed = mpz_cmp_ui(outside, 1) != 0 || mpz_cmp_ui(mpq_denref(expr_rat(x)), 1) != 0;
  if (changed) {
    mpq_t factor, radicand;
    mpq_init(factor);
    mpq_init(radicand);
    mpz_set(mpq_numref(factor), outside);
    mpz_set(mpq_denref(factor), mpq_denref(expr_rat(x)));
    mpq_canonicalize(factor);
    mpq_set_z(radicand, n);
    ExprId f = expr_rational(factor), r = expr_rational(radicand);
    *out = simplify_expr(expr_apply(Op::Mul, {f, expr_apply(Op::Sqrt, {r})}));
    mpq_clear(factor);
    mpq_clear(radicand);
  }
  mpz_clear(n);
  mpz_clear(outside);
  mpz_clear(d2);
  return changed;
}

ExprId simplify_rational(ExprId id) {
  Pass pass;
  pass.collect(id);
  pass.make_ring();
  RatFun f = pass.convert(id);
  f = pass.reduce_roots(std::move(f));
  f = pass.reduce_roots(pass.lift_roots(std::move(f)));
  f = pass.reduce_trig(std::move(f));
  ExprId r = rf_to_expr(f, pass.inexact());
  // The coefficients are computed exactly and then made flonums, so one can
  // overflow to an infinity that id did not hold; the canonical form has
  // no place for it (C4, C5), so that is an error, not a result.
  if (pass.inexact() && holds_nonfinite(r) && !holds_nonfinite(id))
    runtime_error(current_call_loc(), "simplify: a coefficient overflows the flonums");
  return r;
}

} // namespace

ExprId simplify_expr(ExprId id) {
  ExprId known = memo_get(id);
  if (known != kNoExpr) return known;
  ExprKind kind = expr_kind(id);
  ExprId r;
  if (kind == ExprKind::Rational || kind == ExprKind::Symbol || kind == ExprKind::Flonum)
    r = id;
  else if (is_skeleton(id))
    r = simplify_rational(id);
  else
    r = simplify_kernel(id);
  SICM_EXPR_CHECK(expr_is_canonical(r));
  memo_put(id, r);
  return r;
}

} // namespace sicm
