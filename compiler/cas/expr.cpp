// The expression arena: hash-consing, access, the total order and the canonical-form checker.
#include "cas/expr.hpp"

#include <cmath>
#include <cstring>
#include <vector>

#include "base/limits.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"

namespace sicm {
namespace {

// The arena. Nodes, their argument lists and the exact numbers are plain
// vectors: they hold no Values (see the memory note in expr.hpp). A GMP
// rational is a struct of two limb pointers, safe to move bitwise when the
// pool grows.
std::vector<ExprNode> g_nodes;
std::vector<ExprId> g_argpool;
std::vector<__mpq_struct> g_rats;
// Open-addressing table of node ids by hash; size is a power of two, at most
// half full.
std::vector<ExprId> g_table;
// Keeps every symbol the arena mentions reachable for the collector.
gcvec<Value> g_symbol_roots;

uint32_t mix(uint32_t h, uint64_t v) {
  v ^= v >> 33;
  v *= 0xff51afd7ed558ccdULL;
  v ^= v >> 33;
  return (h ^ static_cast<uint32_t>(v ^ (v >> 32))) * 0x9E3779B1u;
}

uint32_t hash_mpq(mpq_srcptr q) {
  uint32_t h = 0x12345;
  const __mpz_struct *parts[2] = {mpq_numref(q), mpq_denref(q)};
  for (const __mpz_struct *z : parts) {
    h = mix(h, static_cast<uint64_t>(z->_mp_size));
    size_t n = static_cast<size_t>(std::abs(z->_mp_size));
    for (size_t i = 0; i < n; i++)
      h = mix(h, z->_mp_d[i]);
  }
  return h;
}

uint32_t hash_args(uint32_t h, const ExprId *args, size_t n) {
  for (size_t i = 0; i < n; i++)
    h = mix(h, args[i]);
  return mix(h, n);
}

void grow_table() {
  std::vector<ExprId> bigger(g_table.empty() ? 1024 : g_table.size() * 2, kNoExpr);
  size_t mask = bigger.size() - 1;
  for (ExprId id : g_table) {
    if (id == kNoExpr) continue;
    size_t i = g_nodes[id].hash & mask;
    while (bigger[i] != kNoExpr)
      i = (i + 1) & mask;
    bigger[i] = id;
  }
  g_table.swap(bigger);
}

// Find the node equal to a candidate (`same` decides equality of a stored node
// with the candidate) or add it with `make`, which returns the new node's id.
template <class Same, class Make> ExprId intern_node(uint32_t hash, Same same, Make make) {
  if ((g_nodes.size() + 1) * 2 > g_table.size()) grow_table();
  size_t mask = g_table.size() - 1;
  size_t i = hash & mask;
  while (g_table[i] != kNoExpr) {
    ExprId id = g_table[i];
    if (g_nodes[id].hash == hash && same(g_nodes[id])) return id;
    i = (i + 1) & mask;
  }
  SICM_ASSERT(g_nodes.size() < kNoExpr);
  check_expression_nodes(g_nodes.size()); // may throw; nothing is changed yet
  ExprId id = make();
  g_table[i] = id;
  return id;
}

ExprId push_node(ExprNode n) {
  ExprId id = static_cast<ExprId>(g_nodes.size());
  g_nodes.push_back(n);
  return id;
}

bool same_args(const ExprNode &n, const ExprId *args, size_t nargs) {
  return n.nargs == nargs && std::equal(args, args + nargs, g_argpool.begin() + n.args);
}

uint32_t store_args(const ExprId *args, size_t nargs) {
  uint32_t at = static_cast<uint32_t>(g_argpool.size());
  if (args >= g_argpool.data() && args < g_argpool.data() + g_argpool.size()) {
    std::vector<ExprId> copy(args, args + nargs); // the pool may move while growing
    g_argpool.insert(g_argpool.end(), copy.begin(), copy.end());
  } else {
    g_argpool.insert(g_argpool.end(), args, args + nargs);
  }
  return at;
}

bool arity_ok(Op op, size_t n) {
  switch (op) {
  case Op::Add:
  case Op::Mul: return n >= 2;
  case Op::Sub: return false; // never built (I4)
  case Op::Div: return n == 2;
  case Op::Atan: return n == 1 || n == 2;
  default: return op_info(op).arity == static_cast<int>(n);
  }
}

} // namespace

// ---- construction --------------------------------------------------------

ExprId expr_canonical_rational(mpq_srcptr q) {
  uint32_t h = mix(hash_mpq(q), static_cast<uint64_t>(ExprKind::Rational));
  ExprId id = intern_node(
      h,
      [&](const ExprNode &n) {
        return n.kind == ExprKind::Rational && mpq_equal(&g_rats[n.rat], q);
      },
      [&] {
        ExprNode n{};
        n.kind = ExprKind::Rational;
        n.hash = h;
        n.rat = static_cast<uint32_t>(g_rats.size());
        __mpq_struct owned;
        mpq_init(&owned);
        mpq_set(&owned, q);
        g_rats.push_back(owned);
        return push_node(n);
      });
  return id;
}

ExprId expr_rational(mpq_srcptr q_in) {
  mpq_t q;
  mpq_init(q);
  mpq_set(q, q_in);
  mpq_canonicalize(q);
  ExprId id = expr_canonical_rational(q);
  mpq_clear(q);
  return id;
}

ExprId expr_integer(int64_t v) {
  mpq_t q;
  mpq_init(q);
  mpz_set_si(mpq_numref(q), static_cast<long>(v));
  ExprId id = expr_rational(q);
  mpq_clear(q);
  return id;
}

ExprId expr_flonum(double d) {
  uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  uint32_t h = mix(mix(0, static_cast<uint64_t>(ExprKind::Flonum)), bits);
  return intern_node(
      h,
      [&](const ExprNode &n) {
        if (n.kind != ExprKind::Flonum) return false;
        uint64_t nb;
        std::memcpy(&nb, &n.d, sizeof nb);
        return nb == bits;
      },
      [&] {
        ExprNode n{};
        n.kind = ExprKind::Flonum;
        n.hash = h;
        n.d = d;
        return push_node(n);
      });
}

ExprId expr_symbol(Symbol *s) {
  uint32_t h = mix(mix(0, static_cast<uint64_t>(ExprKind::Symbol)), reinterpret_cast<uintptr_t>(s));
  return intern_node(
      h, [&](const ExprNode &n) { return n.kind == ExprKind::Symbol && n.sym == s; },
      [&] {
        g_symbol_roots.push_back(Value::object(Tag::Symbol, s));
        ExprNode n{};
        n.kind = ExprKind::Symbol;
        n.hash = h;
        n.sym = s;
        return push_node(n);
      });
}

ExprId expr_apply(Op op, const ExprId *args, size_t nargs) {
  SICM_EXPR_CHECK(arity_ok(op, nargs));
  uint32_t h = hash_args(mix(static_cast<uint32_t>(ExprKind::Apply), static_cast<uint64_t>(op)),
                         args, nargs);
  return intern_node(
      h,
      [&](const ExprNode &n) {
        return n.kind == ExprKind::Apply && n.op == op && same_args(n, args, nargs);
      },
      [&] {
        for (size_t i = 0; i < nargs; i++)
          SICM_EXPR_CHECK(args[i] < g_nodes.size()); // I1
        ExprNode n{};
        n.kind = ExprKind::Apply;
        n.op = op;
        n.hash = h;
        n.nargs = static_cast<uint32_t>(nargs);
        n.args = store_args(args, nargs);
        return push_node(n);
      });
}

ExprId expr_apply(Op op, std::initializer_list<ExprId> args) {
  return expr_apply(op, args.begin(), args.size());
}

ExprId expr_call(ExprId head, const ExprId *args, size_t nargs) {
  uint32_t h = hash_args(mix(static_cast<uint32_t>(ExprKind::Call), head), args, nargs);
  return intern_node(
      h,
      [&](const ExprNode &n) {
        return n.kind == ExprKind::Call && n.head == head && same_args(n, args, nargs);
      },
      [&] {
        SICM_EXPR_CHECK(head < g_nodes.size()); // I1
        for (size_t i = 0; i < nargs; i++)
          SICM_EXPR_CHECK(args[i] < g_nodes.size());
        ExprNode n{};
        n.kind = ExprKind::Call;
        n.hash = h;
        n.head = head;
        n.nargs = static_cast<uint32_t>(nargs);
        n.args = store_args(args, nargs);
        return push_node(n);
      });
}

ExprId expr_from_number(Value v) {
  if (v.is(Tag::Flonum)) return expr_flonum(v.d);
  if (v.is(Tag::Recnum))
    runtime_error(current_call_loc(),
                  "the complex number " + number_to_string(v) +
                      " cannot enter a symbolic expression: sicm's symbolic algebra is over the "
                      "real numbers");
  if (v.is(Tag::Fixnum)) return expr_integer(v.i);
  SICM_ASSERT(is_exact_rational(v));
  // A number of the tower is canonical already (and canonicalizing one of
  // millions of bits is a gcd that takes minutes).
  mpq_t q;
  mpq_init(q);
  to_mpq(v, q);
  ExprId id = expr_canonical_rational(q);
  mpq_clear(q);
  return id;
}

// ---- access ----------------------------------------------------------------

const ExprNode &expr_node(ExprId id) {
  SICM_EXPR_CHECK(id < g_nodes.size());
  return g_nodes[id];
}

const ExprId *expr_args(ExprId id) {
  return g_argpool.data() + expr_node(id).args;
}

mpq_srcptr expr_rat(ExprId id) {
  SICM_EXPR_CHECK(expr_kind(id) == ExprKind::Rational);
  return &g_rats[g_nodes[id].rat];
}

size_t expr_count() {
  return g_nodes.size();
}

bool expr_is_exact_zero(ExprId id) {
  return expr_kind(id) == ExprKind::Rational && mpq_sgn(expr_rat(id)) == 0;
}

bool expr_is_exact_one(ExprId id) {
  return expr_kind(id) == ExprKind::Rational && mpq_cmp_si(expr_rat(id), 1, 1) == 0;
}

bool expr_is_exact_integer(ExprId id) {
  return expr_kind(id) == ExprKind::Rational && mpz_cmp_ui(mpq_denref(expr_rat(id)), 1) == 0;
}

bool expr_get_int64(ExprId id, int64_t *out) {
  if (!expr_is_exact_integer(id)) return false;
  mpz_srcptr z = mpq_numref(expr_rat(id));
  if (!mpz_fits_slong_p(z)) return false;
  *out = mpz_get_si(z);
  return true;
}

Value expr_number_value(ExprId id) {
  const ExprNode &n = expr_node(id);
  if (n.kind == ExprKind::Flonum) return Value::flonum(n.d);
  SICM_ASSERT(n.kind == ExprKind::Rational);
  return make_canonical_rational(expr_rat(id)); // the arena's rationals are canonical
}

int expr_number_sign(ExprId id) {
  const ExprNode &n = expr_node(id);
  if (n.kind == ExprKind::Flonum) return n.d > 0 ? 1 : n.d < 0 ? -1 : 0;
  return mpq_sgn(expr_rat(id));
}

bool op_is_rational(Op op) {
  return op == Op::Add || op == Op::Mul || op == Op::Sub || op == Op::Div;
}

bool expr_is_polynomial_power(ExprId id) {
  int64_t e;
  return expr_is_apply(id, Op::Expt) && expr_get_int64(expr_arg(id, 1), &e) &&
         e >= -kMaxExpandedPower && e <= kMaxExpandedPower;
}

bool expr_is_variable(ExprId id) {
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational: return false;
  case ExprKind::Flonum: return !std::isfinite(n.d);
  case ExprKind::Symbol:
  case ExprKind::Call: return true;
  case ExprKind::Apply: return !op_is_rational(n.op) && !expr_is_polynomial_power(id);
  }
  return false;
}

