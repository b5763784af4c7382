// show-expression, ->infix and ->tex-string: values in the book's notation.
//
// Each first turns its argument into the prefix datum it prints as, then
// renders that datum (print/infix.cpp, print/tex.cpp).
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "eval/core.hpp"
#include "print/infix.hpp"

namespace sicm {

namespace {

// v as a datum: structures and matrices spelled out as (up ...), (down ...)
// and (matrix-by-rows (list ...) ...) here, since the renderers read only
// data, and every other part, expressions included, by expression_to_datum.
Value show_datum(Value v) {
  if (is_structure(v)) {
    Structure *s = as_structure(v);
    gcvec<Value> items;
    for (size_t i = 0; i < s->len; ++i)
      items.push_back(show_datum(s->items[i]));
    return cons(intern(s->up ? "up" : "down"), list_from(items.data(), items.size()));
  }
  if (is_matrix(v)) {
    Matrix *m = as_matrix(v);
    gcvec<Value> rows;
    for (size_t i = 0; i < m->rows; ++i) {
      gcvec<Value> row;
      for (size_t j = 0; j < m->cols; ++j)
        row.push_back(show_datum(matrix_at(m, i, j)));
      rows.push_back(cons(intern("list"), list_from(row.data(), row.size())));
    }
    return cons(intern("matrix-by-rows"), list_from(rows.data(), rows.size()));
  }
  if (is_pair(v) && list_length(v) > 0) {
    gcvec<Value> items;
    for (Value p = v; is_pair(p); p = cdr(p))
      items.push_back(show_datum(car(p)));
    return list_from(items.data(), items.size());
  }
  return expression_to_datum(v);
}

// (show-expression x): the infix form on a line of its own, as the book
// shows a result set apart from the text around it.
Value P_show_expression(Value *a, int) {
  std::string text = datum_to_infix(show_datum(a[0]));
  if (output_column() != 0) output("\n");
  output(text + "\n");
  return Value::unspecified();
}

Value P_to_infix(Value *a, int) {
  return make_string(datum_to_infix(show_datum(a[0])));
}

Value P_to_tex_string(Value *a, int) {
  return make_string(value_to_tex(a[0]));
}

// (set-dot-notation! on): time derivatives with dots in show-expression,
// ->infix and ->tex-string from now on (print/infix.hpp).
Value P_set_dot_notation(Value *a, int) {
  set_dot_notation(!a[0].is_false());
  return Value::unspecified();
}

} // namespace

std::string value_to_tex(Value v) {
  return datum_to_tex(show_datum(v));
}

void install_show_primitives() {
  define_primitive("show-expression", 1, 1, Stage::Effect, P_show_expression);
  define_primitive("->infix", 1, 1, Stage::Pure, P_to_infix);
  define_primitive("->tex-string", 1, 1, Stage::Pure, P_to_tex_string);
  // Pure: its effect is on how values print, which sicm build does while
  // compiling, in program order.
  define_primitive("set-dot-notation!", 1, 1, Stage::Pure, P_set_dot_notation);
}

} // namespace sicm
