// Generic arithmetic: + - * / sin ... over numbers, expressions, structures and functions.
//
// Numbers take a fast path straight into the numeric tower (base/number.hpp).
// Every other kind of value belongs to an *arithmetic type*: a row of a small
// table giving a membership test, a rank and the handlers of the unary and
// binary operations. An operation on a value of some type is handled by that
// type; a binary operation on two values of different types is handled by the
// type of higher rank, which treats the other operand as a coefficient:
//
//   rank 10  symbolic   symbols used as numbers, expressions (algebra/symbolic.hpp)
//   rank 15  differential  tagged infinitesimals of AD (algebra/differential.hpp)
//   rank 30  function   procedures: (+ f g) is x |-> (+ (f x) (g x))
//   rank 32  structure  up/down tuples and matrices (algebra/structure.hpp); above
//            functions, as in scmutils: (* f (down g h)) is (down (* f g) (* f h))
//   rank 35  series     lazy power series (algebra/series.hpp)
//   rank 40  operator   D, partial, make-operator (algebra/operator.hpp)
//
// A new kind of value (differentials, operators, series) is added by
// registering one more ArithType with a suitable rank; nothing else changes.
//
// Two identities hold for any arithmetic value x, as in scmutils:
// (+ 0 x) = (+ x 0) = x and (* 1 x) = (* x 1) = x with exact 0 and 1; so
// (+ 0 (up 1 2)) is (up 1 2) although numbers and structures cannot be added.
// Values of no arithmetic type (strings, lists, ...) raise MIT's error for the
// primitive the operation stands for:
//   "The object "a", passed as the second argument to integer-add, is not the correct type."
#pragma once

#include <cstdint>

#include "base/number.hpp"
#include "base/value.hpp"
#include "eval/procedure.hpp"

namespace sicm {

enum class UnaryOp : uint8_t {
  Neg,
  Invert,
  Sqrt,
  Exp,
  Log,
  Sin,
  Cos,
  Tan,
  Asin,
  Acos,
  Atan,
  Abs,
  Magnitude,
  Square,
  Cube,
  ZeroP, // the result is a boolean
};

enum class BinaryOp : uint8_t {
  Add,
  Sub,
  Mul,
  Div,
  Expt,
  Atan2, // (atan y x)
  Equal, // the result is a boolean
};

// The Scheme name of an operation ("+", "sin") and the name MIT's errors use
// for it ("integer-add", "sin").
const char *op_scheme_name(UnaryOp op);
const char *op_scheme_name(BinaryOp op);
const char *op_error_name(UnaryOp op);
const char *op_error_name(BinaryOp op);

struct ArithType {
  const char *name;
  int rank;                // higher ranks handle mixed operations
  bool (*member)(Value v); // does v belong to this type?
  Value (*unary)(UnaryOp op, Value x);
  // Called when a or b is of this type and the other is of a type of rank
  // no higher (or a number, or no arithmetic value at all: then raise).
  Value (*binary)(BinaryOp op, Value a, Value b);
};

// Add a type to the table (at startup). Types are consulted in rank order,
// highest first, so a more specific type (operators among procedures) needs
// a higher rank than the general one.
void register_arith_type(const ArithType *type);
// The arithmetic type of v, or null for numbers and non-arithmetic values.
const ArithType *arith_type_of(Value v);
// A number or a value of some arithmetic type.
bool is_arithmetic(Value v);

// ---- the generic operations ----
Value g_unary(UnaryOp op, Value x);
Value g_binary(BinaryOp op, Value a, Value b);

inline Value g_add(Value a, Value b) {
  if (is_number(a) && is_number(b)) return num_add(a, b);
  return g_binary(BinaryOp::Add, a, b);
}
inline Value g_sub(Value a, Value b) {
  if (is_number(a) && is_number(b)) return num_sub(a, b);
  return g_binary(BinaryOp::Sub, a, b);
}
inline Value g_mul(Value a, Value b) {
  if (is_number(a) && is_number(b)) return num_mul(a, b);
  return g_binary(BinaryOp::Mul, a, b);
}
inline Value g_div(Value a, Value b) {
  if (is_number(a) && is_number(b)) return num_div(a, b);
  return g_binary(BinaryOp::Div, a, b);
}
inline Value g_neg(Value x) {
  return is_number(x) ? num_neg(x) : g_unary(UnaryOp::Neg, x);
}
Value g_expt(Value base, Value exponent);
Value g_square(Value x);
bool g_zero_p(Value x);         // exact or inexact zero, a zero expression, all-zero structure
bool g_equal(Value a, Value b); // =
bool is_exact_zero(Value v);    // the fixnum 0
bool is_exact_one(Value v);     // the fixnum 1

// Errors for impossible combinations, in MIT's words, naming the primitive.
[[noreturn]] void arith_wrong_type(UnaryOp op, Value x);
[[noreturn]] void arith_wrong_type(BinaryOp op, Value obj, int argpos);

// ---- procedures made in C++ (algebra/function_arith.cpp) ----
// An applicable object printed as #[compound-procedure N]: sums and products
// of functions, compositions, component selectors.
struct NativeProc;
using NativeFn = Value (*)(NativeProc *self, Value *args, int nargs);
struct NativeProc {
  NativeFn fn;
  int op;       // an operation, for combinations
  Value a, b;   // operands or captured data
  Value *items; // captured values (compose: the functions), GC memory
  size_t nitems;
  Closure print_as; // gives the object its #[compound-procedure N] number
};
Value make_native_procedure(NativeFn fn, int op, Value a, Value b, const Value *items = nullptr,
                            size_t nitems = 0);
// MIT's arity error for a NativeProc that takes exactly `required` arguments.
[[noreturn]] void native_arity_error(NativeProc *self, int given, int required);
// ... "it requires between 4 and 6 arguments." (exactly, when min == max).
[[noreturn]] void native_arity_error(NativeProc *self, int given, int min, int max);
// (op a b) as a function, x... |-> (op (a x...) (b x...)): what a sum or
// difference of a structure or matrix and a procedure is, the structure
// applied entry by entry (arithmetic on structures of functions is
// arithmetic on functions, as in scmutils).
Value function_combination(BinaryOp op, Value a, Value b);
// (compose f g ...): the procedure x... |-> (f (g ... x...)).
Value compose_procedures(const Value *fs, size_t n);

// Register the arithmetic types (symbolic, structure, function) and the
// generic primitives: + - * / = zero? square cube expt sqrt exp log sin cos
// tan asin acos atan abs negate invert magnitude 1+ -1+ 1- compose, and the
// structure and matrix primitives. Replaces the numbers-only bindings of
// install_number_primitives, so it must run after it.
void install_generic_primitives();
// <, >, <=, >=, positive?, negative?, max and min extended to differentials
// (algebra/comparison.cpp); called by install_generic_primitives.
void install_differential_comparisons();
void register_symbolic_arith();
void register_function_arith();

} // namespace sicm