bool expr_is_constant(ExprId id) {
  return expr_is_number(id) && !expr_is_variable(id);
}

std::vector<ExprId> expr_arg_vector(ExprId id) {
  const ExprNode &n = expr_node(id);
  const ExprId *a = expr_args(id);
  return std::vector<ExprId>(a, a + n.nargs);
}

// ---- order -----------------------------------------------------------------

namespace {

int compare_numbers(ExprId a, ExprId b) {
  const ExprNode &na = expr_node(a), &nb = expr_node(b);
  if (na.kind == ExprKind::Rational && nb.kind == ExprKind::Rational)
    return mpq_cmp(expr_rat(a), expr_rat(b));
  double x = na.kind == ExprKind::Flonum ? na.d : mpq_get_d(expr_rat(a));
  double y = nb.kind == ExprKind::Flonum ? nb.d : mpq_get_d(expr_rat(b));
  if (x < y) return -1;
  if (x > y) return 1;
  if (na.kind != nb.kind) return na.kind == ExprKind::Rational ? -1 : 1;
  // Equal flonums that are different nodes: -0. and 0., or NaNs; order by bits.
  uint64_t bx, by;
  std::memcpy(&bx, &na.d, sizeof bx);
  std::memcpy(&by, &nb.d, sizeof by);
  return bx < by ? -1 : bx > by ? 1 : 0;
}

int rank(ExprKind k) {
  switch (k) {
  case ExprKind::Rational:
  case ExprKind::Flonum: return 0;
  case ExprKind::Symbol: return 1;
  case ExprKind::Apply:
  case ExprKind::Call: return 2;
  }
  return 3;
}

// The name of an application's head, or null for a derived-function head.
const char *head_name(const ExprNode &n) {
  if (n.kind == ExprKind::Apply) return op_info(n.op).scheme_name;
  const ExprNode &h = expr_node(n.head);
  return h.kind == ExprKind::Symbol ? h.sym->name.c_str() : nullptr;
}

} // namespace

