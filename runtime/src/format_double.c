/* Flonum printing: shortest digits that identify a double, in MIT Scheme's layout. */
#include "sicm/runtime.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* MIT Scheme prints with Steele & White's free-format Dragon4, which yields the
 * shortest digit string strictly inside the rounding interval of x. Candidates
 * come from the correctly rounded output of printf("%.*e"): if any string of at
 * most 15 digits identifies x it is the 15-digit rounding of x (15-digit
 * decimals are further apart than the interval is wide); at 16 and 17 digits
 * the rounding or one of its two neighbours is the answer, and 17 always is.
 *
 * The interval test is exact, like Dragon4's, not a strtod round trip, because
 * the two differ in the cases MIT users see: a decimal exactly on a boundary
 * (1e23 reads back as x but Dragon4 excludes boundaries, so MIT prints
 * 9.999999999999999e22) and subnormals (Dragon4 normalizes them to 53 bits, so
 * MIT prints 2^-1074 as 4.9406564584124654e-324, not 5e-324). */

/* ---- exact comparison of D * 10^j with N * 2^F ---------------------------- */

/* Enough 32-bit words for 2^1024 * 5^343 * 2^1130 with room to spare. */
enum { BIG_WORDS = 112 };

typedef struct {
  uint32_t w[BIG_WORDS]; /* little-endian */
  int n;                 /* words in use */
} Big;

static void big_set(Big *b, uint64_t v) {
  b->n = 0;
  while (v) {
    b->w[b->n++] = (uint32_t)v;
    v >>= 32;
  }
}

static void big_mul_small(Big *b, uint32_t k) {
  uint64_t carry = 0;
  for (int i = 0; i < b->n; i++) {
    uint64_t t = (uint64_t)b->w[i] * k + carry;
    b->w[i] = (uint32_t)t;
    carry = t >> 32;
  }
  if (carry && b->n < BIG_WORDS) b->w[b->n++] = (uint32_t)carry;
}

static void big_mul_pow5(Big *b, int k) {
  static const uint32_t pow5[14] = {1,       5,        25,        125,       625,
                                    3125,    15625,    78125,     390625,    1953125,
                                    9765625, 48828125, 244140625, 1220703125};
  for (; k >= 13; k -= 13)
    big_mul_small(b, pow5[13]);
  big_mul_small(b, pow5[k]);
}

static void big_shift_left(Big *b, int bits) {
  int words = bits / 32, rest = bits % 32;
  if (b->n == 0) return;
  if (rest) {
    uint32_t carry = 0;
    for (int i = 0; i < b->n; i++) {
      uint32_t next = b->w[i] >> (32 - rest);
      b->w[i] = (b->w[i] << rest) | carry;
      carry = next;
    }
    if (carry && b->n < BIG_WORDS) b->w[b->n++] = carry;
  }
  if (words && b->n + words <= BIG_WORDS) {
    memmove(b->w + words, b->w, (size_t)b->n * sizeof b->w[0]);
    memset(b->w, 0, (size_t)words * sizeof b->w[0]);
    b->n += words;
  }
}

static int big_compare(const Big *a, const Big *b) {
  if (a->n != b->n) return a->n < b->n ? -1 : 1;
  for (int i = a->n - 1; i >= 0; i--)
    if (a->w[i] != b->w[i]) return a->w[i] < b->w[i] ? -1 : 1;
  return 0;
}

/* D*10^j and N*2^F scaled by the same positive factor 5^max(0,-j) * 2^-min(j,F)
 * so that both become integers. */
static void scaled_pair(uint64_t d, int j, uint64_t n, int f, Big *left, Big *right) {
  int scale5 = j < 0 ? -j : 0;
  int two_min = j < f ? j : f;
  big_set(left, d);
  big_mul_pow5(left, j + scale5);
  big_shift_left(left, j - two_min);
  big_set(right, n);
  big_mul_pow5(right, scale5);
  big_shift_left(right, f - two_min);
}

/* Sign of D*10^j - N*2^F. */
static int compare_decimal_dyadic(uint64_t d, int j, uint64_t n, int f) {
  Big left, right;
  scaled_pair(d, j, n, f, &left, &right);
  return big_compare(&left, &right);
}

/* ---- candidates ------------------------------------------------------------ */

/* |x| = m * 2^e with m in [2^52, 2^53), normalized as Dragon4 does even for
 * subnormals. */
typedef struct {
  uint64_t m;
  int e;
} Dyadic;

static Dyadic normalize(double x) {
  int exp2;
  double f = frexp(fabs(x), &exp2); /* f in [0.5, 1) with at most 53 bits */
  Dyadic r = {(uint64_t)ldexp(f, 53), exp2 - 53};
  return r;
}

/* Is D*10^j strictly between the midpoints of x and its neighbours? Below a
 * power of two the neighbour is twice as close. */
static int inside_exact(uint64_t d, int j, Dyadic x) {
  /* Both midpoints as N * 2^(e-2); the upper one scales like the lower. */
  int power_of_two = x.m == (UINT64_C(1) << 52);
  uint64_t low = power_of_two ? 4 * x.m - 1 : 4 * x.m - 2;
  Big left, right;
  scaled_pair(d, j, low, x.e - 2, &left, &right);
  if (big_compare(&left, &right) <= 0) return 0;
  scaled_pair(d, j, 4 * x.m + 2, x.e - 2, &left, &right);
  return big_compare(&left, &right) < 0;
}

