// The kernel interpreter: a schedule as three-address instructions over a register file (see
// kernel_interpreter.hpp).
#include "codegen/kernel_interpreter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <math.h>
#include <unordered_map>

#include "base/error.hpp"
#include "codegen/schedule.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// The factorizations and solves the generated C calls, from the same
// source (the C emitter embeds its text).
#include "codegen/kernel_solve.inc"

enum class Code : uint8_t {
  Copy,
  Neg,
  Add,
  Sub,
  Mul,
  Div,
  Sin,
  Cos,
  Tan,
  Exp,
  Log,
  Sqrt,
  Asin,
  Acos,
  Atan,
  Sinh,
  Cosh,
  Fabs,
  Atan2,
  Pow,
  Copysign,
  SinCos,           // sincos(r[a], &r[dst], &r[b])
  LdltFactor,       // flags[c] = sicm_ldlt_factor(b, &r[dst])
  LuFactor,         // flags[c] = sicm_lu_factor(b, &r[dst], &pivots[a])
  LdltSolve,        // sicm_ldlt_solve(b, &r[a], &r[dst])
  LuSolve,          // sicm_lu_solve(b, &r[a], &pivots[c], &r[dst])
  SolveInterpreted, // sicm_linalg_solve_as_interpreted(b, &r[a], &r[c], &r[dst])
  Output,           // out[dst] = r[a]
  SingularCheck,    // any of flags[flag_lists[a .. a + b)]: every output the singular NaN
};

struct Instr {
  Code code;
  uint32_t dst = 0, a = 0, b = 0, c = 0;
};

// The libm functions a schedule calls, by their C names.
struct LibmFunction {
  const char *name;
  Code code;
  size_t arity;
};
constexpr LibmFunction kLibm[] = {
    {"sin", Code::Sin, 1},     {"cos", Code::Cos, 1},   {"tan", Code::Tan, 1},
    {"exp", Code::Exp, 1},     {"log", Code::Log, 1},   {"sqrt", Code::Sqrt, 1},
    {"asin", Code::Asin, 1},   {"acos", Code::Acos, 1}, {"atan", Code::Atan, 1},
    {"sinh", Code::Sinh, 1},   {"cosh", Code::Cosh, 1}, {"fabs", Code::Fabs, 1},
    {"atan2", Code::Atan2, 2}, {"pow", Code::Pow, 2},   {"copysign", Code::Copysign, 2},
};

constexpr uint32_t kNone = UINT32_MAX;

} // namespace

class KernelProgram {
public:
  std::vector<double> init; // the registers before a call: the constants, zeros elsewhere
  uint32_t in_base = 0, nin = 0, p_base = 0, np = 0;
  uint32_t nflags = 0, npivots = 0;
  std::vector<uint32_t> flag_lists;
  std::vector<Instr> code;
  uint32_t noutputs = 0;
};

namespace {

// Turns a schedule into a KernelProgram: each term gets the register that
// holds its value (computed by the instruction it adds, or a constant's, an
// input's, a temporary's), once.
class Loader {
public:
  Loader(const Schedule &s, std::span<Symbol *const> inputs, std::span<Symbol *const> params)
      : s_(s), term_reg_(s.terms.size(), kNone), temp_reg_(s.ntemps, kNone) {
    p_.nin = static_cast<uint32_t>(inputs.size());
    p_.np = static_cast<uint32_t>(params.size());
    p_.in_base = registers(p_.nin);
    p_.p_base = registers(p_.np);
    for (uint32_t i = 0; i < p_.nin; ++i)
      symbol_reg_[inputs[i]] = p_.in_base + i;
    for (uint32_t k = 0; k < p_.np; ++k)
      symbol_reg_[params[k]] = p_.p_base + k;
    p_.noutputs = static_cast<uint32_t>(s.noutputs);
  }

  KernelProgram load() {
    for (const Step &step : s_.steps)
      load_step(step);
    return std::move(p_);
  }

private:
  uint32_t registers(size_t n, double value = 0) {
    uint32_t first = static_cast<uint32_t>(p_.init.size());
    p_.init.insert(p_.init.end(), n, value);
    return first;
  }
  void emit(Code code, uint32_t dst, uint32_t a = 0, uint32_t b = 0, uint32_t c = 0) {
    p_.code.push_back(Instr{code, dst, a, b, c});
  }

  // Copies of the terms' values into the array at base.
  void fill(uint32_t base, const uint32_t *terms, size_t n) {
    for (size_t k = 0; k < n; ++k)
      emit(Code::Copy, base + static_cast<uint32_t>(k), value(terms[k]));
  }