int expr_compare(ExprId a, ExprId b) {
  if (a == b) return 0;
  const ExprNode &na = expr_node(a), &nb = expr_node(b);
  int ra = rank(na.kind), rb = rank(nb.kind);
  if (ra != rb) return ra < rb ? -1 : 1;
  if (ra == 0) return compare_numbers(a, b);
  if (ra == 1) {
    int c = na.sym->name.compare(nb.sym->name);
    if (c) return c;
    // Distinct symbols with one name (uninterned ones): order by creation.
    return a < b ? -1 : 1;
  }
  const char *ha = head_name(na), *hb = head_name(nb);
  if (!ha || !hb) {
    // A derived-function head ((D f), (expt D 2), ((partial 0) H)) first.
    if (ha) return 1;
    if (hb) return -1;
    int c = expr_compare(na.head, nb.head);
    if (c) return c;
  } else {
    int c = std::strcmp(ha, hb);
    if (c) return c;
    if (na.kind != nb.kind) return na.kind == ExprKind::Apply ? -1 : 1; // (sin x) vs (|sin| x)
    if (na.kind == ExprKind::Call && na.head != nb.head) return na.head < nb.head ? -1 : 1;
  }
  size_t n = std::min(na.nargs, nb.nargs);
  const ExprId *xa = expr_args(a), *xb = expr_args(b);
  for (size_t i = 0; i < n; i++) {
    int c = expr_compare(xa[i], xb[i]);
    if (c) return c;
  }
  if (na.nargs != nb.nargs) return na.nargs < nb.nargs ? -1 : 1;
  return a < b ? -1 : 1; // unreachable for distinct hash-consed nodes
}

