// Complex numbers as MIT Scheme has them (its "recnums"): a pair of real
// numbers of the tower, each exact or inexact on its own, so 1+2i is exact,
// 1.+2.i inexact and 0.+2i mixed. An exact-zero imaginary part makes the
// number real (make-rectangular 1 0) = 1, while 1+0.i stays complex.
//
// Arithmetic is written over the real operations of number.cpp, so
// exactness follows from the parts: (* 2 1+i) is 2+2i, (sqrt -4) is +2i,
// (log -1) is +3.141592653589793i with an exact-zero real part. The
// elementary functions use the textbook identities MIT uses (exp through
// make-polar, log through magnitude and angle, sin and cos through e^(iz)
// and e^(-iz), the inverse functions through log and sqrt), so exact zeros survive
// where MIT's do and inexact results agree with MIT's to the last bit or two.
#include <cmath>
#include <numbers>

#include "base/number.hpp"
#include "base/number_internal.hpp"
#include "base/primitive.hpp"

namespace sicm {

namespace {

Value re_of(Value z) {
  return is_recnum(z) ? z.as<Recnum>()->re : z;
}
Value im_of(Value z) {
  return is_recnum(z) ? z.as<Recnum>()->im : Value::fixnum(0);
}

Value exact_int(int64_t n) {
  return Value::fixnum(n);
}

// i z.
Value times_i(Value z) {
  return make_rectangular(num_neg(im_of(z)), re_of(z));
}
// -i z.
Value times_minus_i(Value z) {
  return make_rectangular(im_of(z), num_neg(re_of(z)));
}

} // namespace

bool is_recnum(Value v) {
  return v.tag == Tag::Recnum;
}

Value make_rectangular(Value re, Value im) {
  check_number(re, 1, "make-rectangular");
  check_number(im, 2, "make-rectangular");
  if (im.tag == Tag::Fixnum && im.i == 0) return re;
  return Value::object(Tag::Recnum, gc_new<Recnum>(Recnum{re, im}));
}

Value make_polar(Value magnitude, Value angle) {
  check_number(magnitude, 1, "make-polar");
  check_number(angle, 2, "make-polar");
  return make_rectangular(num_mul(magnitude, num_cos(angle)), num_mul(magnitude, num_sin(angle)));
}

Value num_real_part(Value z) {
  if (!is_number(z)) wrong_type(z, 1, "real-part");
  return re_of(z);
}

Value num_imag_part(Value z) {
  if (!is_number(z)) wrong_type(z, 1, "imag-part");
  return im_of(z);
}

Value num_conjugate(Value z) {
  if (!is_number(z)) wrong_type(z, 1, "conjugate");
  if (!is_recnum(z)) return z;
  return make_rectangular(re_of(z), num_neg(im_of(z)));
}

// |z|. With exact parts, as MIT computes it: v sqrt(1 + (w/v)^2) for v and
// w the larger and smaller magnitude of the parts, exact when the square
// root is ((magnitude 3+4i) is 5; (magnitude 2+3i) is 3.6055512754639896,
// not the (sqrt 13) = 3.605551275463989 of the sum of squares). With an
// inexact part, hypot, which neither overflows nor underflows where the
// magnitude itself does not.
Value num_magnitude(Value z) {
  if (!is_number(z)) wrong_type(z, 1, "magnitude");
  if (!is_recnum(z)) return num_abs(z);
  Value x = re_of(z), y = im_of(z);
  if (is_exact(x) && is_exact(y)) {
    Value ax = num_abs(x), ay = num_abs(y);
    bool x_larger = num_compare(ax, ay) >= 0;
    Value v = x_larger ? ax : ay, w = x_larger ? ay : ax;
    if (num_is_zero(v)) return v;
    Value ratio = num_div(w, v);
    return num_mul(v, num_sqrt(num_add(exact_int(1), num_mul(ratio, ratio))));
  }
  return Value::flonum(std::hypot(to_double(x), to_double(y)));
}

// The angle of z in (-pi, pi]: 0 for a non-negative real (exact for an exact
// one), pi for a negative real (and for -0., as MIT), atan2 otherwise.
Value num_angle(Value z) {
  if (!is_number(z)) wrong_type(z, 1, "angle");
  if (!is_recnum(z)) {
    if (is_flonum(z) && std::isnan(z.d)) return z;
    bool negative = is_flonum(z) ? std::signbit(z.d) : num_sign(z) < 0;
    if (negative) return Value::flonum(std::numbers::pi);
    return is_flonum(z) ? Value::flonum(0) : exact_int(0);
  }
  return num_atan2(im_of(z), re_of(z));
}

// ---- arithmetic ------------------------------------------------------------------

Value complex_add(Value a, Value b) {
  return make_rectangular(num_add(re_of(a), re_of(b)), num_add(im_of(a), im_of(b)));
}

Value complex_sub(Value a, Value b) {
  return make_rectangular(num_sub(re_of(a), re_of(b)), num_sub(im_of(a), im_of(b)));
}

Value complex_mul(Value a, Value b) {
  Value x = re_of(a), y = im_of(a), u = re_of(b), v = im_of(b);
  return make_rectangular(num_sub(num_mul(x, u), num_mul(y, v)),
                          num_add(num_mul(x, v), num_mul(y, u)));
}

// (x + iy)/(u + iv) = ((xu + yv) + i(yu - xv)) / (u^2 + v^2); a real divisor
// divides each part.
Value complex_div(Value a, Value b) {
  Value x = re_of(a), y = im_of(a);
  if (!is_recnum(b)) return make_rectangular(num_div(x, b), num_div(y, b));
  Value u = re_of(b), v = im_of(b);
  Value d = num_add(num_mul(u, u), num_mul(v, v));
  return make_rectangular(num_div(num_add(num_mul(x, u), num_mul(y, v)), d),
                          num_div(num_sub(num_mul(y, u), num_mul(x, v)), d));
}

bool complex_equal(Value a, Value b) {
  return num_equal(re_of(a), re_of(b)) && num_equal(im_of(a), im_of(b));
}

bool complex_is_zero(Value z) {
  return num_is_zero(re_of(z)) && num_is_zero(im_of(z));
}

Value complex_exact_to_inexact(Value z) {
  return make_rectangular(num_exact_to_inexact(re_of(z)), num_exact_to_inexact(im_of(z)));
}

Value complex_inexact_to_exact(Value z) {
  return make_rectangular(num_inexact_to_exact(re_of(z)), num_inexact_to_exact(im_of(z)));
}

// ---- elementary functions ------------------------------------------------------------

// e^(x + iy) = e^x (cos y + i sin y).
Value complex_exp(Value z) {
  return make_polar(num_exp(re_of(z)), im_of(z));
}

// log |z| for an inexact magnitude: near |z| = 1, where log |z| is small and
// the rounding of |z| would dominate it, as log1p(|z|^2 - 1)/2 with |z|^2 - 1
// formed from the parts ((log 1.+1.i) has the real part (log 2)/2 to the last
// bit, as MIT's); elsewhere as the log of hypot.
double log_magnitude(double x, double y) {
  double a = std::fmax(std::fabs(x), std::fabs(y)), b = std::fmin(std::fabs(x), std::fabs(y));
  if (a > 0.5 && a < 2) return std::log1p((a - 1) * (a + 1) + b * b) / 2;
  return std::log(std::hypot(x, y));
}

// log z = log |z| + i angle(z), for z a recnum or a negative real: the real
// part exact when |z| is an exact 1 ((log -1) is +3.141592653589793i).
Value complex_log(Value z) {
  Value magnitude = num_magnitude(z);
  Value re = is_exact(magnitude)
                 ? num_log(magnitude)
                 : Value::flonum(log_magnitude(to_double(re_of(z)), to_double(im_of(z))));
  return make_rectangular(re, num_angle(z));
}

// sqrt of a recnum or of a negative real, as MIT computes it. A negative
// real's root is i times the root of its magnitude (exact when that is:
// (sqrt -4) is +2i), and so is that of a negative real part with an
// inexact zero imaginary part, whose sign it takes ((sqrt -9-0.i) is
// 0.-3i); an imaginary iy, its real part zero exact or not, has the root
// s(1 + i sign y) with s = sqrt(|y|/2), exact when that is ((sqrt 0.+2i)
// is 1+i); any other z has the root of its magnitude at half its angle
// (where cos(pi/2) would leave 6e-17 instead of the zero).
Value complex_sqrt(Value z) {
  if (!is_recnum(z)) return make_rectangular(exact_int(0), num_sqrt(num_neg(z)));
  Value x = re_of(z), y = im_of(z);
  if (num_is_zero(x)) {
    Value s = num_sqrt(num_div(num_abs(y), exact_int(2)));
    return make_rectangular(s, num_sign(y) < 0 ? num_neg(s) : s);
  }
  if (is_flonum(y) && y.d == 0 && num_sign(x) < 0) {
    Value root = num_sqrt(num_neg(x));
    return make_rectangular(Value::flonum(0), std::signbit(y.d) ? num_neg(root) : root);
  }
  return make_polar(num_sqrt(num_magnitude(z)), num_div(num_angle(z), exact_int(2)));
}

// b^e for a complex base or exponent, or a negative real base with a
// non-integer exponent: exact integer exponents by repeated squaring (exact
// parts stay exact: (expt 1+i 2) is +2i), anything else as e^(e log b), as
// MIT: (expt -1 1/2) is 6.123233995736766e-17+1.i, not (sqrt -1) = +i.
Value complex_expt(Value b, Value e) {
  if (is_exact_integer(e)) {
    bool negative = num_sign(e) < 0;
    Value n = negative ? num_neg(e) : e;
    Value result = exact_int(1), square = b;
    while (!num_is_zero(n)) {
      if (!num_is_zero(num_remainder(n, exact_int(2)))) result = num_mul(result, square);
      n = num_quotient(n, exact_int(2));
      if (!num_is_zero(n)) square = num_mul(square, square);
    }
    return negative ? num_div(exact_int(1), result) : result;
  }
  if (num_is_zero(b)) { // MIT: 0 for an exponent with a positive real part, else an error
    if (num_sign(re_of(e)) > 0) return is_exact(b) ? exact_int(0) : Value::flonum(0);
    divide_by_zero("expt");
  }
  return num_exp(num_mul(e, num_log(b)));
}

// sin z = (e^(iz) - e^(-iz)) / 2i and cos z = (e^(iz) + e^(-iz)) / 2, as MIT
// computes them: (sin +i) is +1.1752011936438014i with an exact-zero real
// part, (cos +i) the real 1.5430806348152437.
Value complex_sin(Value z) {
  Value iz = times_i(z);
  Value difference = num_sub(num_exp(iz), num_exp(num_neg(iz)));
  return num_div(difference, make_rectangular(exact_int(0), exact_int(2)));
}

Value complex_cos(Value z) {
  Value iz = times_i(z);
  return num_div(num_add(num_exp(iz), num_exp(num_neg(iz))), exact_int(2));
}

Value complex_tan(Value z) {
  return num_div(complex_sin(z), complex_cos(z));
}

// asin z = -i log(iz + sqrt(1 - z^2)), for a recnum or a real outside [-1, 1].
Value complex_asin(Value z) {
  Value root = num_sqrt(num_sub(exact_int(1), num_mul(z, z)));
  return times_minus_i(num_log(num_add(times_i(z), root)));
}

// acos z = -i log(z + i sqrt(1 - z^2)).
Value complex_acos(Value z) {
  Value root = num_sqrt(num_sub(exact_int(1), num_mul(z, z)));
  return times_minus_i(num_log(num_add(z, times_i(root))));
}

// atan z = log((1 + iz)/(1 - iz)) / 2i; +i and -i are its poles.
Value complex_atan(Value z) {
  Value iz = times_i(z);
  Value denominator = num_sub(exact_int(1), iz);
  Value numerator = num_add(exact_int(1), iz);
  if (num_is_zero(denominator) || num_is_zero(numerator)) divide_by_zero("atan");
  Value l = num_log(num_div(numerator, denominator));
  return num_div(times_minus_i(l), exact_int(2));
}

// ---- text ------------------------------------------------------------------------------

// MIT's form: the real part unless it is an exact zero, then the imaginary
// part with its sign and an i; an exact imaginary 1 or -1 is written + or -:
// 1+2i, +2i, 1/2-1/2i, 1.+0.i, +i, -i, +inf.0i.
std::string complex_to_string(Value z, int radix) {
  Value x = re_of(z), y = im_of(z);
  std::string out = x.tag == Tag::Fixnum && x.i == 0 ? "" : number_to_string(x, radix);
  if (y.tag == Tag::Fixnum && (y.i == 1 || y.i == -1)) return out + (y.i == 1 ? "+i" : "-i");
  std::string im = number_to_string(y, radix);
  if (im[0] != '-' && im[0] != '+') out += '+';
  return out + im + "i";
}

} // namespace sicm