  void load_step(const Step &step) {
    uint32_t n = step.n;
    switch (step.kind) {
    case StepKind::Define: temp_reg_[step.temp] = value(step.term); return;
    case StepKind::SinCos: {
      uint32_t a = value(step.term), sin = registers(1), cos = registers(1);
      emit(Code::SinCos, sin, a, cos);
      temp_reg_[step.temp] = sin;
      temp_reg_[step.temp2] = cos;
      return;
    }
    case StepKind::Factor: {
      uint32_t base = registers(size_t(n) * n);
      fill(base, step.terms.data(), step.terms.size());
      uint32_t flag = p_.nflags++;
      flag_of_[step.temp] = flag;
      if (step.symmetric) {
        emit(Code::LdltFactor, base, 0, n, flag);
      } else {
        pivots_of_[step.temp] = p_.npivots;
        emit(Code::LuFactor, base, p_.npivots, n, flag);
        p_.npivots += n;
      }
      temp_reg_[step.temp] = base;
      return;
    }
    case StepKind::Solve: {
      uint32_t x = registers(n);
      fill(x, step.terms.data(), step.terms.size());
      uint32_t a = temp_reg_[step.temp2];
      if (step.symmetric)
        emit(Code::LdltSolve, x, a, n);
      else
        emit(Code::LuSolve, x, a, n, pivots_of_.at(step.temp2));
      temp_reg_[step.temp] = x;
      return;
    }
    case StepKind::SolveInterpreted: {
      size_t nn = size_t(n) * n;
      uint32_t matrix = registers(nn), rhs = registers(n), x = registers(n);
      fill(matrix, step.terms.data(), nn);
      fill(rhs, step.terms.data() + nn, n);
      emit(Code::SolveInterpreted, x, matrix, n, rhs);
      temp_reg_[step.temp] = x;
      return;
    }
    case StepKind::Output: emit(Code::Output, step.output, value(step.term)); return;
    case StepKind::SingularCheck: {
      uint32_t first = static_cast<uint32_t>(p_.flag_lists.size());
      for (uint32_t f : step.flags)
        p_.flag_lists.push_back(flag_of_.at(f));
      emit(Code::SingularCheck, 0, first, static_cast<uint32_t>(step.flags.size()));
      return;
    }
    }
  }

  // The register of term t, adding the instructions of it and of the terms
  // it needs that have none yet. Terms come after their arguments
  // (schedule.hpp), so those are taken in increasing order, without
  // recursion (a sum of a thousand terms is a chain a thousand deep).
  uint32_t value(uint32_t t) {
    if (term_reg_[t] != kNone) return term_reg_[t];
    std::vector<uint32_t> needed, stack{t};
    while (!stack.empty()) {
      uint32_t u = stack.back();
      stack.pop_back();
      if (term_reg_[u] != kNone) continue;
      term_reg_[u] = kNone - 1; // queued
      needed.push_back(u);
      for (uint32_t a : s_.terms[u].args)
        stack.push_back(a);
    }
    std::sort(needed.begin(), needed.end());
    for (uint32_t u : needed)
      term_reg_[u] = compute(s_.terms[u]);
    return term_reg_[t];
  }

  uint32_t compute(const Term &t) {
    auto arg = [&](size_t i) { return term_reg_[t.args[i]]; };
    switch (t.kind) {
    case TermKind::Literal: return registers(1, t.value);
    case TermKind::Symbol: return symbol_reg_.at(t.symbol);
    case TermKind::Temp: return temp_reg_.at(t.temp);
    case TermKind::Element: return temp_reg_.at(t.temp) + t.element;
    case TermKind::Paren: return arg(0);
    case TermKind::Neg: return op(Code::Neg, arg(0));
    case TermKind::Add: return op(Code::Add, arg(0), arg(1));
    case TermKind::Sub: return op(Code::Sub, arg(0), arg(1));
    case TermKind::Mul: return op(Code::Mul, arg(0), arg(1));
    case TermKind::Div: return op(Code::Div, arg(0), arg(1));
    case TermKind::Call:
      for (const LibmFunction &f : kLibm)
        if (t.text == f.name) {
          SICM_ASSERT(t.args.size() == f.arity);
          return op(f.code, arg(0), f.arity == 2 ? arg(1) : 0);
        }
      break;
    case TermKind::CheckedCall:
    case TermKind::CheckedQuotient: break; // a residual program's, never a kernel's
    }
    internal_failure(__FILE__, __LINE__, "a term the kernel interpreter cannot compute");
  }

  uint32_t op(Code code, uint32_t a, uint32_t b = 0) {
    uint32_t dst = registers(1);
    emit(code, dst, a, b);
    return dst;
  }