// ---- canonical-form checker --------------------------------------------------

namespace {

// Memo of expr_is_canonical: 0 unknown, 1 canonical, 2 not.
std::vector<uint8_t> g_canonical_memo;

// A power's variable and exponent; false if id is not a variable or power.
bool as_power(ExprId id, ExprId *var, int64_t *exp) {
  if (expr_is_variable(id)) {
    *var = id;
    *exp = 1;
    return true;
  }
  if (expr_is_apply(id, Op::Expt) && expr_is_variable(expr_arg(id, 0)) &&
      expr_get_int64(expr_arg(id, 1), exp) && *exp >= 2) {
    *var = expr_arg(id, 0);
    return true;
  }
  return false;
}

// A monomial as (variable, exponent) pairs in increasing variable order, its
// coefficient (kNoExpr for 1) returned in *coeff; false if not a monomial (C4).
bool as_monomial(ExprId id, std::vector<std::pair<ExprId, int64_t>> *powers, ExprId *coeff) {
  powers->clear();
  *coeff = kNoExpr;
  ExprId v;
  int64_t e;
  if (expr_is_constant(id)) {
    *coeff = id;
    return !expr_is_exact_zero(id);
  }
  if (as_power(id, &v, &e)) {
    powers->push_back({v, e});
    return true;
  }
  if (!expr_is_apply(id, Op::Mul)) return false;
  const ExprNode &n = expr_node(id);
  size_t i = 0;
  if (expr_is_constant(expr_arg(id, 0))) {
    *coeff = expr_arg(id, 0);
    if (expr_is_exact_one(*coeff) || expr_is_exact_zero(*coeff)) return false;
    i = 1;
  }
  if (n.nargs - i < 1) return false;
  for (; i < n.nargs; i++) {
    if (!as_power(expr_arg(id, i), &v, &e)) return false;
    if (!powers->empty() && expr_compare(powers->back().first, v) >= 0) return false;
    powers->push_back({v, e});
  }
  return true;
}

// Graded lexicographic comparison of two monomials' exponent vectors.
int compare_monomials(const std::vector<std::pair<ExprId, int64_t>> &a,
                      const std::vector<std::pair<ExprId, int64_t>> &b) {
  int64_t da = 0, db = 0;
  for (auto &p : a)
    da += p.second;
  for (auto &p : b)
    db += p.second;
  if (da != db) return da < db ? -1 : 1;
  size_t i = 0;
  for (; i < a.size() && i < b.size(); i++) {
    int c = expr_compare(a[i].first, b[i].first);
    // The monomial that has the earlier variable has a positive exponent
    // where the other has zero.
    if (c) return c < 0 ? 1 : -1;
    if (a[i].second != b[i].second) return a[i].second < b[i].second ? -1 : 1;
  }
  if (a.size() != b.size()) return a.size() < b.size() ? -1 : 1;
  return 0;
}

// Whether id is a polynomial (C5); reports whether every coefficient is an
// exact integer or a flonum (inexact results are exempt from C6's integrality),
// whether it is a single monomial, and its first coefficient (kNoExpr for 1).
struct PolyFacts {
  bool integer = true;
  bool single = true;
  ExprId first = kNoExpr;
};

bool is_polynomial(ExprId id, PolyFacts *f) {
  std::vector<std::pair<ExprId, int64_t>> prev, cur;
  ExprId coeff;
  auto note = [&](ExprId c) {
    if (c != kNoExpr && expr_kind(c) == ExprKind::Rational && !expr_is_exact_integer(c))
      f->integer = false;
  };
  *f = PolyFacts{};
  if (!expr_is_apply(id, Op::Add)) {
    if (!as_monomial(id, &cur, &coeff)) return false;
    note(coeff);
    f->first = coeff;
    return true;
  }
  f->single = false;
  const ExprNode &n = expr_node(id);
  // A constant term comes first (C5); the others descend.
  uint32_t i = expr_is_constant(expr_arg(id, 0)) ? 1 : 0;
  if (i == 1) note(expr_arg(id, 0));
  for (uint32_t k = i; k < n.nargs; k++) {
    if (!as_monomial(expr_arg(id, k), &cur, &coeff) || expr_is_constant(expr_arg(id, k)))
      return false;
    if (k == i) f->first = coeff;
    note(coeff);
    if (k > i && compare_monomials(prev, cur) <= 0) return false;
    prev.swap(cur);
  }
  return n.nargs - i >= 1;
}

bool check_canonical(ExprId id);

bool kernel_args_canonical(ExprId id) {
  const ExprNode &n = expr_node(id);
  for (uint32_t i = 0; i < n.nargs; i++)
    if (!check_canonical(expr_arg(id, i))) return false;
  return true;
}

// Every variable inside a polynomial or quotient has canonical arguments.
bool variables_canonical(ExprId id) {
  if (expr_is_constant(id)) return true;
  if (expr_is_variable(id))
    return expr_kind(id) == ExprKind::Symbol || expr_kind(id) == ExprKind::Flonum ||
           kernel_args_canonical(id);
  const ExprNode &n = expr_node(id);
  if (n.kind != ExprKind::Apply) return false;
  if (n.op == Op::Expt) return variables_canonical(expr_arg(id, 0));
  for (uint32_t i = 0; i < n.nargs; i++)
    if (!variables_canonical(expr_arg(id, i))) return false;
  return true;
}

bool check_canonical(ExprId id) {
  if (g_canonical_memo.size() <= id) g_canonical_memo.resize(expr_count(), 0);
  if (g_canonical_memo[id]) return g_canonical_memo[id] == 1;
  bool ok;
  PolyFacts nf, df;
  if (expr_is_apply(id, Op::Div)) {
    ExprId num = expr_arg(id, 0), den = expr_arg(id, 1);
    ok = !expr_is_constant(den) && !expr_is_exact_zero(num) && is_polynomial(num, &nf) &&
         is_polynomial(den, &df);
    if (ok && df.single) ok = df.first == kNoExpr; // C6: monomial denominator, coefficient 1
    if (ok && !df.single)
      ok = nf.integer && df.integer && (df.first == kNoExpr || expr_number_sign(df.first) > 0);
    ok = ok && variables_canonical(num) && variables_canonical(den);
  } else {
    ok = expr_is_exact_zero(id) || (is_polynomial(id, &nf) && variables_canonical(id));
  }
  if (g_canonical_memo.size() <= id) g_canonical_memo.resize(expr_count(), 0);
  g_canonical_memo[id] = ok ? 1 : 2;
  return ok;
}

void debug_string(std::string &out, ExprId id) {
  const ExprNode &n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: out += number_to_string(expr_number_value(id)); return;
  case ExprKind::Symbol: out += n.sym->name; return;
  case ExprKind::Apply:
  case ExprKind::Call:
    out += '(';
    if (n.kind == ExprKind::Apply)
      out += op_info(n.op).scheme_name;
    else
      debug_string(out, n.head);
    for (uint32_t i = 0; i < n.nargs; i++) {
      out += ' ';
      debug_string(out, expr_arg(id, i));
    }
    out += ')';
    return;
  }
}

} // namespace

bool expr_is_canonical(ExprId id) {
  return check_canonical(id);
}

std::string expr_debug_string(ExprId id) {
  std::string s;
  debug_string(s, id);
  return s;
}

} // namespace sicm
