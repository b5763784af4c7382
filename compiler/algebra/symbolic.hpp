// The bridge between generic arithmetic (eval/) and the expression algebra
// (algebra/): how Scheme values become symbolic expressions and back.
//
// A symbolic value is a Value with Tag::Expr whose payload is an ExprId into
// the hash-consed expression DAG (cas/expr.hpp). Quoted symbols used as
// numbers ('m, 'theta) are literal real numbers: arithmetic on them builds
// expressions.
#pragma once

#include <cstdint>
#include <unordered_map>

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

// The exact rational of the shortest decimal that reads back as the finite
// flonum d (9.8 -> 49/5), as DecimalConstants makes it.
Value decimal_rational(double d);

// While a KernelParameters lives (on this thread, inside a trace: see
// codegen/trace.hpp), a number the traced procedure brings into an operation
// with a value that depends on the kernel's inputs becomes a parameter of
// the kernel: a symbol standing for p[j] (the kernel ABI's third argument)
// instead of a constant folded into the algebra. Two systems whose numbers
// differ only in value are then one kernel: a parameter scan, a map that
// makes a new system at every step, a Lagrangian redefined in the REPL with
// new numbers compile once. Numbers that change a kernel's structure stay
// constants: exact numbers, exponents and 0. (a term with a zero
// coefficient vanishes: an effect switched off costs nothing). Every other
// flonum is a parameter, even 1. or 2.: folded, it would round otherwise
// than the executable's run-time value of the same number. Equal flonums
// are one parameter.
//
// Parameter j is the uninterned symbol k<j>. sicm build says which values
// are captured run-time values (is_captured: a symbol or an expression that
// does not depend on the kernel's inputs), so that a value known only at
// run time that the procedure captured (a (parameter), a result of an
// earlier integration) is a parameter in the same way: the trace of a
// system derivative is then the same in both modes, and so is its C.
class KernelParameters {
public:
  using CapturedTest = bool (*)(Value v);
  explicit KernelParameters(CapturedTest is_captured = nullptr);
  ~KernelParameters();
  KernelParameters(const KernelParameters &) = delete;
  KernelParameters &operator=(const KernelParameters &) = delete;

  // Parameter j: the symbol that stands for it and its value (a flonum, or
  // with hooks a run-time value).
  gcvec<Symbol *> symbols;
  gcvec<Value> values;

  // For symbolic.cpp: the parameter standing for v (made on first use), and
  // whether v is a captured run-time value.
  Value parameter_for(Value v);
  bool is_captured(Value v) const { return is_captured_ && is_captured_(v); }

private:
  CapturedTest is_captured_;
  KernelParameters *outer_;
  // Parameter of each value met: flonums by their bits, run-time values by
  // their expression.
  std::unordered_map<uint64_t, size_t> by_bits_;
  std::unordered_map<uint32_t, size_t> by_expression_;
};

// Register the algebra's primitives (simplify, print-expression, pe,
// expression, datum->expression) and the printer's converter that shows an
// expression as its simplified prefix form. Called by init_interpreter.
void install_algebra_primitives();

} // namespace sicm
