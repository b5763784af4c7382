// What structure.cpp (structures and matrices) shares with
// structure_primitives.cpp (their primitives) and no one else: building
// them component by component, and the error of mismatched shapes.
#pragma once

#include <cstddef>

#include "algebra/structure.hpp"

namespace sicm {

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

// "The shapes of A and B, passed to WHO, do not match."
[[noreturn]] void shape_mismatch(const char *who, Value a, Value b);

} // namespace sicm