/* Can x be exactly halfway between two p-digit decimals, p <= 17? Then x is
 * a decimal of at most 18 digits ending in 5: as an odd m * 2^e, either
 * e >= 0 and 5 divides m, or e < 0 and m * 5^-e has at most 18 digits. */
static int may_be_decimal_tie(Dyadic x) {
  while (!(x.m & 1)) {
    x.m >>= 1;
    x.e++;
  }
  return x.e >= 0 ? x.m % 5 == 0 : x.e >= -25;
}

/* The P-digit rounding of |x| as D*10^j. When x lies exactly halfway between
 * two P-digit decimals, printf rounds to even but Dragon4 takes the lower one. */
static void round_to_digits(double x, int p, Dyadic dx, uint64_t *d, int *j) {
  char buf[64];
  snprintf(buf, sizeof buf, "%.*e", p - 1, fabs(x));
  uint64_t v = 0;
  const char *s = buf;
  for (; *s && *s != 'e'; s++)
    if (*s >= '0' && *s <= '9') v = v * 10 + (uint64_t)(*s - '0');
  int k = atoi(s + 1);
  *j = k - (p - 1);
  if (may_be_decimal_tie(dx) && compare_decimal_dyadic((2 * v - 1) * 5, *j - 1, dx.m, dx.e) == 0)
    v--;
  *d = v;
}

/* The shortest D*10^j inside x's interval, with MIT's choice among equals. */
static void shortest(double x, uint64_t *d, int *j) {
  Dyadic dx = normalize(x);
  for (int p = 15; p <= 17; p++) {
    uint64_t c;
    int cj;
    round_to_digits(x, p, dx, &c, &cj);
    uint64_t tries[3] = {c, c + 1, c - 1};
    int ntries = p == 15 ? 1 : 3;
    for (int i = 0; i < ntries; i++) {
      if (inside_exact(tries[i], cj, dx)) {
        *d = tries[i];
        *j = cj;
        return;
      }
    }
  }
  round_to_digits(x, 17, dx, d, j); /* unreachable: 17 digits always fit */
}

size_t sicm_shortest_digits(char *digits, int *exponent10, double x) {
  uint64_t d;
  int j;
  shortest(x, &d, &j);
  while (d % 10 == 0) {
    d /= 10;
    j++;
  }
  int n = snprintf(digits, 18, "%llu", (unsigned long long)d);
  *exponent10 = j + n - 1;
  return (size_t)n;
}

/* ---- layout ---------------------------------------------------------------- */

static size_t append(char *buf, size_t at, const char *s, size_t n) {
  memcpy(buf + at, s, n);
  return at + n;
}

static size_t append_zeros(char *buf, size_t at, int n) {
  for (int i = 0; i < n; i++)
    buf[at++] = '0';
  return at;
}

/* d1.d2...e<k>, or d1e<k> for a single digit. */
static size_t scientific(char *buf, size_t at, const char *digits, size_t l, int k) {
  at = append(buf, at, digits, 1);
  if (l > 1) {
    buf[at++] = '.';
    at = append(buf, at, digits + 1, l - 1);
  }
  return at + (size_t)sprintf(buf + at, "e%d", k);
}

/* MIT's flonum-printer normal output, with n = 17 significant digits. */
static size_t layout(char *buf, size_t at, const char *digits, size_t l, int k) {
  const int n = 17;
  int k1_l = k + 1 - (int)l;
  if (k1_l < -n) return scientific(buf, at, digits, l, k);
  if (k < 0) {
    buf[at++] = '.';
    at = append_zeros(buf, at, -(k + 1));
    return append(buf, at, digits, l);
  }
  if (k1_l < 0) {
    at = append(buf, at, digits, (size_t)k + 1);
    buf[at++] = '.';
    return append(buf, at, digits + k + 1, l - (size_t)k - 1);
  }
  if (k <= n) {
    at = append(buf, at, digits, l);
    at = append_zeros(buf, at, k1_l);
    buf[at++] = '.';
    return at;
  }
  return scientific(buf, at, digits, l, k);
}

size_t sicm_format_double(char *buf, double x) {
  const char *special = NULL;
  if (isnan(x))
    special = "+nan.0";
  else if (isinf(x))
    special = x > 0 ? "+inf.0" : "-inf.0";
  else if (x == 0)
    special = signbit(x) ? "-0." : "0.";
  if (special) {
    strcpy(buf, special);
    return strlen(special);
  }
  size_t at = 0;
  if (x < 0) buf[at++] = '-';
  char digits[18];
  int k;
  size_t l = sicm_shortest_digits(digits, &k, x);
  at = layout(buf, at, digits, l, k);
  buf[at] = '\0';
  return at;
}

size_t sicm_format_tolerance(char *buf, double x) {
  int len = 0;
  for (int digits = 1; digits <= 17; digits++) {
    len = snprintf(buf, SICM_DOUBLE_BUFSIZE, "%.*g", digits, x);
    if (strtod(buf, NULL) == x) break;
  }
  return len < 0 ? 0 : (size_t)len;
}
