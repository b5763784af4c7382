// Up/down structures and matrices: construction, shapes, arithmetic, contraction, linear
// algebra. Their primitives are structure_primitives.cpp.
#include "algebra/structure.hpp"
#include "algebra/structure_internal.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/series.hpp"
#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

// ---- construction -----------------------------------------------------------------------------

namespace {

Value *gc_values(size_t n) {
  auto *items = static_cast<Value *>(GC_MALLOC((n ? n : 1) * sizeof(Value)));
  if (!items) throw std::bad_alloc();
  for (size_t i = 0; i < n; ++i)
    new (&items[i]) Value();
  return items;
}

} // namespace

Value make_structure(bool up, size_t len) {
  return Value::object(Tag::Structure, gc_new<Structure>(Structure{up, gc_values(len), len}));
}

Value make_structure_from(bool up, const Value *items, size_t len) {
  Value v = make_structure(up, len);
  std::copy(items, items + len, as_structure(v)->items);
  return v;
}

Value make_matrix(size_t rows, size_t cols) {
  Value *items = gc_values(rows * cols);
  for (size_t k = 0; k < rows * cols; ++k)
    items[k] = Value::fixnum(0);
  return Value::object(Tag::Matrix, gc_new<Matrix>(Matrix{rows, cols, items}));
}

// ---- shapes -----------------------------------------------------------------------------------

size_t structure_dimension(Value v) {
  if (!is_structure(v)) return 1;
  Structure *s = as_structure(v);
  size_t n = 0;
  for (size_t i = 0; i < s->len; ++i)
    n += structure_dimension(s->items[i]);
  return n;
}

void structure_leaves(Value v, gcvec<Value> &out) {
  if (!is_structure(v)) {
    out.push_back(v);
    return;
  }
  Structure *s = as_structure(v);
  for (size_t i = 0; i < s->len; ++i)
    structure_leaves(s->items[i], out);
}

namespace {

Value rebuild_shape(Value shape, bool dual, const Value *leaves, size_t &pos) {
  if (!is_structure(shape)) return leaves[pos++];
  Structure *s = as_structure(shape);
  return generate_structure(s->up != dual, s->len, [&](size_t i) {
    return rebuild_shape(s->items[i], dual, leaves, pos);
  });
}

} // namespace

[[noreturn]] void shape_mismatch(const char *who, Value a, Value b) {
  runtime_error(current_call_loc(), "The shapes of " + write_string(a) + " and " + write_string(b) +
                                        ", passed to " + who + ", do not match.");
}

Value shape_from_leaves(Value shape, bool dual, const Value *leaves) {
  size_t pos = 0;
  return rebuild_shape(shape, dual, leaves, pos);
}

// ---- structure arithmetic ---------------------------------------------------------------------

namespace {

bool compatible_for_contraction(const Structure *s, const Structure *t) {
  if (s->up == t->up || s->len != t->len) return false;
  for (size_t i = 0; i < s->len; ++i) {
    Value x = s->items[i], y = t->items[i];
    if (is_structure(x) && is_structure(y) &&
        !compatible_for_contraction(as_structure(x), as_structure(y)))
      return false;
  }
  return true;
}

Value componentwise(BinaryOp op, Value a, Value b) {
  Structure *s = as_structure(a), *t = as_structure(b);
  if (s->up != t->up || s->len != t->len) shape_mismatch(op_scheme_name(op), a, b);
  return generate_structure(s->up, s->len,
                            [&](size_t i) { return g_binary(op, s->items[i], t->items[i]); });
}

// scmutils' square of a structure: the sum of the squares of its components,
// so (square v) is v.v for an up or a down of any nesting.
Value structure_square(Value v) {
  Structure *s = as_structure(v);
  Value sum = Value::fixnum(0);
  for (size_t i = 0; i < s->len; ++i)
    sum = g_add(sum, g_square(s->items[i]));
  return sum;
}

bool structures_equal(Value a, Value b) {
  Structure *s = as_structure(a), *t = as_structure(b);
  if (s->up != t->up || s->len != t->len) return false;
  for (size_t i = 0; i < s->len; ++i)
    if (!g_equal(s->items[i], t->items[i])) return false;
  return true;
}

bool all_zero(const Value *items, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!g_zero_p(items[i])) return false;
  return true;
}

