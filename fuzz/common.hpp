// What the fuzz targets share: start-up on a big stack, a byte decoder, and a
// numerical evaluator of expression DAGs that bounds its own rounding error.
//
// Every target is linked with common.cpp, which provides main(): it starts the
// collector, then runs libFuzzer (LLVMFuzzerRunDriver) on a thread with a
// big stack and the stack guard that `sicm` gives its evaluator, so deep
// recursion in the reader, the evaluator or the simplifier ends in the
// error it gives in the real program rather than overflowing libFuzzer's
// 8 MiB main stack (common.cpp says why the stack is smaller than sicm's).
// A target defines fuzz_setup() (called once on that thread, before the
// first input) and LLVMFuzzerTestOneInput.
#pragma once

#include <complex>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "cas/expr.hpp"

// Called once, on the fuzzing thread, before any input.
void fuzz_setup();

namespace fuzz {

using sicm::ExprId;
using sicm::Symbol;

// Restore the evaluator's stack guard to what main() set (the eval target
// trips it on purpose to cancel a run).
void reset_stack_limit();

// Put sicm's expression size limit (--max-expression-nodes) in force at
// `nodes`, no other limit; begin_input counts it from zero again, as the
// REPL does for each form. The simplify and emit targets use it to refuse
// expansions that would take FLINT minutes (the limit's own check of
// expansions, base/limits.hpp) well inside libFuzzer's -timeout.
void limit_expression_nodes(uint64_t nodes);
void begin_input();

// Stop the process with a message on stderr (libFuzzer reports the abort as
// a crash and saves the input).
[[noreturn]] void fail(const std::string &what);

// Reads small integers from the fuzzer's bytes; past the end it yields 0,
// so every byte string decodes to something.
class Bytes {
public:
  Bytes(const uint8_t *data, size_t size) : p_(data), end_(data + size) {}
  bool empty() const { return p_ == end_; }
  uint8_t byte() { return p_ == end_ ? 0 : *p_++; }
  // A value in [0, n), n >= 1.
  unsigned below(unsigned n) { return byte() % n; }
  // A value in [lo, hi].
  int in(int lo, int hi) {
    return lo + static_cast<int>(below(static_cast<unsigned>(hi - lo + 1)));
  }

private:
  const uint8_t *p_, *end_;
};

// A small deterministic generator (splitmix64), seeded from the input, for
// the points at which expressions are compared.
class Rng {
public:
  explicit Rng(uint64_t seed) : s_(seed) {}
  uint64_t next();
  // Uniform in [lo, hi).
  double uniform(double lo, double hi);

private:
  uint64_t s_;
};
uint64_t hash_bytes(const uint8_t *data, size_t size);

// The value of an expression DAG at a point, in complex doubles, with a
// first-order bound on the rounding error of that evaluation.
//
// Complex, because the simplifier uses identities that hold in complex
// arithmetic but not in real arithmetic where an intermediate value is not
// real: (expt (sqrt u) 2) is u also for u < 0. Every operator is evaluated
// on its principal branch (std::sqrt, std::log, ...); a caller wanting real
// semantics checks the imaginary part. Nodes are evaluated children first.
// Each carries its value v and a bound e on |v - exact value at the point|,
// propagated as a running error analysis does: for a + b, e_a + e_b +
// u|a + b|; for a b, |b| e_a + |a| e_b + u|a b|; for f(a), |f'(a)| e_a +
// 2u|f(a)| (libm is within an ulp or so); constants that are not doubles
// start with u|c|; the point's coordinates are exact. The bound is
// first-order (it ignores products of errors), which is what lets two
// evaluations of one function in different forms be compared honestly:
// when the bound is large beside the value, the point is ill-conditioned
// (cancellation, a near-zero denominator) and the forms may legitimately
// disagree by about that much.
struct Approx {
  std::complex<double> v;
  double e = 0;
  // Some operator on the way (sqrt, log, a power that is not an integer,
  // asin, acos) had a real argument whose interval reaches past the edge of
  // its real domain: a correct evaluation may round to the other side and
  // give NaN where the interpreter has a value (an expanded polynomial
  // worth 1.6e-21, whose largest term's last bit is 3.4e-21, to the 5/2:
  // emit run H).
  bool edge = false;
};

class NumEval {
public:
  // symbols[i] takes the value point[i]; any other symbol, and Call nodes,
  // evaluate to NaN.
  NumEval(std::vector<Symbol *> symbols, std::vector<double> point)
      : symbols_(std::move(symbols)), point_(std::move(point)) {}
  Approx eval(ExprId id);
  // False if some node on the way had a value or bound that was not finite.
  bool all_finite() const { return finite_; }
  // True if the first-order bound cannot be trusted: some node divided by,
  // took a negative power or a root of, a value whose own bound is more
  // than 1/100 of it (the error of 1/b is not |e_b / b^2| when e_b is
  // comparable to b). The point is then too ill-conditioned to judge.
  bool degenerate() const { return degenerate_; }
  // Take the negative root at the sqrt nodes given (and forget what was
  // evaluated before): the simplifier assumes, as scmutils does, that
  // (sqrt (expt u 2)) is u, so a form it returns may equal the original
  // only on another branch of some square roots.
  void set_negative_roots(std::vector<ExprId> roots) {
    negative_ = std::move(roots);
    memo_.clear();
    finite_ = true;
    degenerate_ = false;
  }

private:
  Approx node(ExprId id);
  std::vector<Symbol *> symbols_;
  std::vector<double> point_;
  std::vector<ExprId> negative_;
  std::unordered_map<ExprId, Approx> memo_;
  bool finite_ = true;
  bool degenerate_ = false;
};

// The distinct sqrt nodes reachable from id (in increasing id order).
std::vector<ExprId> sqrt_nodes(ExprId id);

} // namespace fuzz
