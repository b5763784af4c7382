// What number.cpp (the numeric tower) shares with builtins_number.cpp (its
// primitives) and no one else: scoped GMP integers, argument checks, and the
// comparison and integer division that MIT's primitives are written over.
#pragma once

#include <gmp.h>

#include "eval/number.hpp"
#include "eval/primitive.hpp"

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

inline mpz_srcptr big(Value v) {
  return v.as<Bignum>()->z;
}

inline bool is_flonum(Value v) {
  return v.tag == Tag::Flonum;
}

inline void check_number(Value v, int argpos, const char *who) {
  if (!is_number(v)) wrong_type(v, argpos, who);
}

// -1, 0 or 1 as a < b, a = b, a > b; 2 when a NaN makes them unordered.
// Exact and inexact numbers compare exactly (no rounding of the exact one).
int compare_numbers(Value a, Value b);

enum class Div { Quotient, Remainder, Modulo, Floor, Ceiling, Round };

// Integer division of any kind, MIT style: flonum arguments must be integral
// and make the result a flonum.
Value integer_divide(Div kind, Value n, Value d, const char *who);

} // namespace sicm