// x^n for structures and matrices; a negative n inverts first, and (expt x 0)
// is 1, the multiplicative identity of any shape. Matrix products associate,
// so matrices square and multiply; products of structures need not, so they
// multiply left to right: (expt s 3) is (* (* s s) s).
Value integer_power(Value x, Value exponent, BinaryOp op) {
  auto n = to_int64(exponent);
  if (!n) arith_wrong_type(op, exponent, 2);
  if (*n < 0) return integer_power(g_unary(UnaryOp::Invert, x), num_neg(exponent), op);
  Value acc = Value::fixnum(1);
  if (is_matrix(x)) {
    for (uint64_t k = static_cast<uint64_t>(*n); k; k >>= 1, x = k ? g_mul(x, x) : x)
      if (k & 1) acc = g_mul(acc, x);
    return acc;
  }
  for (int64_t i = 0; i < *n; ++i)
    acc = g_mul(acc, x);
  return acc;
}

Value structure_binary_ops(BinaryOp op, Value a, Value b) {
  bool sa = is_structure(a), sb = is_structure(b);
  switch (op) {
  case BinaryOp::Add:
  case BinaryOp::Sub:
    if (sa && sb) return componentwise(op, a, b);
    if (is_procedure(a) || is_procedure(b)) return function_combination(op, a, b);
    arith_wrong_type(op, sa ? a : b, sa ? 1 : 2);
  case BinaryOp::Mul: return structure_mul(a, b);
  case BinaryOp::Div:
    if (!sb) return map_structure(a, [&](Value x) { return g_div(x, b); });
    return divide_by_structure(a, b);
  case BinaryOp::Expt:
    if (sb) arith_wrong_type(op, b, 2);
    return integer_power(a, b, op);
  case BinaryOp::Atan2: arith_wrong_type(op, sa ? a : b, sa ? 1 : 2);
  case BinaryOp::Equal: return Value::boolean(sa && sb && structures_equal(a, b));
  }
  SICM_ASSERT(false);
  return a;
}

Value structure_unary_ops(UnaryOp op, Value x) {
  switch (op) {
  case UnaryOp::Neg: return map_structure(x, g_neg);
  case UnaryOp::Invert: return structure_inverse(x, "/");
  case UnaryOp::Square: return structure_square(x);
  case UnaryOp::Cube: return g_mul(x, g_mul(x, x));
  case UnaryOp::Abs:
  case UnaryOp::Magnitude: return g_unary(UnaryOp::Sqrt, structure_square(x));
  case UnaryOp::ZeroP: {
    Structure *s = as_structure(x);
    return Value::boolean(all_zero(s->items, s->len));
  }
  default: arith_wrong_type(op, x);
  }
}

} // namespace

Value structure_mul(Value a, Value b) {
  if (!is_structure(b)) return map_structure(a, [&](Value x) { return g_mul(x, b); });
  Structure *t = as_structure(b);
  if (is_structure(a) && compatible_for_contraction(as_structure(a), t)) {
    Structure *s = as_structure(a);
    Value sum = Value::fixnum(0);
    for (size_t i = 0; i < s->len; ++i)
      sum = g_add(sum, g_mul(s->items[i], t->items[i]));
    return sum;
  }
  return generate_structure(t->up, t->len, [&](size_t i) { return g_mul(a, t->items[i]); });
}

// ---- matrix arithmetic ------------------------------------------------------------------------

