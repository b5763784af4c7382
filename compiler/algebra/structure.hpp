// Up and down tuples (SICM's structures) and matrices: representation, shapes and linear algebra.
//
// A structure is an up (contravariant, "column") or down (covariant, "row")
// tuple whose components are any values, structures included, so shapes nest:
// (up t (up x y) (down p_x p_y)). A matrix is a rows x cols array of values
// stored row-major. Both live on the collected heap (Tag::Structure,
// Tag::Matrix) and are immutable once built.
//
// Arithmetic on them follows the book's appendix "Our Notation": a down times
// an up of the same length contracts to the sum of the products of
// components; any other product of structures multiplies the first factor
// into each component of the second; sums are componentwise and need equal
// shapes. The generic operations (algebra/generic.hpp) call in here through
// the "structure" arithmetic type registered by register_structure_arith().
#pragma once

#include <cstddef>

#include "base/value.hpp"

namespace sicm {

// ---- construction and access ----
// A structure of len components, each initialized to #!unspecific; fill it
// before it escapes.
Value make_structure(bool up, size_t len);
Value make_structure_from(bool up, const Value *items, size_t len);
// A rows x cols matrix, entries initialized to exact 0.
Value make_matrix(size_t rows, size_t cols);

inline bool is_structure(Value v) {
  return v.is(Tag::Structure);
}
inline bool is_matrix(Value v) {
  return v.is(Tag::Matrix);
}
inline Structure *as_structure(Value v) {
  return v.as<Structure>();
}
inline Matrix *as_matrix(Value v) {
  return v.as<Matrix>();
}
inline Value &matrix_at(Matrix *m, size_t i, size_t j) {
  return m->items[i * m->cols + j];
}

// ---- shapes ----
// Number of scalar leaves of a (nested) structure; 1 for anything else.
size_t structure_dimension(Value v);
// The leaves of v in order (v itself if it is not a structure).
void structure_leaves(Value v, gcvec<Value> &out);
// A structure of the shape of `shape` (with up and down exchanged at every
// level if `dual`) whose leaves are leaves[0 .. structure_dimension(shape)).
Value shape_from_leaves(Value shape, bool dual, const Value *leaves);

// ---- arithmetic on structures and matrices (operands already dispatched) ----
// Contraction when a and b are structures compatible for it, else the first
// factor times each component of the second.
Value structure_mul(Value a, Value b);
// The linear-algebra inverse of a square matrix. `who` names the caller in
// the "singular" error.
Value matrix_inverse(Value m, const char *who);
// Determinant of a square matrix, or of a structure that is a square linear map.
Value determinant(Value m);

// ---- structures as linear maps (structure_linear_map.cpp) ----
// A structure of any nesting is a linear map x |-> (* s x); these flatten
// it to its matrix, as scmutils does. (/ b s) for a structure s: the x with
// (* s x) = b (for a scalar b, b times the inverse of s).
Value divide_by_structure(Value b, Value s);
// The inverse map of a square linear map s (a down of downs, the mass
// matrix of nested coordinates, ...); `who` names the caller in errors.
Value structure_inverse(Value s, const char *who);
Value structure_determinant(Value s);
// The k-th basis structure of shape's shape: leaf k is 1, the others 0.
Value basis_element(Value shape, size_t k);

// Register the structure and matrix arithmetic type with generic arithmetic,
// and the structure and matrix primitives (up, down, ref, matrix-by-rows, ...),
// and their printers.
void register_structure_arith();
void install_structure_primitives();

} // namespace sicm
