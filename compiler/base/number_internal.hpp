// What number.cpp (the numeric tower) shares with complex.cpp (its complex
// numbers), number_text.cpp (reading and writing them) and
// builtins/number.cpp (its primitives) and no one else: scoped GMP integers
// and rationals, argument checks, the comparison and integer division that
// MIT's primitives are written over, and the complex operations.
#pragma once

#include <gmp.h>

#include "base/number.hpp"
#include "base/primitive.hpp"

namespace sicm {

// A scoped mpz, so that a thrown error never leaks its limbs.
struct Z {
  mpz_t v;
  Z() { mpz_init(v); }
  ~Z() { mpz_clear(v); }
  Z(const Z &) = delete;
  Z &operator=(const Z &) = delete;
  operator mpz_ptr() { return v; }
  operator mpz_srcptr() const { return v; }
};

// A scoped mpq.
struct Q {
  mpq_t v;
  Q() { mpq_init(v); }
  ~Q() { mpq_clear(v); }
  Q(const Q &) = delete;
  Q &operator=(const Q &) = delete;
  operator mpq_ptr() { return v; }
  operator mpq_srcptr() const { return v; }
};

inline mpz_srcptr big(Value v) {
  return v.as<Bignum>()->z;
}

inline mpq_srcptr rat(Value v) {
  return v.as<Ratnum>()->q;
}

// The integer a flonum holds (it must be integral and finite).
inline void flonum_to_mpz(double d, mpz_ptr z) {
  mpz_set_d(z, d);
}

inline bool is_flonum(Value v) {
  return v.tag == Tag::Flonum;
}

// The argument check of the operations of real numbers (comparison,
// rounding, integer division, ...): a recnum is the wrong type there, as in MIT.
inline void check_number(Value v, int argpos, const char *who) {
  if (!is_real(v)) wrong_type(v, argpos, who);
}

[[noreturn]] void divide_by_zero(const char *who);

// ---- complex arithmetic (complex.cpp) ----
// Called by the operations of number.cpp when an argument is a recnum (or a
// real argument takes the result out of the reals, for the functions so
// marked); any argument may be a real number.
Value complex_add(Value a, Value b);
Value complex_sub(Value a, Value b);
Value complex_mul(Value a, Value b);
Value complex_div(Value a, Value b); // b not zero
bool complex_equal(Value a, Value b);
bool complex_is_zero(Value z);
Value complex_exact_to_inexact(Value z);
Value complex_inexact_to_exact(Value z);
Value complex_exp(Value z);
Value complex_log(Value z);           // also a negative real
Value complex_sqrt(Value z);          // also a negative real
Value complex_expt(Value b, Value e); // also a negative real b with a non-integer e
Value complex_sin(Value z);
Value complex_cos(Value z);
Value complex_tan(Value z);
Value complex_asin(Value z); // also a real outside [-1, 1]
Value complex_acos(Value z); // also a real outside [-1, 1]
Value complex_atan(Value z);
std::string complex_to_string(Value z, int radix);

// -1, 0 or 1 as a < b, a = b, a > b; 2 when a NaN makes them unordered.
// Exact and inexact numbers compare exactly (no rounding of the exact one).
int compare_numbers(Value a, Value b);

enum class Div { Quotient, Remainder, Modulo, Floor, Ceiling, Round };

// Integer division of any kind, MIT style: flonum arguments must be integral
// and make the result a flonum.
Value integer_divide(Div kind, Value n, Value d, const char *who);

} // namespace sicm
