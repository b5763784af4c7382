// Unit tests of the numeric tower (compiler/base/number.cpp); expected values are MIT Scheme's.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "base/error.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"

namespace sicm {
namespace {

const bool gc_ready = [] {
  GC_INIT();
  return true;
}();

Value lit(std::string_view text) {
  auto v = parse_number(text);
  EXPECT_TRUE(v.has_value()) << text;
  return v ? *v : Value::fixnum(0);
}

std::string str(Value v) {
  return number_to_string(v);
}

std::string show(Value v) {
  if (v.tag == Tag::Bool) return v.b ? "#t" : "#f";
  if (v.tag == Tag::Values) {
    auto *mv = v.as<MultipleValues>();
    std::string s;
    for (size_t i = 0; i < mv->len; i++)
      s += (i ? " " : "") + show(mv->items[i]);
    return s;
  }
  if (v.tag == Tag::String) return std::string(string_view(v));
  return str(v);
}

// The unit-test environment normally runs init_interpreter(); install the
// primitives only when it has not (reinstalling would undo the prelude's
// redefinitions for the other tests).
void ensure_primitives() {
  if (!intern("+").symbol()->bound) install_number_primitives();
}

// Calls a primitive the way the evaluator does. Arguments are numeric literals,
// 'name for a symbol or "text" for a string.
Value call(const char *name, std::initializer_list<const char *> texts) {
  ensure_primitives();
  gcvec<Value> args;
  for (const char *t : texts) {
    if (t[0] == '\'')
      args.push_back(intern(t + 1));
    else if (t[0] == '"')
      args.push_back(make_string(std::string_view(t + 1)));
    else
      args.push_back(lit(t));
  }
  Value f = intern(name).symbol()->global;
  EXPECT_EQ(f.tag, Tag::Primitive) << name;
  return f.as<Primitive>()->fn(args.data(), static_cast<int>(args.size()));
}

std::string run(const char *name, std::initializer_list<const char *> texts) {
  return show(call(name, texts));
}

// The message of the error a call raises ("" if it raises none).
std::string error_of(const char *name, std::initializer_list<const char *> texts) {
  try {
    call(name, texts);
  } catch (const Error &e) {
    EXPECT_EQ(e.kind, ErrorKind::Runtime);
    return e.what();
  }
  return "";
}

std::string wrong_type_msg(const char *obj, const char *pos, const char *who) {
  return std::string("The object ") + obj + ", passed as the " + pos + " argument to " + who +
         ", is not the correct type.";
}

// ---- reading and printing -------------------------------------------------------

TEST(Number, ParsesAndPrintsExactNumbers) {
  EXPECT_EQ(str(lit("42")), "42");
  EXPECT_EQ(str(lit("-42")), "-42");
  EXPECT_EQ(str(lit("+7")), "7");
  EXPECT_EQ(str(lit("-5/128")), "-5/128");
  EXPECT_EQ(str(lit("6/4")), "3/2");
  EXPECT_EQ(lit("4/2").tag, Tag::Fixnum);
  EXPECT_EQ(str(lit("4/2")), "2");
  EXPECT_EQ(str(lit("#x1F")), "31");
  EXPECT_EQ(str(lit("#xff")), "255");
  EXPECT_EQ(str(lit("#x-ff")), "-255");
  EXPECT_EQ(str(lit("#b101")), "5");
  EXPECT_EQ(str(lit("#o17")), "15");
  EXPECT_EQ(str(lit("#d19")), "19");
  EXPECT_EQ(str(lit("123456789012345678901234567890")), "123456789012345678901234567890");
  EXPECT_EQ(lit("123456789012345678901234567890").tag, Tag::Bignum);
  EXPECT_EQ(str(lit("-9223372036854775808")), "-9223372036854775808");
  EXPECT_EQ(lit("-9223372036854775808").tag, Tag::Fixnum);
  EXPECT_EQ(lit("9223372036854775808").tag, Tag::Bignum);
}

TEST(Number, ParsesAndPrintsFlonums) {
  EXPECT_EQ(str(lit(".5")), ".5");
  EXPECT_EQ(str(lit("-.5")), "-.5");
  EXPECT_EQ(str(lit("1.")), "1.");
  EXPECT_EQ(str(lit("1e-13")), ".0000000000001");
  EXPECT_EQ(str(lit("1e-20")), "1e-20");
  EXPECT_EQ(str(lit("1E3")), "1000.");
  EXPECT_EQ(str(lit("1e+3")), "1000.");
  EXPECT_EQ(str(lit("-1.5987211554602254e-14")), "-1.5987211554602254e-14");
  EXPECT_EQ(str(lit("435.0")), "435.");
  EXPECT_EQ(str(lit("0.7518269446689928")), ".7518269446689928");
  EXPECT_EQ(str(lit("436.29121428571153")), "436.29121428571153");
  EXPECT_EQ(str(lit("1e21")), "1e21");
  EXPECT_EQ(str(lit("1e-7")), ".0000001");
  EXPECT_EQ(str(lit("123.456")), "123.456");
  EXPECT_EQ(str(lit("0.1")), ".1");
  EXPECT_EQ(str(lit("-0.")), "-0.");
  EXPECT_EQ(str(lit("+inf.0")), "+inf.0");
  EXPECT_EQ(str(lit("-inf.0")), "-inf.0");
  EXPECT_EQ(str(lit("+nan.0")), "+nan.0");
  EXPECT_EQ(str(Value::flonum(1.0 / 3)), ".3333333333333333");
  EXPECT_EQ(str(lit("1e400")), "+inf.0");
}

TEST(Number, ExactnessPrefixes) {
  EXPECT_EQ(str(lit("#e1.5")), "3/2");
  EXPECT_EQ(str(lit("#e.1")), "1/10");
  EXPECT_EQ(str(lit("#e1e3")), "1000");
  EXPECT_EQ(str(lit("#e-1.25e-1")), "-1/8");
  EXPECT_EQ(str(lit("#i1/3")), ".3333333333333333");
  EXPECT_EQ(str(lit("#i5")), "5.");
  EXPECT_EQ(str(lit("#x#e10")), "16");
  EXPECT_EQ(str(lit("#e#x10")), "16");
}

TEST(Number, RejectsNonNumbers) {
  for (const char *s :
       {"",     "-",   "+",  "...", "1+",    "-1+",   "->x",   "1/0",      ".",   "e5",  "abc",
        "1e",   "1e+", "#t", "#f",  "1/2/3", "1.2.3", "#x1.5", "#e+inf.0", "--1", "+-1", "1/-2",
        "1/2.", ".e5", "+.", "#",   "#q1",   "#x#x1", "#e#i1", "1 2",      "1-"})
    EXPECT_FALSE(parse_number(s).has_value()) << s;
}

TEST(Number, PrintsInOtherRadices) {
  EXPECT_EQ(run("number->string", {"255", "16"}), "ff");
  EXPECT_EQ(run("number->string", {"-255", "2"}), "-11111111");
  EXPECT_EQ(run("number->string", {"1/3", "2"}), "1/11");
  EXPECT_EQ(run("number->string", {"18446744073709551616", "16"}), "10000000000000000");
  EXPECT_EQ(run("number->string", {"42"}), "42");
  EXPECT_EQ(run("number->string", {"2.5"}), "2.5");
  EXPECT_EQ(run("string->number", {"\"ff", "16"}), "255");
  EXPECT_EQ(run("string->number", {"\"1/2"}), "1/2");
  EXPECT_EQ(run("string->number", {"\"1e3"}), "1000.");
  EXPECT_EQ(run("string->number", {"\"abc"}), "#f");
  EXPECT_EQ(run("string->number", {"\"-"}), "#f");
}

// ---- exact integer arithmetic ---------------------------------------------------

TEST(Number, FixnumOverflowPromotesToBignums) {
  EXPECT_EQ(run("+", {"9223372036854775807", "1"}), "9223372036854775808");
  EXPECT_EQ(run("-", {"-9223372036854775808", "1"}), "-9223372036854775809");
  EXPECT_EQ(run("*", {"4294967296", "4294967296"}), "18446744073709551616");
  EXPECT_EQ(run("*", {"-9223372036854775808", "-1"}), "9223372036854775808");
  EXPECT_EQ(run("-", {"-9223372036854775808"}), "9223372036854775808");
  EXPECT_EQ(run("abs", {"-9223372036854775808"}), "9223372036854775808");
  EXPECT_EQ(run("quotient", {"-9223372036854775808", "-1"}), "9223372036854775808");
  EXPECT_EQ(run("1+", {"9223372036854775807"}), "9223372036854775808");
  EXPECT_EQ(run("-1+", {"-9223372036854775808"}), "-9223372036854775809");
}

TEST(Number, BignumsNormalizeBackToFixnums) {
  Value two63 = call("expt", {"2", "63"});
  EXPECT_EQ(two63.tag, Tag::Bignum);
  EXPECT_EQ(str(two63), "9223372036854775808");
  Value neg = num_neg(two63);
  EXPECT_EQ(neg.tag, Tag::Fixnum);
  EXPECT_EQ(str(neg), "-9223372036854775808");
  Value back = num_sub(two63, Value::fixnum(1));
  EXPECT_EQ(back.tag, Tag::Fixnum);
  EXPECT_EQ(str(back), "9223372036854775807");
  EXPECT_EQ(run("+", {"18446744073709551616", "-18446744073709551616"}), "0");
  EXPECT_EQ(num_sub(lit("18446744073709551616"), lit("18446744073709551615")).tag, Tag::Fixnum);
}

TEST(Number, Factorial) {
  Value f = Value::fixnum(1);
  for (int i = 2; i <= 40; i++)
    f = num_mul(f, Value::fixnum(i));
  EXPECT_EQ(str(f), "815915283247897734345611269596115894272000000000");
  for (int i = 40; i >= 2; i--)
    f = num_quotient(f, Value::fixnum(i));
  EXPECT_EQ(f.tag, Tag::Fixnum);
  EXPECT_EQ(str(f), "1");
}

TEST(Number, VariadicArithmetic) {
  EXPECT_EQ(run("+", {}), "0");
  EXPECT_EQ(run("*", {}), "1");
  EXPECT_EQ(run("+", {"5"}), "5");
  EXPECT_EQ(run("+", {"1", "2", "3", "4"}), "10");
  EXPECT_EQ(run("*", {"1", "2", "3", "4"}), "24");
  EXPECT_EQ(run("-", {"10", "1", "2"}), "7");
  EXPECT_EQ(run("-", {"5"}), "-5");
  EXPECT_EQ(run("/", {"2"}), "1/2");
  EXPECT_EQ(run("/", {".5"}), "2.");
  EXPECT_EQ(run("/", {"1", "2", "3"}), "1/6");
  EXPECT_EQ(run("/", {"6", "3"}), "2");
  EXPECT_EQ(call("/", {"6", "3"}).tag, Tag::Fixnum);
  EXPECT_EQ(run("+", {"1/2", "1/3"}), "5/6");
  EXPECT_EQ(run("+", {"1/2", "1/2"}), "1");
  EXPECT_EQ(run("*", {"2/3", "3/2"}), "1");
  EXPECT_EQ(run("-", {"1/2", "1/2"}), "0");
  EXPECT_EQ(run("+", {"1", "2.5"}), "3.5");
  EXPECT_EQ(run("+", {"1/2", ".5"}), "1.");
  EXPECT_EQ(run("-", {".1", ".3"}), "-.19999999999999998");
  EXPECT_EQ(run("+", {".1", ".2"}), ".30000000000000004");
}

// MIT: an exact zero times a finite flonum, or divided by one, stays exact.
TEST(Number, ExactZeroAgainstFlonums) {
  EXPECT_EQ(run("*", {"0", "1.5"}), "0");
  EXPECT_EQ(run("*", {"1.5", "0"}), "0");
  EXPECT_EQ(run("*", {"0", "+inf.0"}), "+nan.0");
  EXPECT_EQ(run("/", {"0", "2.5"}), "0");
  EXPECT_EQ(run("+", {"0", "1.5"}), "1.5");
  EXPECT_EQ(run("*", {"0.", "5"}), "0.");
}

TEST(Number, DivisionByZero) {
  const std::string msg = "Division by zero signalled by /.";
  EXPECT_EQ(error_of("/", {"1", "0"}), msg);
  EXPECT_EQ(error_of("/", {"0"}), msg);
  EXPECT_EQ(error_of("/", {"1/2", "0"}), msg);
  EXPECT_EQ(error_of("/", {"1.5", "0"}), msg);
  EXPECT_EQ(error_of("/", {"1.5", "0."}), msg);
  EXPECT_EQ(error_of("/", {"1", "2", "0"}), msg);
  EXPECT_EQ(error_of("quotient", {"1", "0"}), "Division by zero signalled by integer-quotient.");
  EXPECT_EQ(error_of("remainder", {"1", "0"}), "Division by zero signalled by integer-remainder.");
  EXPECT_EQ(error_of("modulo", {"1", "0"}), "Division by zero signalled by modulo.");
  EXPECT_EQ(error_of("integer-floor", {"1", "0"}), "Division by zero signalled by integer-floor.");
  EXPECT_EQ(error_of("expt", {"0", "-1"}), "Division by zero signalled by expt.");
}

TEST(Number, IntegerDivision) {
  EXPECT_EQ(run("quotient", {"17", "5"}), "3");
  EXPECT_EQ(run("quotient", {"-17", "5"}), "-3");
  EXPECT_EQ(run("remainder", {"17", "-5"}), "2");
  EXPECT_EQ(run("remainder", {"-17", "5"}), "-2");
  EXPECT_EQ(run("modulo", {"-17", "5"}), "3");
  EXPECT_EQ(run("modulo", {"17", "-5"}), "-3");
  EXPECT_EQ(run("modulo", {"-17", "-5"}), "-2");
  EXPECT_EQ(run("modulo", {"-7", "2."}), "1.");
  EXPECT_EQ(run("quotient", {"7.", "2"}), "3.");
  EXPECT_EQ(run("modulo", {"1000000000000000000000000000000", "7"}), "1");
  EXPECT_EQ(run("quotient", {"1000000000000000000000000000000", "1000000000000000000000"}),
            "1000000000");
  EXPECT_EQ(run("remainder", {"-1000000000000000000000000000001", "1000000000000000000000"}), "-1");
  EXPECT_EQ(run("integer-floor", {"7", "2"}), "3");
  EXPECT_EQ(run("integer-floor", {"-7", "2"}), "-4");
  EXPECT_EQ(run("integer-ceiling", {"7", "2"}), "4");
  EXPECT_EQ(run("integer-ceiling", {"-7", "2"}), "-3");
  EXPECT_EQ(run("integer-round", {"7", "2"}), "4");
  EXPECT_EQ(run("integer-round", {"5", "2"}), "2");
  EXPECT_EQ(run("integer-round", {"-5", "2"}), "-2");
  EXPECT_EQ(run("integer-round", {"8", "3"}), "3");
  EXPECT_EQ(run("integer-truncate", {"-7", "2"}), "-3");
  EXPECT_EQ(error_of("quotient", {"1.5", "1"}), wrong_type_msg("1.5", "first", "integer-quotient"));
  EXPECT_EQ(error_of("remainder", {"1", "'x"}), wrong_type_msg("x", "second", "integer-remainder"));
}

TEST(Number, GcdLcm) {
  EXPECT_EQ(run("gcd", {"12", "18"}), "6");
  EXPECT_EQ(run("gcd", {"-12", "18"}), "6");
  EXPECT_EQ(run("gcd", {}), "0");
  EXPECT_EQ(run("gcd", {"-4"}), "4");
  EXPECT_EQ(run("gcd", {"12", "18", "8"}), "2");
  EXPECT_EQ(run("lcm", {"4", "6"}), "12");
  EXPECT_EQ(run("lcm", {}), "1");
  EXPECT_EQ(run("lcm", {"-4", "6"}), "12");
  EXPECT_EQ(run("gcd", {"12.", "18"}), "6.");
}

// ---- comparison ------------------------------------------------------------------

TEST(Number, Comparisons) {
  EXPECT_EQ(run("<", {"1", "2", "3"}), "#t");
  EXPECT_EQ(run("<", {"1", "3", "2"}), "#f");
  EXPECT_EQ(run("<", {"1", "1"}), "#f");
  EXPECT_EQ(run("<", {"5"}), "#t");
  EXPECT_EQ(run(">", {"3", "2", "1"}), "#t");
  EXPECT_EQ(run(">", {"3", "3"}), "#f");
  EXPECT_EQ(run("<=", {"1", "1", "2"}), "#t");
  EXPECT_EQ(run("<=", {"2", "1"}), "#f");
  EXPECT_EQ(run(">=", {"2", "2", "3"}), "#f");
  EXPECT_EQ(run(">=", {"3", "2", "2"}), "#t");
  EXPECT_EQ(run("=", {"1", "1.", "1"}), "#t");
  EXPECT_EQ(run("=", {"1/2", ".5"}), "#t");
  EXPECT_EQ(run("=", {"1", "2"}), "#f");
  EXPECT_EQ(run("<", {"-1/2", "-1/3"}), "#t");
  EXPECT_EQ(run("<", {"100000000000000000000", "100000000000000000001"}), "#t");
  EXPECT_EQ(run("<", {"-100000000000000000000", "1"}), "#t");
  EXPECT_EQ(run("<", {"1", "+inf.0"}), "#t");
  EXPECT_EQ(run(">", {"100000000000000000000000", "-inf.0"}), "#t");
}

// Mixed exact/inexact comparisons are exact, as in MIT.
TEST(Number, MixedComparisonsAreExact) {
  EXPECT_EQ(run("<", {"1/3", ".3333333333333333"}), "#f");
  EXPECT_EQ(run(">", {"1/3", ".3333333333333333"}), "#t");
  EXPECT_EQ(run("=", {"9007199254740993", "9007199254740992."}), "#f");
  EXPECT_EQ(run(">", {"9007199254740993", "9007199254740992."}), "#t");
  EXPECT_EQ(run("=", {"9007199254740992", "9007199254740992."}), "#t");
  EXPECT_EQ(run("=", {".1", "1/10"}), "#f");
}

TEST(Number, NaNIsUnordered) {
  for (const char *op : {"=", "<", ">", "<=", ">="}) {
    EXPECT_EQ(run(op, {"1", "+nan.0"}), "#f") << op;
    EXPECT_EQ(run(op, {"+nan.0", "1"}), "#f") << op;
    EXPECT_EQ(run(op, {"+nan.0", "+nan.0"}), "#f") << op;
  }
}

// A string stands for "not a number": symbols are literal numbers to the
// generic arithmetic. MIT computes (> a b) as (integer-less? b a) and (<= a b) as (not
// (integer-less? b a)).
TEST(Number, ComparisonErrorsNameMitsPrimitives) {
  EXPECT_EQ(error_of("<", {"1", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-less?"));
  EXPECT_EQ(error_of(">", {"1", "\"a"}), wrong_type_msg("\"a\"", "first", "integer-less?"));
  EXPECT_EQ(error_of("<=", {"1", "\"a"}), wrong_type_msg("\"a\"", "first", "integer-less?"));
  EXPECT_EQ(error_of(">=", {"1", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-less?"));
  EXPECT_EQ(error_of("=", {"\"a", "1"}), wrong_type_msg("\"a\"", "first", "integer-equal?"));
  EXPECT_EQ(error_of("<", {"\"a"}), wrong_type_msg("\"a\"", "first", "integer-less?"));
  EXPECT_EQ(run("<", {"2", "1", "\"a"}), "#f"); // stops at the first false pair
}

TEST(Number, ArithmeticErrorsNameMitsPrimitives) {
  EXPECT_EQ(error_of("+", {"1", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-add"));
  EXPECT_EQ(error_of("+", {"\"a", "1"}), wrong_type_msg("\"a\"", "first", "integer-add"));
  EXPECT_EQ(error_of("+", {"\"a"}), wrong_type_msg("\"a\"", "first", "integer-add"));
  EXPECT_EQ(error_of("+", {"1", "2", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-add"));
  EXPECT_EQ(error_of("-", {"\"a"}), wrong_type_msg("\"a\"", "first", "integer-negate"));
  EXPECT_EQ(error_of("-", {"1", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-subtract"));
  EXPECT_EQ(error_of("*", {"2", "\"a"}), wrong_type_msg("\"a\"", "second", "integer-multiply"));
  EXPECT_EQ(error_of("/", {"2", "\"a"}), wrong_type_msg("\"a\"", "second", "/"));
  EXPECT_EQ(error_of("1+", {"\"a"}), wrong_type_msg("\"a\"", "first", "integer-add"));
  EXPECT_EQ(error_of("sqrt", {"\"a"}), wrong_type_msg("\"a\"", "first", "sqrt"));
  EXPECT_EQ(error_of("exp", {"\"a"}), wrong_type_msg("\"a\"", "first", "exp"));
  EXPECT_EQ(error_of("zero?", {"\"a"}), wrong_type_msg("\"a\"", "first", "zero?"));
  EXPECT_EQ(error_of("even?", {"1.5"}), wrong_type_msg("1.5", "first", "integer-remainder"));
}

TEST(Number, MaxMin) {
  EXPECT_EQ(run("max", {"1", "2", "3"}), "3");
  EXPECT_EQ(run("min", {"3", "1", "2"}), "1");
  EXPECT_EQ(run("max", {"1", "2.", "3"}), "3.");
  EXPECT_EQ(run("min", {"1", "2.", "3"}), "1.");
  EXPECT_EQ(run("max", {"1/2", "1/3"}), "1/2");
  EXPECT_EQ(run("max", {"7"}), "7");
  EXPECT_EQ(run("max", {"+nan.0", "1"}), "1.");
  EXPECT_EQ(run("min", {"1", "+nan.0"}), "1.");
  EXPECT_EQ(run("max", {"-inf.0", "-5"}), "-5.");
}

// ---- rounding and conversion ----------------------------------------------------------

TEST(Number, Rounding) {
  EXPECT_EQ(run("round", {"2.5"}), "2.");
  EXPECT_EQ(run("round", {"3.5"}), "4.");
  EXPECT_EQ(run("round", {"-2.5"}), "-2.");
  EXPECT_EQ(run("round", {"-3.7"}), "-4.");
  EXPECT_EQ(run("round", {"5/2"}), "2");
  EXPECT_EQ(run("round", {"7/2"}), "4");
  EXPECT_EQ(run("round", {"-7/2"}), "-4");
  EXPECT_EQ(run("round", {"-5/2"}), "-2");
  EXPECT_EQ(run("round", {"1/3"}), "0");
  EXPECT_EQ(run("round", {"7"}), "7");
  EXPECT_EQ(run("floor", {"-7/2"}), "-4");
  EXPECT_EQ(run("ceiling", {"-7/2"}), "-3");
  EXPECT_EQ(run("truncate", {"-7/2"}), "-3");
  EXPECT_EQ(run("floor", {"2.5"}), "2.");
  EXPECT_EQ(run("ceiling", {"2.1"}), "3.");
  EXPECT_EQ(run("truncate", {"-2.7"}), "-2.");
  EXPECT_EQ(run("round->exact", {"2.5"}), "2");
  EXPECT_EQ(run("floor->exact", {"-1.5"}), "-2");
  EXPECT_EQ(run("ceiling->exact", {"1.2"}), "2");
  EXPECT_EQ(run("truncate->exact", {"-1.7"}), "-1");
  EXPECT_EQ(run("round->exact", {"1e20"}), "100000000000000000000");
  EXPECT_EQ(run("floor->exact", {"7/2"}), "3");
}

TEST(Number, ExactInexactConversion) {
  EXPECT_EQ(run("exact->inexact", {"1/3"}), ".3333333333333333");
  EXPECT_EQ(run("inexact", {"1/3"}), ".3333333333333333");
  EXPECT_EQ(run("exact->inexact", {"1180591620717411303424"}), "1.1805916207174113e21");
  EXPECT_EQ(run("exact->inexact", {"100000000000000000000000"}), "9.999999999999999e22");
  // Correct rounding of big integers: ties go to even.
  EXPECT_EQ(run("exact->inexact", {"9007199254740993"}), "9007199254740992.");
  EXPECT_EQ(run("exact->inexact", {"9007199254740995"}), "9007199254740996.");
  EXPECT_EQ(run("exact->inexact", {"-9007199254740995"}), "-9007199254740996.");
  EXPECT_EQ(run("inexact->exact", {".5"}), "1/2");
  EXPECT_EQ(run("exact", {".5"}), "1/2");
  EXPECT_EQ(run("inexact->exact", {".1"}), "3602879701896397/36028797018963968");
  EXPECT_EQ(run("inexact->exact", {"1e20"}), "100000000000000000000");
  EXPECT_EQ(run("inexact->exact", {"-2."}), "-2");
  EXPECT_EQ(run("inexact->exact", {"7/3"}), "7/3");
  EXPECT_EQ(error_of("inexact->exact", {"+inf.0"}),
            wrong_type_msg("+inf.0", "first", "inexact->exact"));
}

// Ratios far outside the double range still convert to the nearest double.
TEST(Number, RatioToDoubleIsCorrectlyRounded) {
  Value ten400 = num_expt(Value::fixnum(10), Value::fixnum(400));
  Value ten399 = num_expt(Value::fixnum(10), Value::fixnum(399));
  EXPECT_EQ(str(num_exact_to_inexact(num_div(ten400, num_add(ten399, Value::fixnum(1))))), "10.");
  EXPECT_EQ(str(num_exact_to_inexact(num_div(Value::fixnum(1), ten400))), "0.");
  EXPECT_EQ(str(num_exact_to_inexact(ten400)), "+inf.0");
  Value two1074 = num_expt(Value::fixnum(2), Value::fixnum(1074));
  EXPECT_EQ(str(num_exact_to_inexact(num_div(Value::fixnum(1), two1074))),
            "4.9406564584124654e-324");
  Value two1076 = num_expt(Value::fixnum(2), Value::fixnum(1076));
  EXPECT_EQ(str(num_exact_to_inexact(num_div(Value::fixnum(3), two1076))),
            "4.9406564584124654e-324");
  EXPECT_EQ(str(num_exact_to_inexact(num_div(Value::fixnum(1), two1076))), "0.");
  EXPECT_EQ(str(num_exact_to_inexact(lit("2/3"))), ".6666666666666666");
  EXPECT_EQ(str(num_exact_to_inexact(lit("-1/10"))), "-.1");
  EXPECT_EQ(str(num_exact_to_inexact(lit("12345678901234567890123/1000"))),
            "1.2345678901234567e19");
}

TEST(Number, NumeratorDenominator) {
  EXPECT_EQ(run("numerator", {"6/4"}), "3");
  EXPECT_EQ(run("denominator", {"6/4"}), "2");
  EXPECT_EQ(run("numerator", {"-6/4"}), "-3");
  EXPECT_EQ(run("denominator", {"5"}), "1");
  EXPECT_EQ(run("numerator", {"5"}), "5");
  EXPECT_EQ(run("numerator", {".5"}), "1.");
  EXPECT_EQ(run("denominator", {".5"}), "2.");
}

// ---- expt, sqrt and the transcendental functions ----------------------------------------

TEST(Number, ExptExact) {
  EXPECT_EQ(run("expt", {"2", "100"}), "1267650600228229401496703205376");
  EXPECT_EQ(run("expt", {"2", "10"}), "1024");
  EXPECT_EQ(run("expt", {"-2", "3"}), "-8");
  EXPECT_EQ(run("expt", {"2", "-2"}), "1/4");
  EXPECT_EQ(run("expt", {"2/3", "3"}), "8/27");
  EXPECT_EQ(run("expt", {"2/3", "-2"}), "9/4");
  EXPECT_EQ(run("expt", {"10", "-3"}), "1/1000");
  EXPECT_EQ(run("expt", {"0", "0"}), "1");
  EXPECT_EQ(run("expt", {"0.", "0"}), "1");
  EXPECT_EQ(run("expt", {"0", "2"}), "0");
  EXPECT_EQ(run("expt", {"0", "2.5"}), "0");
  EXPECT_EQ(run("expt", {"5", "0"}), "1");
  EXPECT_EQ(run("expt", {"1", "100000000000000000000000"}), "1");
  EXPECT_EQ(run("expt", {"-1", "100000000000000000000001"}), "-1");
}

TEST(Number, ExptInexact) {
  EXPECT_EQ(run("expt", {"2.", "3"}), "8.");
  EXPECT_EQ(run("expt", {"2", "3."}), "8.");
  EXPECT_EQ(run("expt", {"-2.", "3"}), "-8.");
  EXPECT_EQ(run("expt", {"2.", "0"}), "1.");
  EXPECT_EQ(run("expt", {"0.", "2"}), "0.");
  EXPECT_EQ(run("expt", {"1.1", "2"}), "1.2100000000000002");
  EXPECT_EQ(run("expt", {"2", ".5"}), "1.4142135623730951");
  EXPECT_EQ(run("expt", {"2.", "-2"}), ".25");
  EXPECT_EQ(run("expt", {".5", "2"}), ".25");
  // From MIT's test suite: 2^-1074 every way round.
  EXPECT_EQ(run("expt", {"2.", "-1074"}), "4.9406564584124654e-324");
  EXPECT_EQ(run("expt", {".5", "1074"}), "4.9406564584124654e-324");
  EXPECT_EQ(run("expt", {"4.", "-537"}), "4.9406564584124654e-324");
  EXPECT_EQ(run("expt", {".25", "537"}), "4.9406564584124654e-324");
  EXPECT_EQ(run("expt", {"2.", "-1075"}), "0.");
}

// An exact base to the power 1/k is exact when the root is; MIT gives any
// other non-integral rational exponent a flonum result.
TEST(Number, ExptRationalExponent) {
  EXPECT_EQ(run("expt", {"4", "1/2"}), "2");
  EXPECT_EQ(run("expt", {"8", "1/3"}), "2");
  EXPECT_EQ(run("expt", {"1/4", "1/2"}), "1/2");
  EXPECT_EQ(run("expt", {"8/27", "1/3"}), "2/3");
  EXPECT_EQ(run("expt", {"2", "1/2"}), "1.4142135623730951");
  EXPECT_EQ(run("expt", {"4", "3/2"}), "8.");
  EXPECT_EQ(run("expt", {"4.", "1/2"}), "2.");
  // A negative base with a non-integer exponent leaves the reals (MIT's values).
  EXPECT_EQ(run("expt", {"-8", "1/3"}), "1.+1.732050807568877i");
  EXPECT_EQ(run("expt", {"-2.", ".5"}), "8.659560562354932e-17+1.414213562373095i");
  EXPECT_EQ(error_of("expt", {"0.", "-1"}), "Division by zero signalled by expt.");
}

TEST(Number, Sqrt) {
  EXPECT_EQ(run("sqrt", {"16"}), "4");
  EXPECT_EQ(call("sqrt", {"16"}).tag, Tag::Fixnum);
  EXPECT_EQ(run("sqrt", {"0"}), "0");
  EXPECT_EQ(run("sqrt", {"1/4"}), "1/2");
  EXPECT_EQ(run("sqrt", {"4/9"}), "2/3");
  EXPECT_EQ(run("sqrt", {"2"}), "1.4142135623730951");
  EXPECT_EQ(run("sqrt", {"15"}), "3.872983346207417");
  EXPECT_EQ(run("sqrt", {"16."}), "4.");
  EXPECT_EQ(run("sqrt", {"-0."}), "-0.");
  EXPECT_EQ(run("sqrt", {"10000000000000000000000000000000000000000"}), "100000000000000000000");
  EXPECT_EQ(run("sqrt", {"1/2"}), ".7071067811865476");
  EXPECT_EQ(run("sqrt", {"-4"}), "+2i");
  EXPECT_EQ(run("sqrt", {"-2."}), "+1.4142135623730951i");
  EXPECT_EQ(run("exact-integer-sqrt", {"17"}), "4 1");
  EXPECT_EQ(run("exact-integer-sqrt", {"16"}), "4 0");
  EXPECT_EQ(error_of("exact-integer-sqrt", {"-1"}),
            wrong_type_msg("-1", "first", "exact-integer-sqrt"));
}

TEST(Number, Transcendental) {
  EXPECT_EQ(run("exp", {"0"}), "1");
  EXPECT_EQ(run("exp", {"0."}), "1.");
  EXPECT_EQ(run("exp", {"1"}), "2.718281828459045");
  EXPECT_EQ(run("log", {"1"}), "0");
  EXPECT_EQ(run("log", {"1."}), "0.");
  EXPECT_EQ(run("log", {"100"}), "4.605170185988092");
  EXPECT_EQ(run("sin", {"0"}), "0");
  EXPECT_EQ(run("sin", {"0."}), "0.");
  EXPECT_EQ(run("cos", {"0"}), "1");
  EXPECT_EQ(run("cos", {"0."}), "1.");
  EXPECT_EQ(run("tan", {"0"}), "0");
  EXPECT_EQ(run("asin", {"0"}), "0");
  EXPECT_EQ(run("acos", {"1"}), "0");
  EXPECT_EQ(run("acos", {"1."}), "0.");
  EXPECT_EQ(run("atan", {"0"}), "0");
  EXPECT_EQ(run("atan", {"1"}), ".7853981633974483");
  EXPECT_EQ(run("atan", {"0", "1"}), "0");
  EXPECT_EQ(run("atan", {"0", "0"}), "0");
  EXPECT_EQ(run("atan", {"0", "-1"}), "3.141592653589793");
  EXPECT_EQ(run("atan", {"1", "1"}), ".7853981633974483");
  EXPECT_EQ(run("atan", {"0.", "1"}), "0.");
  EXPECT_EQ(run("asin", {"1"}), "1.5707963267948966");
  EXPECT_EQ(run("acos", {"0"}), "1.5707963267948966");
  EXPECT_EQ(run("log", {"-1"}), "+3.141592653589793i");
  EXPECT_EQ(run("asin", {"2"}), "1.5707963267948966-1.3169578969248166i");
  EXPECT_EQ(run("acos", {"-1.5"}), "3.141592653589793-.9624236501192069i");
}

// ---- small procedures and predicates ------------------------------------------------------

TEST(Number, SmallProcedures) {
  EXPECT_EQ(run("1+", {"5"}), "6");
  EXPECT_EQ(run("-1+", {"5"}), "4");
  EXPECT_EQ(run("1-", {"5"}), "4");
  EXPECT_EQ(run("1+", {"1/2"}), "3/2");
  EXPECT_EQ(run("square", {"5"}), "25");
  EXPECT_EQ(run("square", {"1/2"}), "1/4");
  EXPECT_EQ(run("square", {"1.5"}), "2.25");
  EXPECT_EQ(run("square", {"3037000500"}), "9223372037000250000");
  EXPECT_EQ(run("cube", {"3"}), "27");
  EXPECT_EQ(run("cube", {"1.5"}), "3.375");
  EXPECT_EQ(run("cube", {"-2/3"}), "-8/27");
  EXPECT_EQ(run("abs", {"-5/3"}), "5/3");
  EXPECT_EQ(run("abs", {"-2.5"}), "2.5");
  EXPECT_EQ(run("magnitude", {"-3"}), "3");
}

TEST(Number, Predicates) {
  EXPECT_EQ(run("number?", {"1"}), "#t");
  EXPECT_EQ(run("number?", {"'a"}), "#f");
  EXPECT_EQ(run("real?", {"1.5"}), "#t");
  EXPECT_EQ(run("complex?", {"1/2"}), "#t");
  EXPECT_EQ(run("integer?", {"2."}), "#t");
  EXPECT_EQ(run("integer?", {"2.5"}), "#f");
  EXPECT_EQ(run("integer?", {"1/2"}), "#f");
  EXPECT_EQ(run("integer?", {"+inf.0"}), "#f");
  EXPECT_EQ(run("integer?", {"'a"}), "#f");
  EXPECT_EQ(run("rational?", {"1.5"}), "#t");
  EXPECT_EQ(run("rational?", {"+inf.0"}), "#f");
  EXPECT_EQ(run("rational?", {"+nan.0"}), "#f");
  EXPECT_EQ(run("exact?", {"1/2"}), "#t");
  EXPECT_EQ(run("exact?", {"1."}), "#f");
  EXPECT_EQ(run("inexact?", {"1."}), "#t");
  EXPECT_EQ(error_of("exact?", {"'a"}), wrong_type_msg("a", "first", "exact?"));
  EXPECT_EQ(run("exact-rational?", {"1/2"}), "#t");
  EXPECT_EQ(run("exact-rational?", {".5"}), "#f");
  EXPECT_EQ(run("exact-rational?", {"'a"}), "#f");
  EXPECT_EQ(run("exact-integer?", {"100000000000000000000"}), "#t");
  EXPECT_EQ(run("exact-integer?", {"1."}), "#f");
  EXPECT_EQ(run("exact-nonnegative-integer?", {"0"}), "#t");
  EXPECT_EQ(run("exact-nonnegative-integer?", {"-1"}), "#f");
  EXPECT_EQ(run("exact-nonnegative-integer?", {"1."}), "#f");
  EXPECT_EQ(run("nan?", {"+nan.0"}), "#t");
  EXPECT_EQ(run("nan?", {"1"}), "#f");
  EXPECT_EQ(run("zero?", {"0"}), "#t");
  EXPECT_EQ(run("zero?", {"-0."}), "#t");
  EXPECT_EQ(run("zero?", {"1/2"}), "#f");
  EXPECT_EQ(run("positive?", {"1/2"}), "#t");
  EXPECT_EQ(run("positive?", {"0"}), "#f");
  EXPECT_EQ(run("negative?", {"-1."}), "#t");
  EXPECT_EQ(run("negative?", {"-100000000000000000000"}), "#t");
  EXPECT_EQ(run("odd?", {"3"}), "#t");
  EXPECT_EQ(run("odd?", {"-3"}), "#t");
  EXPECT_EQ(run("even?", {"0"}), "#t");
  EXPECT_EQ(run("even?", {"100000000000000000000"}), "#t");
  EXPECT_EQ(run("odd?", {"3."}), "#t");
}

TEST(Number, Random) {
  bool seen[10] = {};
  for (int i = 0; i < 1000; i++) {
    Value r = call("random", {"10"});
    ASSERT_EQ(r.tag, Tag::Fixnum);
    ASSERT_GE(r.i, 0);
    ASSERT_LT(r.i, 10);
    seen[r.i] = true;
  }
  for (bool s : seen)
    EXPECT_TRUE(s);
  for (int i = 0; i < 1000; i++) {
    Value r = call("random", {"1."});
    ASSERT_EQ(r.tag, Tag::Flonum);
    ASSERT_GE(r.d, 0.0);
    ASSERT_LT(r.d, 1.0);
  }
  Value limit = lit("1000000000000000000000000000000");
  for (int i = 0; i < 100; i++) {
    Value r = call("random", {"1000000000000000000000000000000"});
    ASSERT_TRUE(is_exact_integer(r));
    ASSERT_GE(num_sign(r), 0);
    ASSERT_LT(num_compare(r, limit), 0);
  }
  EXPECT_NE(error_of("random", {"0"}), "");
  EXPECT_NE(error_of("random", {"-5"}), "");
  EXPECT_NE(error_of("random", {"1/2"}), "");
}

TEST(Number, CApi) {
  EXPECT_TRUE(is_number(lit("1/2")));
  EXPECT_FALSE(is_number(intern("x")));
  EXPECT_TRUE(is_exact(lit("1/2")));
  EXPECT_TRUE(is_integer(lit("2.")));
  EXPECT_EQ(to_int64(lit("42")), std::optional<int64_t>(42));
  EXPECT_FALSE(to_int64(lit("100000000000000000000")).has_value());
  EXPECT_FALSE(to_int64(lit("1.")).has_value());
  EXPECT_EQ(to_double(lit("1/4")), 0.25);
  EXPECT_EQ(num_compare(lit("1"), lit("+nan.0")), 2);
  EXPECT_EQ(num_compare(lit("2"), lit("1.5")), 1);
  EXPECT_EQ(num_sign(lit("-1/2")), -1);
  EXPECT_EQ(str(make_integer_from_string("-123456789012345678901234567890")),
            "-123456789012345678901234567890");
  EXPECT_EQ(str(make_integer_from_string("ff", 16)), "255");
  mpq_t q;
  mpq_init(q);
  mpq_set_si(q, 6, 4);
  EXPECT_EQ(str(make_rational(q)), "3/2");
  to_mpq(lit("-7/3"), q);
  EXPECT_EQ(mpz_get_si(mpq_numref(q)), -7);
  mpq_clear(q);
}

} // namespace
} // namespace sicm
