// The numeric tower: exact integers of any size (int64 fixnums, GMP bignums),
// exact rationals (GMP), IEEE flonums, and complex numbers whose parts are
// any of those (recnums, complex.cpp), with MIT Scheme's rules:
//   - results are normalized: an integral rational is an integer, an integer
//     that fits in int64 is a fixnum;
//   - exactness is contagious the usual way: exact op exact is exact, anything
//     with a flonum is a flonum;
//   - exact division by zero is an error ("Division by zero signalled by /.");
//   - a recnum's imaginary part is never an exact zero (that number is real);
//     operations that leave the reals (sqrt of a negative number, log of one,
//     asin 2) give recnums; comparisons, rounding and integer operations take
//     only real numbers.
// Errors (wrong type, division by zero) are thrown with runtime_error() at
// current_call_loc(), naming the procedure, as MIT does:
//   "The object foo, passed as the first argument to integer-add, is not the correct type."
#pragma once

#include <gmp.h>

#include <optional>
#include <string>
#include <string_view>

#include "base/value.hpp"

namespace sicm {

struct Bignum {
  mpz_t z; // cleared by a GC finalizer
};
struct Ratnum {
  mpq_t q; // canonical (lowest terms, positive denominator); cleared by a GC finalizer
};
struct Recnum {
  Value re, im; // real numbers; im is not an exact 0
};

// ---- classification ----
bool is_number(Value v);         // any number, complex included
bool is_exact(Value v);          // fixnum, bignum, ratnum, recnum of exact parts
bool is_exact_integer(Value v);  // fixnum, bignum
bool is_exact_rational(Value v); // fixnum, bignum, ratnum
bool is_integer(Value v);        // exact integer or integral finite flonum
bool is_real(Value v);           // a number that is not a recnum
bool is_recnum(Value v);         // a complex number that is not real

// ---- construction ----
Value make_integer(const mpz_t z);  // normalizes to fixnum when it fits
Value make_rational(const mpq_t q); // q need not be canonical; normalizes
// q must be canonical: no gcd (which for millions of bits takes minutes).
Value make_canonical_rational(mpq_srcptr q);
Value make_integer_from_string(std::string_view digits, int radix = 10);
double to_double(Value v); // any number -> nearest double
// Exact integer value as int64 if it fits; nullopt otherwise (or if not an exact integer).
std::optional<int64_t> to_int64(Value v);
// Copy an exact integer or rational into q (q must be initialized).
void to_mpq(Value v, mpq_t q);

// ---- complex numbers (complex.cpp) ----
// make-rectangular of two real numbers: re when im is an exact 0.
Value make_rectangular(Value re, Value im);
Value make_polar(Value magnitude, Value angle); // (make-polar 1 0) is exact 1
Value num_real_part(Value z);
Value num_imag_part(Value z); // exact 0 for a real
Value num_magnitude(Value z); // exact for exact parts with a perfect-square norm
Value num_angle(Value z);     // exact 0 for a non-negative exact real
Value num_conjugate(Value z);

// ---- arithmetic (arguments must be numbers; `who` names the procedure in errors) ----
Value num_add(Value a, Value b);
Value num_sub(Value a, Value b);
Value num_mul(Value a, Value b);
Value num_div(Value a, Value b);
Value num_neg(Value a);
int num_compare(Value a, Value b); // -1, 0, 1; NaN compares as unordered -> 2
bool num_equal(Value a, Value b);
bool num_is_zero(Value a);
int num_sign(Value a); // -1, 0, 1
Value num_abs(Value a);

Value num_quotient(Value a, Value b); // integers (exact or integral flonums)
Value num_remainder(Value a, Value b);
Value num_modulo(Value a, Value b);
Value num_gcd(Value a, Value b);
Value num_lcm(Value a, Value b);

Value num_floor(Value a);
Value num_ceiling(Value a);
Value num_round(Value a); // to even
Value num_truncate(Value a);
Value num_numerator(Value a);
Value num_denominator(Value a);

Value num_exact_to_inexact(Value a);
Value num_inexact_to_exact(Value a); // a flonum becomes the exact rational it denotes

// expt: exact base and exact integer exponent -> exact (negative exponents give
// rationals); exact rational base with exact rational exponent gives an exact
// result when it is one ((expt 4 1/2) = 2), otherwise flonum.
Value num_expt(Value base, Value exponent);
// sqrt: exact for exact perfect squares (integers and rationals), else flonum;
// a negative or complex argument has its principal root ((sqrt -4) is +2i).
Value num_sqrt(Value a);
// (exact-integer-sqrt n): s and r with s^2 + r = n.
std::pair<Value, Value> num_exact_integer_sqrt(Value n);

Value num_exp(Value a); // (exp 0) is exact 1, as in MIT
Value num_log(Value a); // (log 1) is exact 0
Value num_sin(Value a); // (sin 0) is exact 0
Value num_cos(Value a); // (cos 0) is exact 1
Value num_tan(Value a);
Value num_asin(Value a);
Value num_acos(Value a);
Value num_atan(Value a);
Value num_atan2(Value y, Value x); // (atan 0 1) is exact 0

// ---- text ----
// Parse a numeric literal as the reader sees it: "42", "-5/128", ".5", "1.",
// "1e-13", "-1.5987211554602254e-14", "#x1F", "#e1.5", "#i1/3", "+inf.0",
// "-inf.0", "+nan.0", "1+2i", "-i", "1.5e3-2/3i", "2@1.5" (polar). Returns nullopt if text is not a
// number (then the reader treats it as a symbol).
std::optional<Value> parse_number(std::string_view text, int radix = 10);
// MIT Scheme's printed form: "42", "1/2", "435.", ".7518269446689928",
// "-1.5987211554602254e-14", "+inf.0", "+nan.0", "1+2i", "+i", "1.5-2.i".
std::string number_to_string(Value v, int radix = 10);

// The primitives of this module (+ - * / = < > <= >= max min quotient
// remainder modulo gcd lcm abs floor ceiling round truncate floor->exact
// round->exact ... exact->inexact inexact->exact exact inexact number?
// integer? rational? real? complex? exact? inexact? zero? positive? negative?
// odd? even? expt sqrt exact-integer-sqrt exp log sin cos tan asin acos atan
// number->string string->number numerator denominator 1+ -1+ 1- square cube
// exact-rational? exact-nonnegative-integer? nan? integer-floor
// integer-ceiling integer-round integer-truncate random).

} // namespace sicm