namespace {

Value matrix_elementwise(BinaryOp op, Value a, Value b) {
  Matrix *m = as_matrix(a), *n = as_matrix(b);
  if (m->rows != n->rows || m->cols != n->cols) shape_mismatch(op_scheme_name(op), a, b);
  return generate_matrix(m->rows, m->cols, [&](size_t i, size_t j) {
    return g_binary(op, matrix_at(m, i, j), matrix_at(n, i, j));
  });
}

Value matrix_product(Value a, Value b) {
  Matrix *m = as_matrix(a), *n = as_matrix(b);
  if (m->cols != n->rows) shape_mismatch("*", a, b);
  return generate_matrix(m->rows, n->cols, [&](size_t i, size_t j) {
    Value sum = Value::fixnum(0);
    for (size_t k = 0; k < m->cols; ++k)
      sum = g_add(sum, g_mul(matrix_at(m, i, k), matrix_at(n, k, j)));
    return sum;
  });
}

// M v for an up v with one component per column: an up, one per row.
Value matrix_times_up(Value mv, Value v) {
  Matrix *m = as_matrix(mv);
  Structure *s = as_structure(v);
  if (!s->up || s->len != m->cols) shape_mismatch("*", mv, v);
  return generate_structure(true, m->rows, [&](size_t i) {
    Value sum = Value::fixnum(0);
    for (size_t j = 0; j < m->cols; ++j)
      sum = g_add(sum, g_mul(matrix_at(m, i, j), s->items[j]));
    return sum;
  });
}

// p M for a down p with one component per row: a down, one per column.
Value down_times_matrix(Value p, Value mv) {
  Matrix *m = as_matrix(mv);
  Structure *s = as_structure(p);
  if (s->up || s->len != m->rows) shape_mismatch("*", p, mv);
  return generate_structure(false, m->cols, [&](size_t j) {
    Value sum = Value::fixnum(0);
    for (size_t i = 0; i < m->rows; ++i)
      sum = g_add(sum, g_mul(s->items[i], matrix_at(m, i, j)));
    return sum;
  });
}

Value matrix_mul(Value a, Value b) {
  bool ma = is_matrix(a), mb = is_matrix(b);
  if (ma && mb) return matrix_product(a, b);
  if (ma && is_structure(b)) return matrix_times_up(a, b);
  if (mb && is_structure(a)) return down_times_matrix(a, b);
  if (ma) return map_matrix(a, [&](Value x) { return g_mul(x, b); });
  return map_matrix(b, [&](Value x) { return g_mul(a, x); });
}

Value matrix_div(Value a, Value b) {
  if (!is_matrix(b)) {
    if (is_structure(b)) shape_mismatch("/", a, b);
    return map_matrix(a, [&](Value x) { return g_div(x, b); });
  }
  if (std::optional<Value> solved = traced_matrix_solve(a, b)) return *solved;
  Value inverse = matrix_inverse(b, "/");
  if (is_structure(a)) return g_mul(inverse, a);
  return g_mul(a, inverse);
}

bool matrices_equal(Value a, Value b) {
  Matrix *m = as_matrix(a), *n = as_matrix(b);
  if (m->rows != n->rows || m->cols != n->cols) return false;
  for (size_t k = 0; k < m->rows * m->cols; ++k)
    if (!g_equal(m->items[k], n->items[k])) return false;
  return true;
}

Value matrix_binary_ops(BinaryOp op, Value a, Value b) {
  bool ma = is_matrix(a), mb = is_matrix(b);
  switch (op) {
  case BinaryOp::Add:
  case BinaryOp::Sub:
    if (ma && mb) return matrix_elementwise(op, a, b);
    if (is_structure(a) || is_structure(b)) shape_mismatch(op_scheme_name(op), a, b);
    if (is_procedure(a) || is_procedure(b)) return function_combination(op, a, b);
    arith_wrong_type(op, ma ? a : b, ma ? 1 : 2);
  case BinaryOp::Mul: return matrix_mul(a, b);
  case BinaryOp::Div: return matrix_div(a, b);
  case BinaryOp::Expt:
    if (mb) arith_wrong_type(op, b, 2);
    return integer_power(a, b, op);
  case BinaryOp::Atan2: arith_wrong_type(op, ma ? a : b, ma ? 1 : 2);
  case BinaryOp::Equal: return Value::boolean(ma && mb && matrices_equal(a, b));
  }
  SICM_ASSERT(false);
  return a;
}

Value matrix_unary_ops(UnaryOp op, Value x) {
  switch (op) {
  case UnaryOp::Neg: return map_matrix(x, g_neg);
  case UnaryOp::Invert: return matrix_inverse(x, "/");
  case UnaryOp::Square: return matrix_product(x, x);
  case UnaryOp::Cube: return matrix_product(x, matrix_product(x, x));
  case UnaryOp::ZeroP: {
    Matrix *m = as_matrix(x);
    return Value::boolean(all_zero(m->items, m->rows * m->cols));
  }
  default: arith_wrong_type(op, x);
  }
}

// ---- the arithmetic type ----

bool is_structure_or_matrix(Value v) {
  return is_structure(v) || is_matrix(v);
}

Value structural_unary(UnaryOp op, Value x) {
  return is_matrix(x) ? matrix_unary_ops(op, x) : structure_unary_ops(op, x);
}

// The other operand is a structure, a matrix, or a value of lower rank (a
// number or an expression, taken as a scalar); anything else is an error.
Value structural_binary(BinaryOp op, Value a, Value b) {
  if (!is_arithmetic(a)) arith_wrong_type(op, a, 1);
  if (!is_arithmetic(b)) arith_wrong_type(op, b, 2);
  if (is_matrix(a) || is_matrix(b)) return matrix_binary_ops(op, a, b);
  return structure_binary_ops(op, a, b);
}

const ArithType kStructureType = {"structure", 32, is_structure_or_matrix, structural_unary,
                                  structural_binary};

} // namespace

