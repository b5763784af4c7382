// Linear solves as expression nodes (see linear_solve.hpp).
#include "algebra/linear_solve.hpp"

#include <algorithm>
#include <vector>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"

namespace sicm {

namespace {

thread_local int g_kernel_tracing = 0;

// A component that can stand in an expression: a number, a symbol or an
// expression (not a structure, a differential, a function).
bool is_scalar(Value v) {
  return is_number(v) || is_symbolic(v);
}

ExprId scalar_expr(Value v) {
  if (is_number(v)) return expr_from_number(v);
  if (v.is(Tag::Symbol)) return expr_symbol(v.symbol());
  return static_cast<ExprId>(v.i);
}

// A symbolic value of an expression node (numbers never reach here: a
// solve node is a Call).
Value call_value(ExprId id) {
  Value v;
  v.tag = Tag::Expr;
  v.i = id;
  return v;
}

// Should the n x n matrix entry(i, j) be left to a run-time factorization?
// Not when symbolic inversion is cheap: numbers only, diagonal, or small.
// A small matrix goes to a solve node only when it is singular whatever
// the inputs (its determinant simplifies to 0): symbolic inversion would
// fail at compile time, where the factorization fails when the kernel
// runs, with the time and the state (a Lagrangian whose velocities do not
// all appear squared).
template <typename Entry> bool wants_solve(size_t n, Entry entry) {
  if (g_kernel_tracing == 0) return false;
  bool all_numbers = true, diagonal = true;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      Value e = entry(i, j);
      if (!is_scalar(e)) return false;
      all_numbers = all_numbers && is_number(e);
      diagonal = diagonal && (i == j || is_exact_zero(e));
    }
  if (all_numbers || diagonal) return false;
  if (n > kMaxSymbolicSolve) return true;
  Value m = make_matrix(n, n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      matrix_at(as_matrix(m), i, j) = entry(i, j);
  Value det = determinant(m);
  return is_number(det) ? num_is_zero(det) : g_zero_p(simplify_value(det));
}

// Is the n x n matrix entry(i, j) made of numbers and run-time values, at
// least one of them a run-time value, outside a kernel in sicm build?
template <typename Entry> bool wants_interpreted_solve(size_t n, Entry entry) {
  RunTimeValueTest is_run_time = run_time_value_test();
  if (g_kernel_tracing != 0 || !is_run_time) return false;
  bool run_time = false;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      Value e = entry(i, j);
      if (!is_number(e) && !is_run_time(e)) return false;
      run_time = run_time || !is_number(e);
    }
  return run_time;
}

// The solution of M x = b as a structure of solve nodes with the given head
// (orientation up or down), M given by entry(i, j).
template <typename Entry>
Value solve_structure(size_t n, Entry entry, const Value *b, bool result_up,
                      ExprId head = solve_head()) {
  std::vector<ExprId> args;
  args.reserve(1 + n * n + n);
  args.push_back(expr_integer(0));
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      args.push_back(scalar_expr(entry(i, j)));
  for (size_t i = 0; i < n; ++i)
    args.push_back(scalar_expr(b[i]));
  gcvec<Value> x(n);
  for (size_t k = 0; k < n; ++k) {
    args[0] = expr_integer(static_cast<int64_t>(k));
    x[k] = call_value(expr_call(head, args.data(), args.size()));
  }
  return make_structure_from(result_up, x.data(), n);
}

// C x = b for the n x n matrix c (row-major values, C(i, j) = c[i n + j]):
// solve nodes when there are no differentials and the kernel should factor
// C, else the symbolic inverse as before. Through differentials, by the
// rule d(C^-1 b) = C^-1 (db - dC x0), x0 = C0^-1 b0, split on the largest
// tag (or its whole gradient group): every tangent solves with the same
// finite matrix C0, which the emitter factors once.
gcvec<Value> solve_values(size_t n, const gcvec<Value> &c, const gcvec<Value> &b) {
  uint32_t e = 0;
  for (Value v : c)
    e = std::max(e, max_differential_tag(v));
  for (Value v : b)
    e = std::max(e, max_differential_tag(v));
  if (e == 0) {
    auto entry = [&](size_t i, size_t j) { return c[i * n + j]; };
    Value x;
    if (wants_solve(n, entry)) {
      x = solve_structure(n, entry, b.data(), true);
    } else {
      Value m = make_matrix(n, n);
      std::copy(c.begin(), c.end(), as_matrix(m)->items);
      x = g_mul(matrix_inverse(m, "/"), make_structure_from(true, b.data(), n));
    }
    return gcvec<Value>(as_structure(x)->items, as_structure(x)->items + n);
  }
  // The finite parts, and per tag the tangents (zero where a value lacks it).
  gcvec<Value> c0(n * n), b0(n), dc, db, keep;
  std::vector<uint32_t> tags;
  auto slot = [&](uint32_t tag) {
    size_t t = std::find(tags.begin(), tags.end(), tag) - tags.begin();
    if (t == tags.size()) {
      tags.push_back(tag);
      dc.resize(tags.size() * n * n, Value::fixnum(0));
      db.resize(tags.size() * n, Value::fixnum(0));
    }
    return t;
  };
  std::vector<std::pair<uint32_t, Value>> parts;
  for (size_t k = 0; k < n * n; ++k) {
    parts.clear();
    split_by_tag(c[k], e, &c0[k], parts, keep);
    for (auto &[tag, tangent] : parts)
      dc[slot(tag) * n * n + k] = tangent;
  }
  for (size_t i = 0; i < n; ++i) {
    parts.clear();
    split_by_tag(b[i], e, &b0[i], parts, keep);
    for (auto &[tag, tangent] : parts)
      db[slot(tag) * n + i] = tangent;
  }
  gcvec<Value> x0 = solve_values(n, c0, b0), x = x0;
  for (size_t t = 0; t < tags.size(); ++t) {
    gcvec<Value> r(n);
    for (size_t i = 0; i < n; ++i) {
      Value ri = db[t * n + i];
      for (size_t j = 0; j < n; ++j)
        ri = g_sub(ri, g_mul(dc[t * n * n + i * n + j], x0[j]));
      r[i] = ri;
    }
    gcvec<Value> xt = solve_values(n, c0, r);
    for (size_t i = 0; i < n; ++i)
      x[i] = g_add(x[i], times_infinitesimal(xt[i], tags[t]));
  }
  return x;
}

// Scalars and differentials of scalars: what solve_values takes.
bool is_solvable(Value v) {
  return is_scalar(v) || is_differential(v);
}

// C x = b in a kernel through differentials (see solve_values), when C is
// larger than kMaxSymbolicSolve: the symbolic inverse of a matrix of
// differentials grows as fast as that of expressions.
template <typename Entry>
std::optional<gcvec<Value>> differential_solve(size_t n, Entry entry, const Value *b) {
  if (g_kernel_tracing == 0 || n <= kMaxSymbolicSolve) return std::nullopt;
  bool differentials = false;
  gcvec<Value> c(n * n), rhs(b, b + n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      c[i * n + j] = entry(i, j);
      if (!is_solvable(c[i * n + j])) return std::nullopt;
      differentials = differentials || is_differential(c[i * n + j]);
    }
  for (Value v : rhs) {
    if (!is_solvable(v)) return std::nullopt;
    differentials = differentials || is_differential(v);
  }
  if (!differentials) return std::nullopt;
  return solve_values(n, c, rhs);
}

bool all_scalars(const Value *items, size_t n) {
  return std::all_of(items, items + n, is_scalar);
}

bool all_numbers_or_run_time(const Value *items, size_t n) {
  RunTimeValueTest is_run_time = run_time_value_test();
  return std::all_of(items, items + n,
                     [&](Value v) { return is_number(v) || (is_run_time && is_run_time(v)); });
}

// M x = b, M given by entry(i, j), as solve nodes (see traced_solve).
template <typename Entry>
std::optional<gcvec<Value>> traced_solve_of(size_t n, Entry entry, const Value *b) {
  if (g_kernel_tracing == 0 && !run_time_value_test()) return std::nullopt;
  if (std::optional<gcvec<Value>> x = differential_solve(n, entry, b)) return x;
  if (!all_scalars(b, n)) return std::nullopt;
  Value x;
  if (wants_interpreted_solve(n, entry) && all_numbers_or_run_time(b, n))
    x = solve_structure(n, entry, b, true, interpreted_solve_head());
  else if (wants_solve(n, entry))
    x = solve_structure(n, entry, b, true);
  else
    return std::nullopt;
  return gcvec<Value>(as_structure(x)->items, as_structure(x)->items + n);
}

} // namespace

