// Up/down structures and matrices: construction, printing, contraction, linear algebra, primitives.
#include "algebra/structure.hpp"

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

template <class F> Value generate_structure(bool up, size_t len, F f) {
  Value r = make_structure(up, len);
  Structure *s = as_structure(r);
  for (size_t i = 0; i < len; ++i)
    s->items[i] = f(i);
  return r;
}

template <class F> Value map_structure(Value v, F f) {
  Structure *s = as_structure(v);
  return generate_structure(s->up, s->len, [&](size_t i) { return f(s->items[i]); });
}

template <class F> Value generate_matrix(size_t rows, size_t cols, F f) {
  Value r = make_matrix(rows, cols);
  Matrix *m = as_matrix(r);
  for (size_t i = 0; i < rows; ++i)
    for (size_t j = 0; j < cols; ++j)
      matrix_at(m, i, j) = f(i, j);
  return r;
}

template <class F> Value map_matrix(Value v, F f) {
  Matrix *m = as_matrix(v);
  return generate_matrix(m->rows, m->cols,
                         [&](size_t i, size_t j) { return f(matrix_at(m, i, j)); });
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

// ---- printing ---------------------------------------------------------------------------------

namespace {

// (up a b) and (matrix-by-rows (list a b) (list c d)), as scmutils prints
// them; the components keep their own printers (expressions print simplified).
Value structure_to_datum(Value v) {
  Structure *s = as_structure(v);
  return cons(intern(s->up ? "up" : "down"), list_from(s->items, s->len));
}

Value matrix_to_datum(Value v) {
  Matrix *m = as_matrix(v);
  Value list_sym = intern("list");
  Value rows = Value::nil();
  for (size_t i = m->rows; i-- > 0;)
    rows = cons(cons(list_sym, list_from(&matrix_at(m, i, 0), m->cols)), rows);
  return cons(intern("matrix-by-rows"), rows);
}

} // namespace

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

// The structure of `shape` with a 1 at leaf k and exact zeros elsewhere.
Value basis_element(Value shape, size_t k) {
  gcvec<Value> leaves(structure_dimension(shape), Value::fixnum(0));
  leaves[k] = Value::fixnum(1);
  return shape_from_leaves(shape, false, leaves.data());
}

[[noreturn]] void shape_mismatch(const char *who, Value a, Value b) {
  runtime_error(current_call_loc(), "The shapes of " + write_string(a) + " and " + write_string(b) +
                                        ", passed to " + who + ", do not match.");
}

} // namespace

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

// (/ a s): a times the inverse of s; an up is solved for on the right of the
// inverse, as the book writes a column vector.
Value divide_by_structure(Value a, Value s) {
  if (std::optional<Value> solved = traced_structure_solve(a, s)) return *solved;
  Value inverse = structure_inverse(s, "/");
  if (is_structure(a) && as_structure(a)->up) return g_mul(inverse, a);
  return g_mul(a, inverse);
}

