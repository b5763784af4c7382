// Unit tests of the reader: lexical syntax, positions, and clean errors.
#include <gtest/gtest.h>

#include "base/number.hpp"
#include "print/printer.hpp"
#include "syntax/reader.hpp"

using namespace sicm;

namespace {

gcvec<ReadForm> read_text(const std::string &text) {
  return read_all(register_source("test.sicm", text));
}

// Read one datum and write it back.
std::string roundtrip(const std::string &text) {
  auto forms = read_text(text);
  EXPECT_EQ(forms.size(), 1u) << text;
  return forms.empty() ? "" : write_string(forms[0].datum);
}

std::string error_of(const std::string &text) {
  try {
    read_text(text);
  } catch (const Error &e) {
    return std::to_string(e.loc.line) + ":" + std::to_string(e.loc.col) + ": " + e.what();
  }
  return "no error";
}

// error_of on a thread with a 256 MiB stack, the size of the evaluator
// thread's, on which sicm reads programs. kMaxReadDepth is safe there; the
// main thread's 8 MiB holds it only without AddressSanitizer, whose frames
// are about seven times larger.
std::string error_of_on_big_stack(const std::string &text) {
  struct Job {
    const std::string *text;
    std::string error;
  } job{&text, "no thread"};
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, size_t(256) << 20);
  pthread_t thread;
  auto body = [](void *p) -> void * {
    Job *j = static_cast<Job *>(p);
    j->error = error_of(*j->text);
    return nullptr;
  };
  // pthread_create is the collector's (GC_THREADS), so the thread is registered.
  if (pthread_create(&thread, &attr, body, &job) == 0) pthread_join(thread, nullptr);
  pthread_attr_destroy(&attr);
  return job.error;
}

} // namespace

TEST(Reader, Integers) {
  EXPECT_EQ(roundtrip("42"), "42");
  EXPECT_EQ(roundtrip("-7"), "-7");
  EXPECT_EQ(roundtrip("+7"), "7");
  EXPECT_EQ(roundtrip("123456789012345678901234567890"), "123456789012345678901234567890");
}

TEST(Reader, Rationals) {
  EXPECT_EQ(roundtrip("1/2"), "1/2");
  EXPECT_EQ(roundtrip("-5/128"), "-5/128");
  EXPECT_EQ(roundtrip("4/2"), "2");
  EXPECT_EQ(roundtrip("6/4"), "3/2");
}

TEST(Reader, Decimals) {
  EXPECT_EQ(roundtrip(".5"), ".5");
  EXPECT_EQ(roundtrip("1."), "1.");
  EXPECT_EQ(roundtrip("1e-13"), ".0000000000001"); // MIT: positional down to 17 places
  EXPECT_EQ(roundtrip("1e-20"), "1e-20");
  EXPECT_EQ(roundtrip("-1.5987211554602254e-14"), "-1.5987211554602254e-14");
  EXPECT_EQ(roundtrip("435.0"), "435.");
  EXPECT_EQ(roundtrip("-0.25"), "-.25");
}

TEST(Reader, SymbolsFromTheBook) {
  for (const char *s : {"->local", "Lagrangian->state-derivative", ":pi", "p_x", "v^0", "1+", "-1+",
                        "...", "+", "-", "set-cdr!", "<=", "a.b", "L-free-particle"})
    EXPECT_EQ(roundtrip(s), s) << s;
  EXPECT_TRUE(read_text("->local")[0].datum.is(Tag::Symbol));
  EXPECT_TRUE(read_text("1+")[0].datum.is(Tag::Symbol));
  EXPECT_TRUE(read_text("-")[0].datum.is(Tag::Symbol));
}

TEST(Reader, SymbolsAreCaseSensitive) {
  auto forms = read_text("Foo foo");
  EXPECT_FALSE(eq(forms[0].datum, forms[1].datum));
}