void register_structure_arith() {
  register_arith_type(&kStructureType);
}

// ---- linear algebra ---------------------------------------------------------------------------
//
// Exact Gaussian elimination with the generic operations, so that it works on
// exact rationals, flonums and expressions alike. A pivot must be non-zero:
// among numbers the largest in magnitude is taken (partial pivoting, for
// flonums' sake); among expressions the first that does not simplify to zero.
// Expression entries are simplified after every step, which keeps them small
// and lets a zero show itself as the number 0.

namespace {

constexpr size_t kNoPivot = SIZE_MAX;
// Symbolic determinants up to this size expand by minors, which yields a
// polynomial directly; larger ones use fraction-free (Bareiss) elimination.
constexpr size_t kLaplaceLimit = 4;

struct Dense {
  size_t rows, cols;
  gcvec<Value> a;
  Dense(size_t r, size_t c) : rows(r), cols(c), a(r * c, Value::fixnum(0)) {}
  Value &at(size_t i, size_t j) { return a[i * cols + j]; }
};

Dense dense_of(Value mv) {
  Matrix *m = as_matrix(mv);
  Dense d(m->rows, m->cols);
  std::copy(m->items, m->items + m->rows * m->cols, d.a.begin());
  return d;
}

Value tidy(Value v) {
  return v.is(Tag::Expr) ? simplify_value(v) : v;
}

bool all_numbers(Dense &d) {
  return std::all_of(d.a.begin(), d.a.end(), [](Value v) { return is_number(v); });
}

size_t choose_pivot(Dense &d, size_t col, size_t from) {
  bool numeric = true;
  for (size_t r = from; r < d.rows; ++r)
    numeric = numeric && is_number(d.at(r, col));
  size_t best = kNoPivot;
  for (size_t r = from; r < d.rows; ++r) {
    Value x = d.at(r, col);
    if (!numeric) {
      if (!g_zero_p(x)) return r;
    } else if (!num_is_zero(x) &&
               (best == kNoPivot || num_compare(num_abs(x), num_abs(d.at(best, col))) > 0)) {
      best = r;
    }
  }
  return best;
}

void swap_rows(Dense &d, size_t i, size_t j) {
  for (size_t k = 0; k < d.cols; ++k)
    std::swap(d.at(i, k), d.at(j, k));
}

[[noreturn]] void singular(const char *who) {
  runtime_error(current_call_loc(), std::string(who) + ": the matrix is singular");
}

// Gauss-Jordan on [A | I]: column c of row r loses f times the pivot row.
void eliminate_column(Dense &d, size_t c) {
  Value pivot = d.at(c, c);
  for (size_t j = c; j < d.cols; ++j)
    d.at(c, j) = tidy(g_div(d.at(c, j), pivot));
  for (size_t r = 0; r < d.rows; ++r) {
    Value f = d.at(r, c);
    if (r == c || is_exact_zero(f)) continue;
    for (size_t j = c; j < d.cols; ++j)
      d.at(r, j) = tidy(g_sub(d.at(r, j), g_mul(f, d.at(c, j))));
  }
}

Value numeric_determinant(Dense &d) {
  Value det = Value::fixnum(1);
  for (size_t c = 0; c < d.rows; ++c) {
    size_t p = choose_pivot(d, c, c);
    if (p == kNoPivot) return num_mul(det, Value::fixnum(0));
    if (p != c) {
      swap_rows(d, p, c);
      det = num_neg(det);
    }
    Value pivot = d.at(c, c);
    det = num_mul(det, pivot);
    for (size_t r = c + 1; r < d.rows; ++r) {
      Value f = num_div(d.at(r, c), pivot);
      if (num_is_zero(f)) continue;
      for (size_t j = c + 1; j < d.cols; ++j)
        d.at(r, j) = num_sub(d.at(r, j), num_mul(f, d.at(c, j)));
    }
  }
  return det;
}

// Expansion by minors along row `row`, over the columns still in `cols`.
Value laplace_determinant(Dense &d, size_t row, std::vector<size_t> &cols) {
  if (cols.size() == 1) return d.at(row, cols[0]);
  Value sum = Value::fixnum(0);
  for (size_t k = 0; k < cols.size(); ++k) {
    Value e = d.at(row, cols[k]);
    if (is_exact_zero(e)) continue;
    size_t col = cols[k];
    cols.erase(cols.begin() + static_cast<long>(k));
    Value term = g_mul(e, laplace_determinant(d, row + 1, cols));
    cols.insert(cols.begin() + static_cast<long>(k), col);
    sum = k % 2 == 0 ? g_add(sum, term) : g_sub(sum, term);
  }
  return sum;
}

// Bareiss: every division is exact, so expression entries stay polynomials
// once simplified.
Value bareiss_determinant(Dense &d) {
  size_t n = d.rows;
  bool negate = false;
  Value previous = Value::fixnum(1);
  for (size_t k = 0; k + 1 < n; ++k) {
    size_t p = choose_pivot(d, k, k);
    if (p == kNoPivot) return Value::fixnum(0);
    if (p != k) {
      swap_rows(d, p, k);
      negate = !negate;
    }
    for (size_t i = k + 1; i < n; ++i)
      for (size_t j = k + 1; j < n; ++j) {
        Value cross = g_sub(g_mul(d.at(i, j), d.at(k, k)), g_mul(d.at(i, k), d.at(k, j)));
        d.at(i, j) = tidy(g_div(cross, previous));
      }
    previous = d.at(k, k);
  }
  Value det = d.at(n - 1, n - 1);
  return negate ? g_neg(det) : det;
}

Value dense_determinant(Dense &d) {
  if (d.rows == 0) return Value::fixnum(1);
  if (all_numbers(d)) return numeric_determinant(d);
  if (d.rows <= kLaplaceLimit) {
    std::vector<size_t> cols(d.cols);
    for (size_t j = 0; j < d.cols; ++j)
      cols[j] = j;
    return laplace_determinant(d, 0, cols);
  }
  return bareiss_determinant(d);
}

} // namespace

Value matrix_inverse(Value mv, const char *who) {
  Matrix *m = as_matrix(mv);
  if (m->rows != m->cols) wrong_type(mv, 1, who);
  size_t n = m->rows;
  Dense d(n, 2 * n);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j)
      d.at(i, j) = matrix_at(m, i, j);
    d.at(i, n + i) = Value::fixnum(1);
  }
  for (size_t c = 0; c < n; ++c) {
    size_t p = choose_pivot(d, c, c);
    if (p == kNoPivot) singular(who);
    swap_rows(d, p, c);
    eliminate_column(d, c);
  }
  return generate_matrix(n, n, [&](size_t i, size_t j) { return d.at(i, n + j); });
}

Value determinant(Value x) {
  if (is_matrix(x)) {
    if (as_matrix(x)->rows != as_matrix(x)->cols) wrong_type(x, 1, "determinant");
    Dense d = dense_of(x);
    return dense_determinant(d);
  }
  if (is_structure(x)) return structure_determinant(x);
  if (is_number(x) || is_symbolic(x)) return x;
  wrong_type(x, 1, "determinant");
}

} // namespace sicm