Value structure_binary_ops(BinaryOp op, Value a, Value b) {
  bool sa = is_structure(a), sb = is_structure(b);
  switch (op) {
  case BinaryOp::Add:
  case BinaryOp::Sub:
    if (sa && sb) return componentwise(op, a, b);
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

// A structure of n > 0 structures of one orientation and one length m: a
// linear map, whose matrix (m x n) has the components as its columns.
bool is_two_tensor(Value v) {
  if (!is_structure(v) || as_structure(v)->len == 0) return false;
  Structure *s = as_structure(v);
  if (!is_structure(s->items[0])) return false;
  Structure *first = as_structure(s->items[0]);
  for (size_t i = 0; i < s->len; ++i) {
    if (!is_structure(s->items[i])) return false;
    Structure *c = as_structure(s->items[i]);
    if (c->up != first->up || c->len != first->len) return false;
  }
  return true;
}

Dense two_tensor_columns(Value v) {
  Structure *s = as_structure(v);
  size_t m = as_structure(s->items[0])->len;
  Dense d(m, s->len);
  for (size_t j = 0; j < s->len; ++j)
    for (size_t i = 0; i < m; ++i)
      d.at(i, j) = as_structure(s->items[j])->items[i];
  return d;
}

Value matrix_of(Dense &d) {
  return generate_matrix(d.rows, d.cols, [&](size_t i, size_t j) { return d.at(i, j); });
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

// The inverse map of a square two-tensor S: it takes what S produces (vectors
// of S's inner orientation) back to what S takes (the dual of S's outer
// orientation), so its orientations are the duals of S's, exchanged.
Value structure_inverse(Value s, const char *who) {
  if (!is_two_tensor(s) || as_structure(as_structure(s)->items[0])->len != as_structure(s)->len)
    runtime_error(current_call_loc(), std::string(who) + ": cannot invert " + write_string(s) +
                                          ": only a square structure of structures (such as a "
                                          "down of downs) is a linear map that can be");
  Dense columns = two_tensor_columns(s);
  Matrix *inverse = as_matrix(matrix_inverse(matrix_of(columns), who));
  Structure *st = as_structure(s);
  bool outer_up = st->up, inner_up = as_structure(st->items[0])->up;
  size_t n = st->len;
  return generate_structure(!inner_up, n, [&](size_t k) {
    return generate_structure(!outer_up, n, [&](size_t i) { return matrix_at(inverse, i, k); });
  });
}

Value determinant(Value x) {
  if (is_matrix(x)) {
    if (as_matrix(x)->rows != as_matrix(x)->cols) wrong_type(x, 1, "determinant");
    Dense d = dense_of(x);
    return dense_determinant(d);
  }
  if (is_two_tensor(x)) {
    Dense d = two_tensor_columns(x);
    if (d.rows != d.cols) wrong_type(x, 1, "determinant");
    return dense_determinant(d);
  }
  if (is_number(x) || is_symbolic(x)) return x;
  wrong_type(x, 1, "determinant");
}

// ---- primitives: structures -------------------------------------------------------------------

namespace {

size_t index_arg(Value idx, int argpos, const char *who) {
  if (!is_exact_integer(idx) || num_sign(idx) < 0) wrong_type(idx, argpos, who);
  auto i = to_int64(idx);
  if (!i) bad_range(idx, argpos, who);
  return static_cast<size_t>(*i);
}

Value list_ref_checked(Value list, size_t i, Value idx, int argpos, const char *who) {
  for (; i > 0 && is_pair(list); --i)
    list = cdr(list);
  if (!is_pair(list)) bad_range(idx, argpos, who);
  return car(list);
}

// One step of (ref x i ...): a component of a structure, an entry of a row
// or column matrix, an element of a vector or a list.
Value ref_step(Value x, Value idx, int argpos, const char *who) {
  size_t i = index_arg(idx, argpos, who);
  if (is_structure(x)) {
    if (i >= as_structure(x)->len) bad_range(idx, argpos, who);
    return as_structure(x)->items[i];
  }
  if (is_matrix(x)) {
    Matrix *m = as_matrix(x);
    if (m->cols != 1 && m->rows != 1) wrong_type(x, 1, who);
    if (i >= m->rows * m->cols) bad_range(idx, argpos, who);
    return m->items[i];
  }
  if (x.is(Tag::Vector)) {
    if (i >= x.vector()->len) bad_range(idx, argpos, who);
    return x.vector()->items[i];
  }
  if (is_pair(x)) return list_ref_checked(x, i, idx, argpos, who);
  wrong_type(x, 1, who);
}

Value ref_path(Value x, const Value *idx, size_t n, int first_argpos, const char *who);

// ((ref f i ...) x...) is (ref (f x...) i ...): a = f, items = the indices,
// op = 1 for component (named in errors), 0 for ref.
Value call_ref_of_value(NativeProc *self, Value *args, int nargs) {
  return ref_path(apply_procedure(self->a, args, nargs), self->items, self->nitems, 2,
                  self->op ? "component" : "ref");
}

// (ref x i j ...): a matrix takes its indices two at a time; a function
// (not a series) composes with the selection, as in scmutils.
Value ref_path(Value x, const Value *idx, size_t n, int first_argpos, const char *who) {
  for (size_t k = 0; k < n;) {
    int argpos = first_argpos + static_cast<int>(k);
    if (is_procedure(x) && !is_series(x)) {
      for (size_t j = k; j < n; ++j)
        index_arg(idx[j], first_argpos + static_cast<int>(j), who);
      int component = std::string_view(who) == "component";
      return make_native_procedure(call_ref_of_value, component, x, Value::nil(), idx + k, n - k);
    }
    if (is_matrix(x) && k + 1 < n) {
      Matrix *m = as_matrix(x);
      size_t i = index_arg(idx[k], argpos, who), j = index_arg(idx[k + 1], argpos + 1, who);
      if (i >= m->rows) bad_range(idx[k], argpos, who);
      if (j >= m->cols) bad_range(idx[k + 1], argpos + 1, who);
      x = matrix_at(m, i, j);
      k += 2;
    } else {
      x = ref_step(x, idx[k], argpos, who);
      ++k;
    }
  }
  return x;
}

Value prim_ref(Value *args, int n) {
  return ref_path(args[0], args + 1, static_cast<size_t>(n - 1), 2, "ref");
}

Value call_component(NativeProc *self, Value *args, int nargs) {
  if (nargs != 1) native_arity_error(self, nargs, 1);
  return ref_path(args[0], self->items, self->nitems, 2, "component");
}

// ((component i j ...) s) is (ref s i j ...).
Value prim_component(Value *args, int n) {
  for (int i = 0; i < n; ++i)
    index_arg(args[i], i + 1, "component");
  return make_native_procedure(call_component, 0, Value::nil(), Value::nil(), args,
                               static_cast<size_t>(n));
}

Value prim_up(Value *args, int n) {
  return make_structure_from(true, args, static_cast<size_t>(n));
}
Value prim_down(Value *args, int n) {
  return make_structure_from(false, args, static_cast<size_t>(n));
}
Value prim_up_p(Value *args, int) {
  return Value::boolean(is_structure(args[0]) && as_structure(args[0])->up);
}
Value prim_down_p(Value *args, int) {
  return Value::boolean(is_structure(args[0]) && !as_structure(args[0])->up);
}
Value prim_structure_p(Value *args, int) {
  return Value::boolean(is_structure(args[0]));
}

Structure *structure_arg(Value *args, int i, const char *who) {
  if (!is_structure(args[i])) wrong_type(args[i], i + 1, who);
  return as_structure(args[i]);
}

template <bool Up> Value prim_vector_to(Value *args, int) {
  if (!args[0].is(Tag::Vector)) wrong_type(args[0], 1, Up ? "vector->up" : "vector->down");
  Vector *v = args[0].vector();
  return make_structure_from(Up, v->items, v->len);
}

template <bool Up> Value prim_to_vector(Value *args, int) {
  const char *who = Up ? "up->vector" : "down->vector";
  Structure *s = structure_arg(args, 0, who);
  if (s->up != Up) wrong_type(args[0], 1, who);
  Value v = make_vector(s->len, Value::nil());
  std::copy(s->items, s->items + s->len, v.vector()->items);
  return v;
}

template <bool Up> Value prim_list_to(Value *args, int) {
  if (list_length(args[0]) < 0) wrong_type(args[0], 1, Up ? "list->up" : "list->down");
  gcvec<Value> items = list_to_vector(args[0]);
  return make_structure_from(Up, items.data(), items.size());
}

Value prim_structure_to_list(Value *args, int) {
  Structure *s = structure_arg(args, 0, "structure->list");
  return list_from(s->items, s->len);
}

Value prim_s_length(Value *args, int) {
  if (!is_structure(args[0])) return Value::fixnum(1);
  return Value::fixnum(static_cast<int64_t>(as_structure(args[0])->len));
}

Value prim_s_dimension(Value *args, int) {
  return Value::fixnum(static_cast<int64_t>(structure_dimension(args[0])));
}

bool orientation_arg(Value *args, int i, const char *who) {
  if (is_symbol(args[i])) {
    const std::string &name = symbol_name(args[i]);
    if (name == "up" || name == "column" || name == "contravariant") return true;
    if (name == "down" || name == "row" || name == "covariant") return false;
  }
  wrong_type(args[i], i + 1, who);
}

// (s:generate n 'up f): (up (f 0) ... (f n-1)).
Value prim_s_generate(Value *args, int) {
  size_t n = index_arg(args[0], 1, "s:generate");
  bool up = orientation_arg(args, 1, "s:generate");
  if (!is_procedure(args[2])) wrong_type(args[2], 3, "s:generate");
  return generate_structure(up, n, [&](size_t i) {
    Value index = Value::fixnum(static_cast<int64_t>(i));
    return apply_procedure(args[2], &index, 1);
  });
}

// f applied to the i-th components of the structures ss[0..n); `recursive`
// descends into components that are structures themselves.
Value map_components(Value f, const Value *ss, int n, bool recursive, const char *who) {
  if (!is_structure(ss[0])) {
    gcvec<Value> xs(ss, ss + n);
    return apply_procedure(f, xs.data(), n);
  }
  Structure *first = as_structure(ss[0]);
  for (int k = 1; k < n; ++k)
    if (!is_structure(ss[k]) || as_structure(ss[k])->len != first->len)
      shape_mismatch(who, ss[0], ss[k]);
  return generate_structure(first->up, first->len, [&](size_t i) {
    gcvec<Value> xs(static_cast<size_t>(n));
    for (int k = 0; k < n; ++k)
      xs[k] = as_structure(ss[k])->items[i];
    if (recursive && is_structure(xs[0])) return map_components(f, xs.data(), n, true, who);
    return apply_procedure(f, xs.data(), n);
  });
}

Value prim_s_map(Value *args, int n) {
  if (!is_procedure(args[0])) wrong_type(args[0], 1, "s:map");
  return map_components(args[0], args + 1, n - 1, false, "s:map");
}

Value prim_s_map_r(Value *args, int n) {
  if (!is_procedure(args[0])) wrong_type(args[0], 1, "s:map/r");
  return map_components(args[0], args + 1, n - 1, true, "s:map/r");
}

// Fresh literal numbers for compatible-shape and typical-object: x100, x101,
// ... (scmutils generates uninterned symbols with such names).
Value fresh_symbol() {
  static uint64_t counter = 100;
  return intern("x" + std::to_string(counter++));
}

Value fresh_leaves(Value shape, bool dual) {
  gcvec<Value> leaves(structure_dimension(shape));
  for (Value &leaf : leaves)
    leaf = fresh_symbol();
  return shape_from_leaves(shape, dual, leaves.data());
}

Value prim_compatible_shape(Value *args, int) {
  return fresh_leaves(args[0], true);
}
Value prim_typical_object(Value *args, int) {
  return fresh_leaves(args[0], false);
}

// scmutils' dot-product: the sum of the products of corresponding leaves of
// two structures of the same orientation and size.
Value prim_dot_product(Value *args, int) {
  Value a = args[0], b = args[1];
  if (!is_structure(a) || !is_structure(b)) return g_mul(a, b);
  if (as_structure(a)->up != as_structure(b)->up ||
      structure_dimension(a) != structure_dimension(b))
    shape_mismatch("dot-product", a, b);
  gcvec<Value> x, y;
  structure_leaves(a, x);
  structure_leaves(b, y);
  Value sum = Value::fixnum(0);
  for (size_t i = 0; i < x.size(); ++i)
    sum = g_add(sum, g_mul(x[i], y[i]));
  return sum;
}

Value prim_cross_product(Value *args, int) {
  Structure *a = structure_arg(args, 0, "cross-product");
  Structure *b = structure_arg(args, 1, "cross-product");
  if (a->len != 3) wrong_type(args[0], 1, "cross-product");
  if (b->len != 3) wrong_type(args[1], 2, "cross-product");
  auto term = [&](size_t i, size_t j) {
    return g_sub(g_mul(a->items[i], b->items[j]), g_mul(a->items[j], b->items[i]));
  };
  Value items[3] = {term(1, 2), term(2, 0), term(0, 1)};
  return make_structure_from(a->up, items, 3);
}

// ---- primitives: matrices ----

Matrix *matrix_arg(Value *args, int i, const char *who) {
  if (!is_matrix(args[i])) wrong_type(args[i], i + 1, who);
  return as_matrix(args[i]);
}

// (matrix-by-rows (list a b) (list c d)): at least one row, all of one length.
Value rows_to_matrix(Value *args, int n, const char *who) {
  long cols = list_length(args[0]);
  for (int i = 0; i < n; ++i)
    if (list_length(args[i]) != cols || cols <= 0) wrong_type(args[i], i + 1, who);
  Value m = make_matrix(static_cast<size_t>(n), static_cast<size_t>(cols));
  for (int i = 0; i < n; ++i) {
    size_t j = 0;
    for (Value row = args[i]; is_pair(row); row = cdr(row))
      matrix_at(as_matrix(m), static_cast<size_t>(i), j++) = car(row);
  }
  return m;
}

Value prim_matrix_by_rows(Value *args, int n) {
  return rows_to_matrix(args, n, "matrix-by-rows");
}

Value prim_matrix_by_cols(Value *args, int n) {
  Value rows = rows_to_matrix(args, n, "matrix-by-cols");
  Matrix *m = as_matrix(rows);
  return generate_matrix(m->cols, m->rows, [&](size_t i, size_t j) { return matrix_at(m, j, i); });
}

Value prim_column_matrix(Value *args, int n) {
  return generate_matrix(static_cast<size_t>(n), 1, [&](size_t i, size_t) { return args[i]; });
}
Value prim_row_matrix(Value *args, int n) {
  return generate_matrix(1, static_cast<size_t>(n), [&](size_t, size_t j) { return args[j]; });
}
Value prim_matrix_p(Value *args, int) {
  return Value::boolean(is_matrix(args[0]));
}

Value prim_transpose(Value *args, int) {
  Matrix *m = matrix_arg(args, 0, "m:transpose");
  return generate_matrix(m->cols, m->rows, [&](size_t i, size_t j) { return matrix_at(m, j, i); });
}

Value prim_inverse(Value *args, int) {
  if (is_structure(args[0])) return structure_inverse(args[0], "m:inverse");
  matrix_arg(args, 0, "m:inverse");
  return matrix_inverse(args[0], "m:inverse");
}

Value prim_determinant(Value *args, int) {
  return determinant(args[0]);
}

Value prim_trace(Value *args, int) {
  Matrix *m = matrix_arg(args, 0, "m:trace");
  if (m->rows != m->cols) wrong_type(args[0], 1, "m:trace");
  Value sum = Value::fixnum(0);
  for (size_t i = 0; i < m->rows; ++i)
    sum = g_add(sum, matrix_at(m, i, i));
  return sum;
}

Value prim_num_rows(Value *args, int) {
  return Value::fixnum(static_cast<int64_t>(matrix_arg(args, 0, "m:num-rows")->rows));
}
Value prim_num_cols(Value *args, int) {
  return Value::fixnum(static_cast<int64_t>(matrix_arg(args, 0, "m:num-cols")->cols));
}
Value prim_m_dimension(Value *args, int) {
  Matrix *m = matrix_arg(args, 0, "m:dimension");
  if (m->rows != m->cols) wrong_type(args[0], 1, "m:dimension");
  return Value::fixnum(static_cast<int64_t>(m->rows));
}

Value prim_matrix_ref(Value *args, int) {
  matrix_arg(args, 0, "matrix-ref");
  return ref_path(args[0], args + 1, 2, 2, "matrix-ref");
}

// (m:submatrix m r0 r1 c0 c1): rows [r0, r1) and columns [c0, c1).
Value prim_submatrix(Value *args, int) {
  Matrix *m = matrix_arg(args, 0, "m:submatrix");
  size_t bounds[4];
  size_t limits[4] = {m->rows, m->rows, m->cols, m->cols};
  for (int k = 0; k < 4; ++k) {
    bounds[k] = index_arg(args[k + 1], k + 2, "m:submatrix");
    bool ordered = k % 2 == 0 || bounds[k] >= bounds[k - 1];
    if (bounds[k] > limits[k] || !ordered) bad_range(args[k + 1], k + 2, "m:submatrix");
  }
  return generate_matrix(bounds[1] - bounds[0], bounds[3] - bounds[2], [&](size_t i, size_t j) {
    return matrix_at(m, bounds[0] + i, bounds[2] + j);
  });
}

Value prim_m_generate(Value *args, int) {
  size_t rows = index_arg(args[0], 1, "m:generate"), cols = index_arg(args[1], 2, "m:generate");
  if (!is_procedure(args[2])) wrong_type(args[2], 3, "m:generate");
  return generate_matrix(rows, cols, [&](size_t i, size_t j) {
    Value ij[2] = {Value::fixnum(static_cast<int64_t>(i)), Value::fixnum(static_cast<int64_t>(j))};
    return apply_procedure(args[2], ij, 2);
  });
}

// The axial vector of an antisymmetric 3x3 matrix A: A v = w x v for the w returned.
Value prim_antisymmetric_to_column(Value *args, int) {
  Matrix *m = matrix_arg(args, 0, "antisymmetric->column-matrix");
  if (m->rows != 3 || m->cols != 3) wrong_type(args[0], 1, "antisymmetric->column-matrix");
  Value w[3] = {matrix_at(m, 2, 1), matrix_at(m, 0, 2), matrix_at(m, 1, 0)};
  return prim_column_matrix(w, 3);
}

// (s->m ls ms rs): the matrix of the bilinear form ls . ms . rs, entry (i, j)
// being the product of ms with the i-th basis element of ls's shape on the
// left and the j-th of rs's on the right; (m->s ls m rs) undoes it.
Value prim_s_to_m(Value *args, int) {
  Value ls = args[0], ms = args[1], rs = args[2];
  size_t rows = structure_dimension(ls), cols = structure_dimension(rs);
  gcvec<Value> right(cols);
  for (size_t j = 0; j < cols; ++j)
    right[j] = g_mul(ms, basis_element(rs, j));
  return generate_matrix(rows, cols, [&](size_t i, size_t j) {
    Value e = g_mul(basis_element(ls, i), right[j]);
    if (is_structure(e) || is_matrix(e)) shape_mismatch("s->m", ls, ms);
    return e;
  });
}

Value prim_m_to_s(Value *args, int) {
  Value ls = args[0], rs = args[2];
  Matrix *m = matrix_arg(args, 1, "m->s");
  size_t rows = structure_dimension(ls), cols = structure_dimension(rs);
  if (m->rows != rows || m->cols != cols) shape_mismatch("m->s", ls, args[1]);
  gcvec<Value> columns(cols), column(rows);
  for (size_t j = 0; j < cols; ++j) {
    for (size_t i = 0; i < rows; ++i)
      column[i] = matrix_at(m, i, j);
    columns[j] = shape_from_leaves(ls, true, column.data());
  }
  return shape_from_leaves(rs, true, columns.data());
}

struct StructureSpec {
  const char *name;
  int min_args, max_args;
  PrimFn fn;
};

const StructureSpec kStructurePrimitives[] = {
    {"up", 0, kVariadic, prim_up},
    {"down", 0, kVariadic, prim_down},
    {"up?", 1, 1, prim_up_p},
    {"down?", 1, 1, prim_down_p},
    {"structure?", 1, 1, prim_structure_p},
    {"vector->up", 1, 1, prim_vector_to<true>},
    {"vector->down", 1, 1, prim_vector_to<false>},
    {"up->vector", 1, 1, prim_to_vector<true>},
    {"down->vector", 1, 1, prim_to_vector<false>},
    {"list->up", 1, 1, prim_list_to<true>},
    {"list->down", 1, 1, prim_list_to<false>},
    {"structure->list", 1, 1, prim_structure_to_list},
    {"ref", 1, kVariadic, prim_ref},
    {"s:ref", 2, 2, prim_ref},
    {"component", 0, kVariadic, prim_component},
    {"s:length", 1, 1, prim_s_length},
    {"s:dimension", 1, 1, prim_s_dimension},
    {"s:generate", 3, 3, prim_s_generate},
    {"s:map", 2, kVariadic, prim_s_map},
    {"s:map/r", 2, kVariadic, prim_s_map_r},
    {"compatible-shape", 1, 1, prim_compatible_shape},
    {"typical-object", 1, 1, prim_typical_object},
    {"dot-product", 2, 2, prim_dot_product},
    {"cross-product", 2, 2, prim_cross_product},
    {"matrix-by-rows", 1, kVariadic, prim_matrix_by_rows},
    {"matrix-by-cols", 1, kVariadic, prim_matrix_by_cols},
    {"column-matrix", 1, kVariadic, prim_column_matrix},
    {"row-matrix", 1, kVariadic, prim_row_matrix},
    {"matrix?", 1, 1, prim_matrix_p},
    {"m:transpose", 1, 1, prim_transpose},
    {"m:inverse", 1, 1, prim_inverse},
    {"m:invert", 1, 1, prim_inverse},
    {"determinant", 1, 1, prim_determinant},
    {"m:determinant", 1, 1, prim_determinant},
    {"m:trace", 1, 1, prim_trace},
    {"m:num-rows", 1, 1, prim_num_rows},
    {"m:num-cols", 1, 1, prim_num_cols},
    {"m:dimension", 1, 1, prim_m_dimension},
    {"matrix-ref", 3, 3, prim_matrix_ref},
    {"m:ref", 3, 3, prim_matrix_ref},
    {"m:submatrix", 5, 5, prim_submatrix},
    {"m:generate", 3, 3, prim_m_generate},
    {"antisymmetric->column-matrix", 1, 1, prim_antisymmetric_to_column},
    {"s->m", 3, 3, prim_s_to_m},
    {"m->s", 3, 3, prim_m_to_s},
};

} // namespace

void install_structure_primitives() {
  set_datum_converter(Tag::Structure, structure_to_datum);
  set_datum_converter(Tag::Matrix, matrix_to_datum);
  for (const StructureSpec &p : kStructurePrimitives)
    define_primitive(p.name, p.min_args, p.max_args, p.fn);
}

} // namespace sicm