  const Schedule &s_;
  KernelProgram p_;
  std::vector<uint32_t> term_reg_, temp_reg_;
  std::unordered_map<Symbol *, uint32_t> symbol_reg_;
  std::unordered_map<uint32_t, uint32_t> flag_of_, pivots_of_; // Factor temp -> flag, pivots
};

double singular_nan() {
  uint64_t bits = SICM_SINGULAR_NAN_BITS;
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

void run_interpreted_fn(const double *in, double *out, const double *p) {
  const auto *k = reinterpret_cast<const InterpretedKernel *>(p);
  run_kernel_program(*k->fn, in, out, k->params.data());
}

void run_interpreted_probe(const double *in, double *out, const double *p) {
  const auto *k = reinterpret_cast<const InterpretedKernel *>(p);
  run_kernel_program(*k->singular_factors, in, out, k->params.data());
}

} // namespace

bool kernels_interpreted() {
  static const bool interpreted = [] {
    const char *e = std::getenv("SICM_INTERPRET");
    return e && *e && std::strcmp(e, "0") != 0;
  }();
  return interpreted;
}

std::shared_ptr<const KernelProgram> load_kernel_program(const std::vector<ExprId> &outputs,
                                                         std::span<Symbol *const> inputs,
                                                         std::span<Symbol *const> params) {
  Schedule s = schedule_outputs(outputs);
  return std::make_shared<const KernelProgram>(Loader(s, inputs, params).load());
}

void run_kernel_program(const KernelProgram &k, const double *in, double *out, const double *p) {
  // Per thread, reused: a kernel runs to completion before another starts.
  thread_local std::vector<double> r;
  thread_local std::vector<int> flags, pivots;
  r.assign(k.init.begin(), k.init.end());
  std::copy(in, in + k.nin, r.begin() + k.in_base);
  if (k.np) std::copy(p, p + k.np, r.begin() + k.p_base);
  flags.assign(k.nflags, 0);
  pivots.assign(k.npivots, 0);
  double *x = r.data();
  for (const Instr &i : k.code) {
    switch (i.code) {
    case Code::Copy: x[i.dst] = x[i.a]; break;
    case Code::Neg: x[i.dst] = -x[i.a]; break;
    case Code::Add: x[i.dst] = x[i.a] + x[i.b]; break;
    case Code::Sub: x[i.dst] = x[i.a] - x[i.b]; break;
    case Code::Mul: x[i.dst] = x[i.a] * x[i.b]; break;
    case Code::Div: x[i.dst] = x[i.a] / x[i.b]; break;
    case Code::Sin: x[i.dst] = ::sin(x[i.a]); break;
    case Code::Cos: x[i.dst] = ::cos(x[i.a]); break;
    case Code::Tan: x[i.dst] = ::tan(x[i.a]); break;
    case Code::Exp: x[i.dst] = ::exp(x[i.a]); break;
    case Code::Log: x[i.dst] = ::log(x[i.a]); break;
    case Code::Sqrt: x[i.dst] = ::sqrt(x[i.a]); break;
    case Code::Asin: x[i.dst] = ::asin(x[i.a]); break;
    case Code::Acos: x[i.dst] = ::acos(x[i.a]); break;
    case Code::Atan: x[i.dst] = ::atan(x[i.a]); break;
    case Code::Sinh: x[i.dst] = ::sinh(x[i.a]); break;
    case Code::Cosh: x[i.dst] = ::cosh(x[i.a]); break;
    case Code::Fabs: x[i.dst] = ::fabs(x[i.a]); break;
    case Code::Atan2: x[i.dst] = ::atan2(x[i.a], x[i.b]); break;
    case Code::Pow: x[i.dst] = ::pow(x[i.a], x[i.b]); break;
    case Code::Copysign: x[i.dst] = ::copysign(x[i.a], x[i.b]); break;
    case Code::SinCos: ::sincos(x[i.a], &x[i.dst], &x[i.b]); break;
    case Code::LdltFactor: flags[i.c] = sicm_ldlt_factor(int(i.b), &x[i.dst]); break;
    case Code::LuFactor: flags[i.c] = sicm_lu_factor(int(i.b), &x[i.dst], &pivots[i.a]); break;
    case Code::LdltSolve: sicm_ldlt_solve(int(i.b), &x[i.a], &x[i.dst]); break;
    case Code::LuSolve: sicm_lu_solve(int(i.b), &x[i.a], &pivots[i.c], &x[i.dst]); break;
    case Code::SolveInterpreted:
      sicm_linalg_solve_as_interpreted(i.b, &x[i.a], &x[i.c], &x[i.dst]);
      break;
    case Code::Output: out[i.dst] = x[i.a]; break;
    case Code::SingularCheck: {
      int any = 0;
      for (uint32_t f = i.a; f < i.a + i.b; ++f)
        any |= flags[k.flag_lists[f]];
      if (any)
        for (uint32_t j = 0; j < k.noutputs; ++j)
          out[j] = singular_nan();
      break;
    }
    }
  }
}

KernelFn interpreted_kernel_entry() {
  return run_interpreted_fn;
}

KernelFn interpreted_probe_entry() {
  return run_interpreted_probe;
}

} // namespace sicm
