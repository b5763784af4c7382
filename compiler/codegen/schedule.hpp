// The schedule of a kernel: its outputs as a straight-line list of steps over expression trees of
// doubles, which the C emitter prints and the kernel interpreter runs.
//
// Requires: outputs over symbols with only numbers, symbols, ops.def
// applications and solve nodes (a Trace's, or a residual program's
// values). Produces: every decision that fixes the floating-point
// operations a kernel performs: which nodes are computed once into a
// temporary (CSE by use counts), integer powers as products and squarings,
// sin and cos of one argument as one sincos, linear solves as LDL^T or LU
// factorizations, the exact zeros (see schedule.cpp). A term is one IEEE
// operation or libm call on the values of its arguments, so whoever
// evaluates the terms as written, in C (emit_c.cpp) or in the interpreter
// (kernel_interpreter.cpp), computes the same bits: the order of
// operations is the trees', and C's precedence never regroups them (the
// printer parenthesizes exactly where it would).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cas/expr.hpp"

namespace sicm {

// C precedence levels of the forms a term is written in, tightest first.
enum TermPrec : int { kAtom = 0, kUnary = 1, kMul = 2, kAdd = 3 };

enum class TermKind : uint8_t {
  Literal,         // value, written as text
  Symbol,          // an input or parameter (the caller spells it)
  Temp,            // the scalar temporary `temp`
  Element,         // element `element` of the array temporary `temp`
  Paren,           // args[0], parenthesized (an operand that must be an atom)
  Neg,             // -args[0]
  Add,             // args[0] + args[1]
  Sub,             // args[0] - args[1]
  Mul,             // args[0] * args[1]
  Div,             // args[0] / args[1]
  Call,            // the libm function `text` of args
  CheckedCall,     // the runtime's sicm_checked_`text`(site, args...)
  CheckedQuotient, // sicm_checked_quotient(site, "text", args[0], args[1])
};

struct Term {
  explicit Term(TermKind k) : kind(k) {}
  TermKind kind;
  int prec = kAtom;
  double value = 0;           // Literal
  std::string text;           // Literal: its C spelling; calls: the function; CheckedQuotient: who
  Symbol *symbol = nullptr;   // Symbol
  uint32_t temp = 0;          // Temp, Element
  uint32_t element = 0;       // Element
  std::vector<uint32_t> args; // terms with smaller indices
  ExprId source = kNoExpr;    // checked terms: the operation node they compute (its site)
};

enum class StepKind : uint8_t {
  Define,           // double temp = term
  SinCos,           // double temp, temp2; sincos(term, &temp, &temp2)
  Factor,           // double temp[n * n] = {terms}; factored in place: LDL^T if symmetric, else LU
  Solve,            // double temp[n] = {terms}; solved with the factors in temp2
  SolveInterpreted, // double temp[n] solves (terms: n * n matrix, n rhs) as the interpreter does
  Output,           // target `output` = term
  SingularCheck, // if any factorization in `flags` was singular, every output is the singular NaN
};

struct Step {
  explicit Step(StepKind k) : kind(k) {}
  StepKind kind;
  uint32_t temp = 0, temp2 = 0;
  uint32_t term = 0;
  uint32_t output = 0;
  uint32_t n = 0;
  bool symmetric = false;
  std::vector<uint32_t> terms;
  std::vector<uint32_t> flags; // the Factor steps' temps
};

struct Schedule {
  std::vector<Term> terms;
  std::vector<Step> steps;
  uint32_t ntemps = 0;
  size_t noutputs = 0;
};

// The schedule that computes outputs[j] into output j. checked: division,
// sqrt, log, asin, acos and pow as the runtime's checked forms (a residual
// program's own arithmetic, which fails where the interpreter raises);
// kernels are unchecked.
Schedule schedule_outputs(const std::vector<ExprId> &outputs, bool checked = false);

} // namespace sicm
