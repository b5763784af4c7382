// The bridge between generic arithmetic (eval/) and the expression algebra
// (algebra/): how Scheme values become symbolic expressions and back.
//
// A symbolic value is a Value with Tag::Expr whose payload is an ExprId into
// the hash-consed expression DAG (cas/expr.hpp). Quoted symbols used as
// numbers ('m, 'theta) are literal real numbers: arithmetic on them builds
// expressions.
#pragma once

#include <cstdint>

#include "base/value.hpp"
#include "cas/ops.hpp"

namespace sicm {

// A Value is "symbolic" if it is an expression or a symbol (a literal number).
inline bool is_expression(Value v) {
  return v.is(Tag::Expr);
}
inline bool is_symbolic(Value v) {
  return v.is(Tag::Expr) || v.is(Tag::Symbol);
}

// Apply an algebraic operator to arguments that are numbers, symbols or
// expressions. Folds exactly when every argument is a number; otherwise
// returns an expression (Tag::Expr). Cheap local rewrites only (x+0, x*1,
// x*0 with exact 0); full simplification is simplify_value's job.
Value symbolic_apply(Op op, const Value *args, int nargs);

// Apply an unknown function (a literal function's name, or an expression
// denoting a derived function such as (D f)) to arguments: the expression (f t).
Value symbolic_call(Value head, const Value *args, int nargs);

// A prefix-form datum as an expression: ((D f) t) or (+ (* 2 x) 1), operators
// of ops.def applied by symbolic_apply, other lists as functions applied to
// arguments. Numbers and symbols are returned as they are.
Value datum_to_expression(Value datum);

// The simplified form: a number if the expression is one, else an expression.
Value simplify_value(Value v);

// The prefix form as a Scheme datum ((* 1/2 m (expt v 2)) as a list), in the
// book's canonical order, of the simplified expression; numbers and symbols
// are returned as they are.
Value expression_to_datum(Value v);

// While a DecimalConstants object lives (on this thread), a finite flonum
// that meets a symbolic value in arithmetic enters the expression as the
// exact rational of its shortest decimal form: 9.8 as 49/5, 1.5 as 3/2, not
// as the binary fractions the doubles hold. Tracing a procedure into a
// kernel uses it: a parameter written 9.8 means 49/5, and with exact
// constants the simplifier cancels what cancels on paper (flonums rounded
// before the algebra leave terms of relative size 1e-16 that never cancel,
// and coefficients of size 1e46 from clearing binary denominators). The
// kernel's numbers are rounded to doubles once, at emission, so a constant
// the user wrote reads back as exactly the double it was. Arithmetic on
// numbers alone is untouched: (* 1.5 9.8) is still a flonum product.
class DecimalConstants {
public:
  DecimalConstants();
  ~DecimalConstants();
  DecimalConstants(const DecimalConstants &) = delete;
  DecimalConstants &operator=(const DecimalConstants &) = delete;
};

// Register the algebra's primitives (simplify, print-expression, pe,
// expression, datum->expression) and the printer's converter that shows an
// expression as its simplified prefix form. Called by init_interpreter.
void install_algebra_primitives();

} // namespace sicm
