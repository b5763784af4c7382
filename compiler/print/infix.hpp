// Conventional renderings of prefix expression data: infix text and TeX.
//
// Both take the datum an expression prints as ((+ (* 1/2 m (expt v 2)) ...),
// (up a b), (((partial 1) L) s)) and never simplify: they show what they get.
//
// Infix conventions (one line of UTF-8):
//   sums        a + b - c            a term (* -1 x) or (* -2 x) shows as - x,
//                                    - 2 x; a leading one as -x, -2 x
//   products    1/2 m v              factors side by side with a space; a
//                                    factor that begins with a digit gets " * "
//   quotients   pₓ(t) / m            (x + y) / (2 m); a quotient inside a
//                                    product is parenthesized: 2 (a / b)
//   powers      x^2, (x + y)^2       x^-1, x^(1/2), (x^2)^3
//   functions   f(t), sin(θ), √x     √(x + y), |x|
//   derivatives Dx(t), D²x(t)        (((partial 1 0) H) s) -> ∂₁,₀H(s);
//                                    an operand that is not a name is
//                                    parenthesized: D(f + g)(t)
//   structures  up(a, b), down(a, b)
//   matrices    [[a, b], [c, d]]     from (matrix-by-rows (list a b) (list c d))
//   other lists (1, 2, 3)            a list not headed by a symbol or a list
//   names       display_name(): θ, θ̇, pₓ (print/display_names.hpp)
//
// TeX conventions: \frac{a}{b}, x^{2}, \sin\left(\theta\right),
// f\left(t\right), \dot{\theta}, p_{x}, D^{2}x\left(t\right), \partial_{1,0},
// \sqrt{x}, up as \begin{pmatrix} a \\ b \end{pmatrix}, down as
// \begin{bmatrix} a & b \end{bmatrix}, matrices as bmatrix rows.
//
// Dot notation (off unless set_dot_notation(true); `sicm repl --kernel` and
// (set-dot-notation! #t) turn it on, for both renderings): a function of
// time applied to the symbol t is written as the book's typeset equations
// write it, without the argument and with a dot per time derivative:
// ((D theta) t) -> θ̇ / \dot{\theta}, (((expt D 2) theta) t) -> θ̈ /
// \ddot{\theta}, (theta t) -> θ / \theta. Only a literal function's name is
// shortened, never sin(t) and its kind, and only up to three dots; other
// derivatives keep their D.
#pragma once

#include <string>

#include "base/value.hpp"

namespace sicm {

std::string datum_to_infix(Value datum);
std::string datum_to_tex(Value datum);

// The dot notation above, for every rendering after the call.
void set_dot_notation(bool on);

// (->tex-string v): v in TeX, as shown (builtins/show.cpp).
std::string value_to_tex(Value v);

// show-expression, ->infix, ->tex-string (builtins/show.cpp).

// Shapes of prefix data that both renderers recognize (print/infix.cpp).
namespace expr_shape {

// d is a list (name ...).
bool head_is(Value d, const char *name);
// d would show with a leading minus: a negative number, (* c ...) with a
// negative number c, (- x), or a quotient whose numerator is one of these.
bool is_negative_term(Value d);
// The datum shown after that minus (precondition: is_negative_term(d)):
// -3 -> 3, (* -1 x) -> x, (* -2 x y) -> (* 2 x y), (- x) -> x.
Value negate_term(Value d);
// d denotes an operator on functions: D, (partial i ...), (expt OP n).
bool is_operator(Value d);
// d is (OP f): an operator applied to a function, such as (D x).
bool is_operator_application(Value d);
// d is a non-negative exact integer (shown without sign or fraction).
bool is_natural(Value d);

} // namespace expr_shape

} // namespace sicm