TEST(Reader, StringsAndCharacters) {
  EXPECT_EQ(roundtrip("\"a\\nb\\\"c\\\\\""), "\"a\\nb\\\"c\\\\\"");
  EXPECT_EQ(roundtrip("#\\a"), "#\\a");
  EXPECT_EQ(roundtrip("#\\space"), "#\\space");
  EXPECT_EQ(roundtrip("#\\newline"), "#\\newline");
  EXPECT_EQ(roundtrip("#\\("), "#\\(");
  EXPECT_EQ(roundtrip("#\\x41"), "#\\A");
  EXPECT_EQ(display_string(read_text("\"\\x3bb;\"")[0].datum), "\xce\xbb");
}

TEST(Reader, BooleansAndSpecials) {
  EXPECT_EQ(roundtrip("#t"), "#t");
  EXPECT_EQ(roundtrip("#false"), "#f");
  EXPECT_EQ(roundtrip("(a #!optional b)"), "(a #!optional b)");
}

TEST(Reader, QuoteForms) {
  EXPECT_EQ(roundtrip("'x"), "(quote x)");
  EXPECT_EQ(roundtrip("`(a ,b ,@c)"), "(quasiquote (a (unquote b) (unquote-splicing c)))");
}

TEST(Reader, ListsVectorsAndDots) {
  EXPECT_EQ(roundtrip("(1 (2 3) . 4)"), "(1 (2 3) . 4)");
  EXPECT_EQ(roundtrip("#(1 2 (3))"), "#(1 2 (3))");
  EXPECT_EQ(roundtrip("()"), "()");
}

TEST(Reader, Comments) {
  EXPECT_EQ(roundtrip("; line\n(a #| block #| nested |# |# b #;(skipped datum) c)"), "(a b c)");
  EXPECT_EQ(read_text("; only a comment\n").size(), 0u);
}

TEST(Reader, PositionsOfFormsAndSubforms) {
  auto forms = read_text("(define x 1)\n  (foo\n   bar)");
  ASSERT_EQ(forms.size(), 2u);
  EXPECT_EQ(forms[0].loc.line, 1u);
  EXPECT_EQ(forms[0].loc.col, 1u);
  EXPECT_EQ(forms[1].loc.line, 2u);
  EXPECT_EQ(forms[1].loc.col, 3u);
  Value second = cdr(forms[1].datum);
  EXPECT_EQ(second.pair()->loc.line, 3u);
  EXPECT_EQ(second.pair()->loc.col, 4u);
}

TEST(Reader, ErrorsPointAtTheProblem) {
  EXPECT_EQ(error_of("(define x\n  (+ 1 2)"),
            "1:1: unbalanced parentheses: this '(' is never closed");
  EXPECT_EQ(error_of("(a))"), "1:4: unbalanced parentheses: unexpected ')'");
  EXPECT_EQ(error_of("\n  \"abc"), "2:3: unterminated string: this '\"' is never closed");
  EXPECT_EQ(error_of("#|"), "1:1: unterminated block comment: this '#|' is never closed");
  EXPECT_EQ(error_of("#\\bogus"), "1:1: unknown character name '#\\bogus'");
  EXPECT_EQ(error_of("(1 . )"), "1:4: ill-formed dotted list: nothing after '.'");
}

TEST(Reader, DeepNestingIsAnErrorNotACrash) {
  std::string deep(kMaxReadDepth + 10, '(');
  EXPECT_NE(error_of_on_big_stack(deep).find("nested too deeply"), std::string::npos);
}

namespace {

ErrorCause cause_of(const std::string &text) {
  try {
    read_text(text);
  } catch (const Error &e) {
    return e.cause;
  }
  return ErrorCause::Other;
}

} // namespace

// The REPL reads another line when the reader runs out of text inside a
// datum; it tells that from other errors by the cause, not the message.
TEST(Reader, IncompleteInputIsItsOwnCause) {
  for (const char *text : {"(+ 1", "[1 2", "\"abc", "#| comment", "'", "#\\", "|sym", "(a . b"})
    EXPECT_EQ(cause_of(text), ErrorCause::IncompleteInput) << text;
  for (const char *text : {")", "(a . b c)", "#q", "(1 ]"})
    EXPECT_EQ(cause_of(text), ErrorCause::Other) << text;
}
