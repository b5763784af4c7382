// Structures as linear maps: a structure of any nesting, multiplying structures of one shape
// into structures of another, divides, inverts and has a determinant through the matrix of
// that map.
//
// The rule is scmutils' (kernel/structs.scm: solve-linear-left, s:inverse, s->m, m->s):
// (/ b M) is the x with (* M x) = b, where x has the shape that makes the
// product numerical, compatible-shape of (* (compatible-shape b) M). Both
// sides flatten: A(i, j) is leaf i of (* M e_j) for the j-th basis
// structure e_j of x's shape, A x = b is solved on the leaves, and x takes
// its shape back. A down of downs is the familiar case (its components are
// A's columns); the mass matrix of coordinates that are structures of
// structures, (up (up x1 y1 z1) (up x2 y2 z2)), is a down of downs of downs
// of downs, and divides the same way. In a kernel, the flattened system
// becomes solve nodes (linear_solve.hpp), as a flat one does.
//
// scmutils inverts only two-level structures (s:invert); a deeper M is
// inverted here by the same rule: M is a structure whose parts, at some
// depth, all have one shape I with as many leaves as there are parts, so
// that M maps a structure x of the dual of the outer shape to (* M x), of
// shape I. Its inverse maps structures of shape I back: an outer structure
// of the dual of I whose parts have x's shape.
#include <algorithm>
#include <optional>
#include <string>

#include "algebra/generic.hpp"
#include "algebra/linear_solve.hpp"
#include "algebra/structure.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

// A structure of v's shape (orientations exchanged if `dual`) with every leaf exact 0.
Value zeros_like(Value v, bool dual) {
  gcvec<Value> zeros(structure_dimension(v), Value::fixnum(0));
  return shape_from_leaves(v, dual, zeros.data());
}

bool same_shape(Value a, Value b) {
  if (!is_structure(a) || !is_structure(b)) return !is_structure(a) && !is_structure(b);
  Structure *s = as_structure(a), *t = as_structure(b);
  if (s->up != t->up || s->len != t->len) return false;
  for (size_t i = 0; i < s->len; ++i)
    if (!same_shape(s->items[i], t->items[i])) return false;
  return true;
}

// The shape of the x that (/ b m) solves for: compatible-shape of
// (* (compatible-shape b) m), in zeros; nullopt when the product has no
// sense (mismatched shapes).
std::optional<Value> quotient_shape(Value b, Value m) {
  try {
    Value product = g_mul(zeros_like(b, true), zeros_like(m, false));
    return zeros_like(product, true);
  } catch (const Error &e) {
    if (e.cause != ErrorCause::Other) throw;
    return std::nullopt;
  }
}

// The n x n matrix (row-major) of x |-> (* m x) on structures x of
// `x_shape`, whose products must have the shape `y_shape`; nullopt when
// they do not, or when the dimensions differ. The products are taken on
// m's leaf numbers (1, 2, ...) rather than its leaves, so that finding
// where each leaf goes costs no symbolic arithmetic: each leaf of
// (* m e_j) is one leaf of m or nothing, since a product of structures is
// bilinear in their leaves.
std::optional<gcvec<Value>> matrix_of_map(Value m, Value x_shape, Value y_shape) {
  size_t n = structure_dimension(x_shape);
  if (!is_structure(x_shape) || !is_structure(y_shape) || structure_dimension(y_shape) != n)
    return std::nullopt;
  gcvec<Value> leaves;
  structure_leaves(m, leaves);
  gcvec<Value> numbers(leaves.size());
  for (size_t k = 0; k < leaves.size(); ++k)
    numbers[k] = Value::fixnum(static_cast<int64_t>(k + 1));
  Value numbered = shape_from_leaves(m, false, numbers.data());
  gcvec<Value> a(n * n, Value::fixnum(0)), column;
  for (size_t j = 0; j < n; ++j) {
    Value y;
    try {
      y = g_mul(numbered, basis_element(x_shape, j));
    } catch (const Error &e) {
      if (e.cause != ErrorCause::Other) throw;
      return std::nullopt;
    }
    if (!same_shape(y, y_shape)) return std::nullopt;
    column.clear();
    structure_leaves(y, column);
    for (size_t i = 0; i < n; ++i) {
      std::optional<int64_t> k = to_int64(column[i]);
      if (!k || *k < 0 || static_cast<size_t>(*k) > leaves.size()) return std::nullopt;
      if (*k > 0) a[i * n + j] = leaves[static_cast<size_t>(*k - 1)];
    }
  }
  return a;
}

// A x = b, n x n: solve nodes in a kernel (linear_solve.hpp), else the
// inverse times b. x_i sums from k = 0 without a leading 0, with b's
// factor first when `b_first`, as the products of structures that computed
// it before did ((* b M^-1) for a down b, (* M^-1 b) for an up).
gcvec<Value> solve_flat(size_t n, const gcvec<Value> &a, const gcvec<Value> &b, bool b_first) {
  if (std::optional<gcvec<Value>> x = traced_solve(n, a, b.data())) return *x;
  Value m = make_matrix(n, n);
  std::copy(a.begin(), a.end(), as_matrix(m)->items);
  Matrix *inverse = as_matrix(matrix_inverse(m, "/"));
  gcvec<Value> x(n);
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < n; ++k) {
      Value term =
          b_first ? g_mul(b[k], matrix_at(inverse, i, k)) : g_mul(matrix_at(inverse, i, k), b[k]);
      x[i] = k == 0 ? term : g_add(x[i], term);
    }
  }
  return x;
}

