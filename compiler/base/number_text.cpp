// Numbers as text: reading them as MIT Scheme's reader does (radixes,
// exactness prefixes, decimals with exponents, ratios, complex numbers in
// rectangular and polar form) and writing them as MIT Scheme writes them.
// The tower itself is number.cpp.
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "base/number.hpp"
#include "base/number_internal.hpp"
#include "base/primitive.hpp"
#include "sicm/runtime.h"

namespace sicm {

// ---- text: parsing ---------------------------------------------------------------------

namespace {

int digit_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'z') return c - 'a' + 10;
  if (c >= 'A' && c <= 'Z') return c - 'A' + 10;
  return 99;
}

bool all_digits(std::string_view s, int radix) {
  if (s.empty()) return false;
  for (char c : s)
    if (digit_value(c) >= radix) return false;
  return true;
}

// An unsigned digit string (already validated) as an exact integer.
void digits_to_mpz(std::string_view s, int radix, mpz_ptr z) {
  std::string copy(s);
  mpz_set_str(z, copy.c_str(), radix);
}

// The pieces of a decimal like "12.5e-3": digits "125", exponent -4.
struct Decimal {
  std::string digits;
  long exponent = 0;
};

std::optional<long> parse_exponent(std::string_view s) {
  bool negative = false;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    negative = s[0] == '-';
    s.remove_prefix(1);
  }
  if (!all_digits(s, 10) || s.size() > 9) return std::nullopt;
  long e = std::strtol(std::string(s).c_str(), nullptr, 10);
  return negative ? -e : e;
}

std::optional<Decimal> parse_decimal(std::string_view s) {
  size_t e = s.find_first_of("eE");
  std::string_view mantissa = s.substr(0, e);
  Decimal d;
  if (e != std::string_view::npos) {
    auto exponent = parse_exponent(s.substr(e + 1));
    if (!exponent) return std::nullopt;
    d.exponent = *exponent;
  }
  size_t point = mantissa.find('.');
  std::string_view whole = mantissa.substr(0, point);
  std::string_view fraction =
      point == std::string_view::npos ? std::string_view() : mantissa.substr(point + 1);
  if (whole.empty() && fraction.empty()) return std::nullopt;
  if ((!whole.empty() && !all_digits(whole, 10)) ||
      (!fraction.empty() && !all_digits(fraction, 10)))
    return std::nullopt;
  d.digits = std::string(whole) + std::string(fraction);
  d.exponent -= static_cast<long>(fraction.size());
  return d;
}

// #e1e999999999 would need a gigabyte; refuse absurd exact exponents.
constexpr long kMaxExactExponent = 1000000;

// A decimal denotes digits * 10^exponent exactly (used by #e).
Value exact_decimal(const Decimal &d, bool negative) {
  Q q;
  digits_to_mpz(d.digits, 10, mpq_numref(q.v));
  Z power;
  mpz_ui_pow_ui(power, 10, static_cast<unsigned long>(std::labs(d.exponent)));
  if (d.exponent >= 0)
    mpz_mul(mpq_numref(q.v), mpq_numref(q.v), power);
  else
    mpz_set(mpq_denref(q.v), power);
  if (negative) mpz_neg(mpq_numref(q.v), mpq_numref(q.v));
  return make_rational(q);
}

// strtod rounds correctly, so the flonum is the one nearest the decimal.
Value inexact_decimal(std::string_view text) {
  std::string copy(text);
  return Value::flonum(std::strtod(copy.c_str(), nullptr));
}

std::optional<Value> parse_ratio(std::string_view s, size_t slash, int radix, bool negative) {
  std::string_view n = s.substr(0, slash), d = s.substr(slash + 1);
  if (!all_digits(n, radix) || !all_digits(d, radix)) return std::nullopt;
  Q q;
  digits_to_mpz(n, radix, mpq_numref(q.v));
  digits_to_mpz(d, radix, mpq_denref(q.v));
  if (mpz_sgn(mpq_denref(q.v)) == 0) return std::nullopt;
  if (negative) mpz_neg(mpq_numref(q.v), mpq_numref(q.v));
  return make_rational(q);
}

std::optional<Value> parse_integer(std::string_view s, int radix, bool negative) {
  if (!all_digits(s, radix)) return std::nullopt;
  if (radix == 10 && s.size() <= 18) {
    int64_t v = 0;
    for (char c : s)
      v = v * 10 + (c - '0');
    return Value::fixnum(negative ? -v : v);
  }
  Z z;
  digits_to_mpz(s, radix, z);
  if (negative) mpz_neg(z, z);
  return make_integer(z);
}

std::optional<Value> parse_special(std::string_view s) {
  if (s == "+inf.0") return Value::flonum(HUGE_VAL);
  if (s == "-inf.0") return Value::flonum(-HUGE_VAL);
  if (s == "+nan.0" || s == "-nan.0") return Value::flonum(std::nan(""));
  return std::nullopt;
}

// A real number without prefixes; exactness is 'e', 'i' or 0 (as written).
std::optional<Value> parse_real(std::string_view s, int radix, char exactness) {
  if (auto special = parse_special(s)) {
    if (exactness == 'e') return std::nullopt;
    return special;
  }
  bool negative = !s.empty() && s[0] == '-';
  std::string_view body = s;
  if (!body.empty() && (body[0] == '+' || body[0] == '-')) body.remove_prefix(1);
  if (body.empty()) return std::nullopt;
  if (size_t slash = body.find('/'); slash != std::string_view::npos)
    return parse_ratio(body, slash, radix, negative);
  if (all_digits(body, radix)) return parse_integer(body, radix, negative);
  if (radix != 10) return std::nullopt;
  auto decimal = parse_decimal(body);
  if (!decimal) return std::nullopt;
  if (exactness == 'e') {
    if (std::labs(decimal->exponent) > kMaxExactExponent) return std::nullopt;
    return exact_decimal(*decimal, negative);
  }
  return inexact_decimal(s);
}