KernelTracing::KernelTracing() {
  ++g_kernel_tracing;
}

KernelTracing::~KernelTracing() {
  --g_kernel_tracing;
}

ExprId solve_head() {
  // A global: the collector scans it, so the uninterned symbol lives.
  static Value head = make_uninterned_symbol("solve");
  return expr_symbol(head.symbol());
}

ExprId interpreted_solve_head() {
  static Value head = make_uninterned_symbol("solve-as-interpreted");
  return expr_symbol(head.symbol());
}

bool is_solve_node(ExprId id) {
  if (expr_kind(id) != ExprKind::Call) return false;
  ExprId head = expr_node(id).head;
  return head == solve_head() || head == interpreted_solve_head();
}

bool is_interpreted_solve(ExprId id) {
  return expr_kind(id) == ExprKind::Call && expr_node(id).head == interpreted_solve_head();
}

size_t solve_dimension(ExprId id) {
  // nargs = 1 + n^2 + n
  size_t rest = expr_node(id).nargs - 1, n = 0;
  while (n * n + n < rest)
    ++n;
  return n;
}

size_t solve_component(ExprId id) {
  int64_t k = 0;
  expr_get_int64(expr_arg(id, 0), &k);
  return static_cast<size_t>(k);
}

ExprId solve_matrix_entry(ExprId id, size_t i, size_t j) {
  return expr_arg(id, 1 + i * solve_dimension(id) + j);
}

ExprId solve_rhs_entry(ExprId id, size_t i) {
  size_t n = solve_dimension(id);
  return expr_arg(id, 1 + n * n + i);
}

std::optional<gcvec<Value>> traced_solve(size_t n, const gcvec<Value> &m, const Value *b) {
  return traced_solve_of(
      n, [&](size_t i, size_t j) { return m[i * n + j]; }, b);
}

// (/ a m) with a an up is m^-1 a, an up (matrix_div and matrix_times_up).
std::optional<Value> traced_matrix_solve(Value a, Value m) {
  if ((g_kernel_tracing == 0 && !run_time_value_test()) || !is_structure(a) || !is_matrix(m))
    return std::nullopt;
  Matrix *mm = as_matrix(m);
  Structure *av = as_structure(a);
  size_t n = mm->rows;
  if (mm->cols != n || !av->up || av->len != n) return std::nullopt;
  std::optional<gcvec<Value>> x = traced_solve_of(
      n, [&](size_t i, size_t j) { return matrix_at(mm, i, j); }, av->items);
  if (!x) return std::nullopt;
  return make_structure_from(true, x->data(), n);
}

} // namespace sicm