// A copy of v with each part of the shape of `part` replaced by exact 0:
// the outer structure of which those parts are the entries; nullopt when
// some leaf of v lies outside every such part.
std::optional<Value> outer_shape(Value v, Value part) {
  if (same_shape(v, part)) return Value::fixnum(0);
  if (!is_structure(v)) return std::nullopt;
  Structure *s = as_structure(v);
  Value out = make_structure(s->up, s->len);
  for (size_t i = 0; i < s->len; ++i) {
    std::optional<Value> o = outer_shape(s->items[i], part);
    if (!o) return std::nullopt;
    as_structure(out)->items[i] = *o;
  }
  return out;
}

// The shape of the structures x that m maps, as a square linear map, to
// (* m x): the dual of m's outer shape, for the first of m's parts (m[0],
// m[0][0], ...) whose shape cuts m into as many parts as it has leaves.
std::optional<Value> argument_shape(Value m) {
  if (!is_structure(m) || as_structure(m)->len == 0) return std::nullopt;
  size_t total = structure_dimension(m);
  for (Value part = as_structure(m)->items[0]; is_structure(part) && as_structure(part)->len > 0;
       part = as_structure(part)->items[0]) {
    size_t k = structure_dimension(part);
    if (k * k != total) continue;
    std::optional<Value> outer = outer_shape(m, part);
    if (outer && structure_dimension(*outer) == k) return zeros_like(*outer, true);
  }
  return std::nullopt;
}

// The matrix of m as a square linear map and the shapes it maps between.
struct SquareMap {
  Value x_shape, y_shape;
  size_t n;
  gcvec<Value> a;
};

std::optional<SquareMap> square_map(Value m) {
  std::optional<Value> x_shape = argument_shape(m);
  if (!x_shape) return std::nullopt;
  Value y_shape = g_mul(zeros_like(m, false), *x_shape);
  std::optional<gcvec<Value>> a = matrix_of_map(m, *x_shape, y_shape);
  if (!a) return std::nullopt;
  return SquareMap{*x_shape, y_shape, structure_dimension(*x_shape), std::move(*a)};
}

[[noreturn]] void not_invertible(Value s, const char *who) {
  runtime_error(current_call_loc(),
                std::string(who) + ": cannot invert " + write_string(s) +
                    ": it is not a square linear map, a structure whose parts at some depth "
                    "all have one shape, with as many entries as there are parts (such as a "
                    "down of downs)");
}

} // namespace

Value basis_element(Value shape, size_t k) {
  gcvec<Value> leaves(structure_dimension(shape), Value::fixnum(0));
  leaves[k] = Value::fixnum(1);
  return shape_from_leaves(shape, false, leaves.data());
}

Value divide_by_structure(Value b, Value m) {
  if (!is_structure(b)) return g_mul(b, structure_inverse(m, "/"));
  std::optional<Value> x_shape = quotient_shape(b, m);
  std::optional<gcvec<Value>> a;
  if (x_shape) a = matrix_of_map(m, *x_shape, b);
  if (!a)
    runtime_error(current_call_loc(),
                  "/: cannot divide " + write_string(b) + " by " + write_string(m) +
                      ": no structure x makes (* M x) a structure of the shape of the dividend, "
                      "with as many entries");
  size_t n = structure_dimension(b);
  gcvec<Value> rhs;
  structure_leaves(b, rhs);
  gcvec<Value> x = solve_flat(n, *a, rhs, !as_structure(b)->up);
  return shape_from_leaves(*x_shape, false, x.data());
}

Value structure_inverse(Value s, const char *who) {
  std::optional<SquareMap> map = square_map(s);
  if (!map) not_invertible(s, who);
  Value m = make_matrix(map->n, map->n);
  std::copy(map->a.begin(), map->a.end(), as_matrix(m)->items);
  Matrix *inverse = as_matrix(matrix_inverse(m, who));
  gcvec<Value> parts(map->n), column(map->n);
  for (size_t k = 0; k < map->n; ++k) {
    for (size_t i = 0; i < map->n; ++i)
      column[i] = matrix_at(inverse, i, k);
    parts[k] = shape_from_leaves(map->x_shape, false, column.data());
  }
  return shape_from_leaves(map->y_shape, true, parts.data());
}

Value structure_determinant(Value s) {
  std::optional<SquareMap> map = square_map(s);
  if (!map) wrong_type(s, 1, "determinant");
  Value m = make_matrix(map->n, map->n);
  std::copy(map->a.begin(), map->a.end(), as_matrix(m)->items);
  return determinant(m);
}

} // namespace sicm