// Reads "#x", "#e", ... prefixes: at most one radix and one exactness.
bool parse_prefixes(std::string_view &text, int &radix, char &exactness) {
  bool radix_seen = false;
  while (text.size() >= 2 && text[0] == '#') {
    char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[1])));
    if (c == 'e' || c == 'i') {
      if (exactness) return false;
      exactness = c;
    } else {
      int r = c == 'x' ? 16 : c == 'b' ? 2 : c == 'o' ? 8 : c == 'd' ? 10 : 0;
      if (!r || radix_seen) return false;
      radix = r;
      radix_seen = true;
    }
    text.remove_prefix(2);
  }
  return true;
}

// A real number with its #e or #i prefix applied.
std::optional<Value> parse_real_part(std::string_view text, int radix, char exactness) {
  auto v = parse_real(text, radix, exactness);
  if (!v) return std::nullopt;
  if (exactness == 'i' && !is_flonum(*v)) return num_exact_to_inexact(*v);
  if (exactness == 'e' && is_flonum(*v)) {
    if (!std::isfinite(v->d)) return std::nullopt;
    return num_inexact_to_exact(*v);
  }
  return v;
}

// Where the imaginary part of "x+yi" (without its i) begins: the last sign
// that neither begins the text nor follows the exponent marker of a decimal.
size_t imaginary_part_start(std::string_view s, int radix) {
  for (size_t j = s.size(); j-- > 1;) {
    if (s[j] != '+' && s[j] != '-') continue;
    bool exponent = radix == 10 && (s[j - 1] == 'e' || s[j - 1] == 'E') && j >= 2 &&
                    (std::isdigit(static_cast<unsigned char>(s[j - 2])) || s[j - 2] == '.');
    if (!exponent) return j;
  }
  return s.empty() || (s[0] != '+' && s[0] != '-') ? std::string_view::npos : 0;
}

// The complex forms "x+yi", "x-i", "+yi", "-i" and "magnitude@angle", each
// part a real number as parse_real reads it (with the prefixes applied).
std::optional<Value> parse_complex(std::string_view s, int radix, char exactness) {
  if (size_t at = s.find('@'); at != std::string_view::npos) {
    auto magnitude = parse_real_part(s.substr(0, at), radix, exactness);
    auto angle = parse_real_part(s.substr(at + 1), radix, exactness);
    if (!magnitude || !angle) return std::nullopt;
    return make_polar(*magnitude, *angle);
  }
  if (s.size() < 2 || (s.back() != 'i' && s.back() != 'I')) return std::nullopt;
  s.remove_suffix(1);
  size_t k = imaginary_part_start(s, radix);
  if (k == std::string_view::npos) return std::nullopt;
  std::string_view im_text = s.substr(k);
  std::optional<Value> im;
  if (im_text == "+" || im_text == "-") // an exact 1 even after #i, as MIT reads it
    im = Value::fixnum(im_text == "+" ? 1 : -1);
  else
    im = parse_real_part(im_text, radix, exactness);
  std::optional<Value> re = Value::fixnum(0);
  if (k > 0) re = parse_real_part(s.substr(0, k), radix, exactness);
  if (!re || !im) return std::nullopt;
  return make_rectangular(*re, *im);
}

} // namespace

std::optional<Value> parse_number(std::string_view text, int radix) {
  char exactness = 0;
  if (!parse_prefixes(text, radix, exactness)) return std::nullopt;
  if (auto real = parse_real_part(text, radix, exactness)) return real;
  return parse_complex(text, radix, exactness);
}

// ---- text: printing ----------------------------------------------------------------------

namespace {

std::string mpz_to_string(mpz_srcptr z, int radix) {
  std::string s(mpz_sizeinbase(z, radix) + 2, '\0');
  mpz_get_str(s.data(), radix, z);
  s.resize(std::strlen(s.c_str()));
  return s;
}

std::string fixnum_to_string(int64_t i, int radix) {
  if (radix == 10) return std::to_string(i);
  Z z;
  mpz_set_si(z, i);
  return mpz_to_string(z, radix);
}

std::string flonum_to_string(double d, int radix) {
  if (radix != 10 && std::isfinite(d) && d == std::floor(d)) {
    Z z;
    flonum_to_mpz(d, z);
    return mpz_to_string(z, radix) + ".";
  }
  if (radix != 10) bad_range(Value::fixnum(radix), 2, "number->string");
  char buf[SICM_DOUBLE_BUFSIZE];
  size_t n = sicm_format_double(buf, d);
  return std::string(buf, n);
}

} // namespace

std::string number_to_string(Value v, int radix) {
  switch (v.tag) {
  case Tag::Fixnum: return fixnum_to_string(v.i, radix);
  case Tag::Flonum: return flonum_to_string(v.d, radix);
  case Tag::Bignum: return mpz_to_string(big(v), radix);
  case Tag::Ratnum:
    return mpz_to_string(mpq_numref(rat(v)), radix) + "/" +
           mpz_to_string(mpq_denref(rat(v)), radix);
  case Tag::Recnum: return complex_to_string(v, radix);
  default: wrong_type(v, 1, "number->string");
  }
}

} // namespace sicm
