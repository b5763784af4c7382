// The reader meets 10,000+ generated malformed inputs (random bytes,
// truncations and mutations of valid programs) and must answer each with a
// clean Error at a position inside the text, or a successful read; never a
// crash or any other exception.
#include <gtest/gtest.h>

#include <random>

#include "syntax/reader.hpp"

using namespace sicm;

namespace {

const char *const kValidPrograms[] = {
    "(define (L-free-particle mass)\n  (lambda (local)\n    (let ((v (velocity local)))\n"
    "      (* 1/2 mass (dot-product v v)))))\n",
    "(define q (up (literal-function 'x) (literal-function 'y)))\n((Gamma q) 't)\n",
    "(let loop ((i 0) (acc '()))\n  (if (> i 10) (reverse acc) (loop (+ i 1) (cons (* i i) "
    "acc))))\n",
    "#| block #| nested |# |# (display \"a \\\"string\\\"\\n\") #;(ignored) 'sym `(a ,b ,@c)\n",
    "(vector #(1 2.5 -3/4 1e-13 .5) #\\a #\\space #t #f (a . b) |odd symbol|)\n",
    "(define ((f a) b #!optional c) (if (default-object? c) (+ a b) c)) ; comment\n",
};

// How one input went: 0 = read fine, 1 = clean error.
int try_read(const std::string &text) {
  uint32_t file = register_source("fuzz.sicm", text);
  try {
    read_all(file);
    return 0;
  } catch (const Error &e) {
    // The position must be inside the text (or just past its end).
    EXPECT_TRUE(e.loc.known()) << text;
    EXPECT_GE(e.loc.line, 1u);
    size_t lines = 1;
    for (char c : text)
      lines += c == '\n';
    EXPECT_LE(e.loc.line, lines) << text;
    EXPECT_FALSE(std::string(e.what()).empty());
    return 1;
  }
}

std::string mutate(std::string s, std::mt19937 &rng) {
  static const std::string alphabet = "()()\"\"#|;'`,@.\\ \n\tab1/-+e#!x";
  int edits = 1 + static_cast<int>(rng() % 4);
  for (int k = 0; k < edits; ++k) {
    size_t at = s.empty() ? 0 : rng() % (s.size() + 1);
    switch (rng() % 3) {
    case 0: s.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
    case 1:
      if (!s.empty() && at < s.size()) s.erase(at, 1);
      break;
    default:
      if (!s.empty() && at < s.size()) s[at] = alphabet[rng() % alphabet.size()];
    }
  }
  return s;
}

} // namespace

TEST(ReaderRobustness, TenThousandMalformedInputsGiveCleanErrors) {
  std::mt19937 rng(20261121);
  int inputs = 0, errors = 0;
  // Random bytes, including NULs and invalid UTF-8.
  for (int i = 0; i < 3000; ++i, ++inputs) {
    std::string s(rng() % 64, '\0');
    for (char &c : s)
      c = static_cast<char>(rng() % 256);
    errors += try_read(s);
  }
  // Every truncation of every valid program.
  for (const char *p : kValidPrograms) {
    std::string prog(p);
    for (size_t n = 0; n <= prog.size(); ++n, ++inputs)
      errors += try_read(prog.substr(0, n));
  }
  // Random mutations.
  for (int i = 0; i < 7000; ++i, ++inputs) {
    std::string prog(kValidPrograms[rng() % std::size(kValidPrograms)]);
    errors += try_read(mutate(prog, rng));
  }
  EXPECT_GE(inputs, 10000);
  // Most of them must really be malformed, or the test proves little.
  EXPECT_GE(errors, inputs / 2) << errors << " errors of " << inputs;
}
