// Operators: D, (partial i j ...), and their arithmetic (products compose,
// sums add, (expt D 2) is D applied twice), plus literal functions, whose
// derivatives are literal functions printed as (D f), ((expt D 2) f),
// ((partial 1 0) H).
#pragma once

#include <vector>

#include "base/value.hpp"

namespace sicm {

bool is_operator(Value v);
// Apply an operator to a function, giving a function.
Value apply_operator(Value op, Value f);
// Is op c D, D times something that is not an operator (D itself: c = 1)?
bool is_derivative_multiple(Value op, Value *c);
// The derivative of f with respect to the argument component selected by
// `path` (empty: with respect to every argument, as D does).
Value derivative_of(Value f, const std::vector<int> &path);

// A literal function: head is its name (or the expression naming a derived
// function), type the evaluated type expression ((-> Real Real) by default).
Value make_literal_function(Value name, Value type);
bool is_literal_function(Value v);

// Register operators and literal functions with generic arithmetic and
// define D, partial, derivative, literal-function, make-operator? ...
void install_operator_primitives();
// Define literal-function and literal-function?.
void install_literal_function_primitives();

} // namespace sicm
