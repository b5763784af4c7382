// Unit tests of flonum printing (runtime/src/format_double.c) against MIT Scheme's output.
#include <gmp.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>

#include "sicm/runtime.h"

namespace {

std::string fmt(double x) {
  char buf[SICM_DOUBLE_BUFSIZE];
  size_t n = sicm_format_double(buf, x);
  EXPECT_EQ(n, std::strlen(buf));
  return buf;
}

// Expected strings are MIT Scheme's (the flonum-printer's normal layout).
TEST(FormatDouble, Layout) {
  EXPECT_EQ(fmt(435.0), "435.");
  EXPECT_EQ(fmt(0.7518269446689928), ".7518269446689928");
  EXPECT_EQ(fmt(436.29121428571153), "436.29121428571153");
  EXPECT_EQ(fmt(-1.5987211554602254e-14), "-1.5987211554602254e-14");
  EXPECT_EQ(fmt(1e21), "1e21");
  EXPECT_EQ(fmt(1e-7), ".0000001");
  EXPECT_EQ(fmt(1e-10), ".0000000001");
  EXPECT_EQ(fmt(123.456), "123.456");
  EXPECT_EQ(fmt(0.1), ".1");
  EXPECT_EQ(fmt(1.0 / 3), ".3333333333333333");
  EXPECT_EQ(fmt(2.0 / 3), ".6666666666666666");
  EXPECT_EQ(fmt(.001), ".001");
  EXPECT_EQ(fmt(3.14), "3.14");
  EXPECT_EQ(fmt(1.0), "1.");
  EXPECT_EQ(fmt(-2.5), "-2.5");
  EXPECT_EQ(fmt(-0.5), "-.5");
  EXPECT_EQ(fmt(100.0), "100.");
  EXPECT_EQ(fmt(1e17), "100000000000000000.");
  EXPECT_EQ(fmt(1e18), "1e18");
  EXPECT_EQ(fmt(1.5e18), "1.5e18");
  EXPECT_EQ(fmt(1.2345678901234568e20), "1.2345678901234568e20");
  EXPECT_EQ(fmt(1e-300), "1e-300");
  EXPECT_EQ(fmt(1.5e-300), "1.5e-300");
  EXPECT_EQ(fmt(std::sqrt(2.0)), "1.4142135623730951");
  EXPECT_EQ(fmt(1.7976931348623157e308), "1.7976931348623157e308");
  EXPECT_EQ(fmt(9007199254740992.0), "9007199254740992.");
  // Positional form only while the last digit is within 17 places of the point.
  EXPECT_EQ(fmt(1e-17), ".00000000000000001");
  EXPECT_EQ(fmt(1e-18), "1e-18");
  EXPECT_EQ(fmt(1.5e-17), "1.5e-17");
  EXPECT_EQ(fmt(1.5e-16), ".00000000000000015");
}

TEST(FormatDouble, Specials) {
  EXPECT_EQ(fmt(0.0), "0.");
  EXPECT_EQ(fmt(-0.0), "-0.");
  EXPECT_EQ(fmt(HUGE_VAL), "+inf.0");
  EXPECT_EQ(fmt(-HUGE_VAL), "-inf.0");
  EXPECT_EQ(fmt(std::nan("")), "+nan.0");
}

// MIT uses Dragon4, which excludes the interval's boundaries even where
// round-to-even would read them back, and normalizes subnormals to 53 bits.
// The subnormal strings are from MIT's own test suite (tests/runtime/test-arith.scm).
TEST(FormatDouble, DragonBoundaries) {
  EXPECT_EQ(fmt(1e23), "9.999999999999999e22");
  EXPECT_EQ(fmt(7e22), "7.0000000000000004e22");
  EXPECT_EQ(fmt(std::ldexp(1.0, -1074)), "4.9406564584124654e-324");
  EXPECT_EQ(fmt(std::ldexp(1.0, -1024)), "5.562684646268004e-309");
  EXPECT_EQ(fmt(std::ldexp(1.0, -1023)), "1.1125369292536007e-308");
  EXPECT_EQ(fmt(std::ldexp(1.0, -1022)), "2.2250738585072014e-308");
  // x exactly halfway between two 16-digit decimals, both inside: Dragon4 takes the lower.
  EXPECT_EQ(fmt(600000000000000.75), "600000000000000.7");
  EXPECT_EQ(fmt(600000000000000.25), "600000000000000.2");
}

TEST(FormatDouble, ShortestDigits) {
  char digits[18];
  int k = 0;
  EXPECT_EQ(sicm_shortest_digits(digits, &k, 0.1), 1u);
  EXPECT_STREQ(digits, "1");
  EXPECT_EQ(k, -1);
  EXPECT_EQ(sicm_shortest_digits(digits, &k, -123.456), 6u);
  EXPECT_STREQ(digits, "123456");
  EXPECT_EQ(k, 2);
  EXPECT_EQ(sicm_shortest_digits(digits, &k, 1e21), 1u);
  EXPECT_STREQ(digits, "1");
  EXPECT_EQ(k, 21);
  EXPECT_EQ(sicm_shortest_digits(digits, &k, 1.0 / 3), 16u);
  EXPECT_STREQ(digits, "3333333333333333");
  EXPECT_EQ(k, -1);
}

// ---- exact oracle, with GMP ---------------------------------------------------

// The exact value of a printed decimal such as "-1.5e-14", ".001" or "435.".
void decimal_value(const std::string &s, mpq_t out) {
  std::string digits;
  long exponent = 0, fraction_digits = 0;
  bool after_point = false;
  size_t i = s[0] == '-' ? 1 : 0;
  for (; i < s.size() && s[i] != 'e'; i++) {
    if (s[i] == '.')
      after_point = true;
    else {
      digits += s[i];
      fraction_digits += after_point;
    }
  }
  if (i < s.size()) exponent = std::strtol(s.c_str() + i + 1, nullptr, 10);
  exponent -= fraction_digits;
  mpz_t power;
  mpz_init(power);
  mpz_ui_pow_ui(power, 10, static_cast<unsigned long>(std::labs(exponent)));
  mpq_set_str(out, digits.c_str(), 10);
  if (exponent >= 0)
    mpz_mul(mpq_numref(out), mpq_numref(out), power);
  else
    mpz_mul(mpq_denref(out), mpq_denref(out), power);
  mpq_canonicalize(out);
  mpz_clear(power);
}

// (m + offset) * 2^e as a rational (m + offset needs more bits than a double has).
void dyadic(mpq_t out, double m, double offset, int e) {
  mpq_t off;
  mpq_init(off);
  mpq_set_d(out, m);
  mpq_set_d(off, offset);
  mpq_add(out, out, off);
  if (e >= 0)
    mpq_mul_2exp(out, out, e);
  else
    mpq_div_2exp(out, out, -e);
  mpq_clear(off);
}

// The rounding interval Dragon4 uses for |x|: half a unit of the 53-bit
// normalized significand each side, a quarter below a power of two.
struct Interval {
  mpq_t low, high;
  Interval(double x) {
    mpq_init(low);
    mpq_init(high);
    int e;
    double m = std::ldexp(std::frexp(std::fabs(x), &e), 53);
    e -= 53;
    dyadic(low, m, m == std::ldexp(1.0, 52) ? -0.25 : -0.5, e);
    dyadic(high, m, 0.5, e);
  }
  ~Interval() {
    mpq_clear(low);
    mpq_clear(high);
  }
  // -1, 0, 1: below, strictly inside, above; 2: exactly on a boundary.
  int locate(const std::string &s) const {
    mpq_t v;
    mpq_init(v);
    decimal_value(s[0] == '-' ? s.substr(1) : s, v);
    int lo = mpq_cmp(v, low), hi = mpq_cmp(v, high);
    mpq_clear(v);
    if (lo == 0 || hi == 0) return 2;
    return lo < 0 ? -1 : hi > 0 ? 1 : 0;
  }
  bool strictly_inside(const std::string &s) const { return locate(s) == 0; }
};

size_t significant_digits(const std::string &s) {
  std::string d;
  for (char c : s) {
    if (c == 'e') break;
    if (c >= '0' && c <= '9') d += c;
  }
  size_t first = d.find_first_not_of('0'), last = d.find_last_not_of('0');
  return last - first + 1;
}

// A million random bit patterns: the printed form reads back as x, lies
// strictly inside Dragon4's interval, and one digit fewer (printf's correctly
// rounded output) does not identify x.
TEST(FormatDouble, RandomRoundTripAndMinimal) {
  std::mt19937_64 bits(20240611);
  int checked = 0;
  while (checked < 1000000) {
    uint64_t u = bits();
    double x;
    std::memcpy(&x, &u, sizeof x);
    if (!std::isfinite(x) || x == 0) continue;
    checked++;
    std::string s = fmt(x);
    ASSERT_EQ(std::strtod(s.c_str(), nullptr), x) << s;
    Interval interval(x);
    ASSERT_TRUE(interval.strictly_inside(s)) << s;
    size_t n = significant_digits(s);
    if (n < 2) continue;
    char shorter[64];
    std::snprintf(shorter, sizeof shorter, "%.*e", static_cast<int>(n) - 2, x);
    bool reads_back = std::strtod(shorter, nullptr) == x;
    // Reading back is not enough for Dragon4: a subnormal's interval is
    // narrower than its real one, and a boundary is never inside.
    ASSERT_FALSE(reads_back && interval.strictly_inside(shorter)) << s << " vs " << shorter;
    bool normal = std::fabs(x) >= 0x1p-1022;
    if (normal && reads_back) {
      ASSERT_EQ(interval.locate(shorter), 2) << s << " vs " << shorter;
    }
  }
}

} // namespace

// Tolerances as people write them, for messages and --stats.
TEST(FormatTolerance, ShortestGFormThatReadsBack) {
  auto tol = [](double x) {
    char buf[SICM_DOUBLE_BUFSIZE];
    size_t n = sicm_format_tolerance(buf, x);
    return std::string(buf, n);
  };
  EXPECT_EQ(tol(1e-12), "1e-12");
  EXPECT_EQ(tol(2.5e-13), "2.5e-13");
  EXPECT_EQ(tol(0.01), "0.01");
  EXPECT_EQ(tol(1e-17), "1e-17");
  EXPECT_EQ(tol(0.1 + 0.2), "0.30000000000000004");
}
