// Fuzz target: the C emitter, on random kernels decoded from the input.
//
// The bytes are a program for a small stack machine (decode below) that
// builds a DAG over the inputs x0..x3 with every operator of ops.def that the
// arena allows (I4: + and * with 2 to 4 arguments, / with 2, no -), small
// exact rationals and flonums, integer powers from -6 to 17 (the emitter
// writes them as products, by repeated squaring from 4 on, and negative ones
// as 1.0 / ...) and powers with rational or computed exponents (pow). Up to
// four of the values left on the stack are the kernel's outputs; a flag
// byte says whether they are simplified first, as trace_procedure does
// (what the emitter meets in practice), or emitted as built (its other
// shapes: Div chains, nested negations, constants folded by nobody).
// Properties:
//   1. emit_kernel_unit's C compiles with `cc -std=c11 -O2 -Wall -Wextra
//      -Werror -fPIC -shared` (the JIT's flags and every warning an error);
//   2. at 3 points (each input uniform in [-3, 3]), every output of the
//      loaded kernel agrees with the interpreter's value of the same DAG
//      (generic arithmetic on flonums, symbolic_apply node by node) to
//      |k - i| <= 1e-12 max(|k|, |i|), or, at an ill-conditioned point,
//      to 8 times the rounding-error bound of the DAG there (fuzz::NumEval),
//      since the C may round differently (x*x*x for pow(x, 3)) and a
//      cancellation magnifies that. A point where the interpreter raises
//      (sqrt or log of a negative: sicm has no complex numbers, a division
//      by an exact zero) or where any value or bound is not finite is
//      skipped.
// Each input starts the C compiler once, so this target runs at tens of
// inputs a second, not thousands.
#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "algebra/expr.hpp"
#include "algebra/simplify.hpp"
#include "algebra/symbolic.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/kernel.hpp"
#include "codegen/trace.hpp"
#include "common.hpp"
#include "eval/number.hpp"

extern char **environ;

using namespace sicm;

namespace {

constexpr int kInputs = 4;
constexpr int kMaxOps = 40;
constexpr size_t kMaxStack = 8;
constexpr size_t kMaxOutputs = 4;
constexpr int kPoints = 3;
constexpr double kRelTol = 1e-12;
constexpr double kBoundFactor = 8;

std::string g_dir; // a private temporary directory for the C and the objects

// What the checks did, printed at exit (for docs/reliability.md).
struct Stats {
  unsigned long kernels = 0, simplified = 0, outputs = 0, compared = 0, by_bound = 0, skipped = 0;
} g_stats;

void print_stats() {
  const Stats &s = g_stats;
  std::fprintf(stderr,
               "emit stats: %lu kernels compiled (%lu simplified), %lu output values: %lu "
               "compared (%lu within the error bound only), %lu skipped\n",
               s.kernels, s.simplified, s.outputs, s.compared, s.by_bound, s.skipped);
}
gcvec<Symbol *> g_inputs;
unsigned long g_serial = 0;

ExprId num(int64_t p, int64_t q = 1) {
  return expr_from_number(num_div(Value::fixnum(p), Value::fixnum(q)));
}

// The DAG the bytes describe: the outputs, bottom of the stack first.
std::vector<ExprId> decode(fuzz::Bytes &in) {
  std::vector<ExprId> stack;
  auto push = [&](ExprId e) {
    if (stack.size() == kMaxStack) stack.erase(stack.begin());
    stack.push_back(e);
  };
  auto pop = [&]() {
    if (stack.empty()) return expr_symbol(g_inputs[0]);
    ExprId e = stack.back();
    stack.pop_back();
    return e;
  };
  static const Op kUnary[] = {Op::Sqrt, Op::Exp,  Op::Log,  Op::Sin,  Op::Cos,  Op::Tan,
                              Op::Asin, Op::Acos, Op::Atan, Op::Sinh, Op::Cosh, Op::Abs};
  for (int ops = 0; ops < kMaxOps && !in.empty(); ++ops) {
    switch (in.below(16)) {
    case 0:
    case 1:
    case 2: push(expr_symbol(g_inputs[in.below(kInputs)])); break;
    case 3: push(num(in.in(-9, 9))); break;
    case 4: push(num(in.in(-9, 9), in.in(1, 7))); break;
    case 5: {
      static const double kFlonums[] = {0.5, -0.25, 0.1, -1.0, 1e-3, 2.5e8, -0.0, 3.0};
      push(expr_flonum(kFlonums[in.below(8)] * in.in(1, 4)));
      break;
    }
    case 6:
    case 7: { // + or * of the top k
      Op op = in.below(2) ? Op::Add : Op::Mul;
      size_t k = 2 + in.below(3);
      std::vector<ExprId> args(k);
      for (size_t i = k; i-- > 0;)
        args[i] = pop();
      push(expr_apply(op, args.data(), k));
      break;
    }
    case 8: { // a / b
      ExprId b = pop(), a = pop();
      push(expr_apply(Op::Div, {a, b}));
      break;
    }
    case 9: { // negation, as generic subtraction builds it
      ExprId a = pop();
      push(expr_apply(Op::Mul, {num(-1), a}));
      break;
    }
    case 10: { // an integer power
      ExprId a = pop();
      push(expr_apply(Op::Expt, {a, num(in.in(-6, 17))}));
      break;
    }
    case 11: { // a power with another exponent: 1/2, 1/3, -3/2, 2.5, or computed
      ExprId a = pop();
      static const int kP[] = {1, 1, -3, 5}, kQ[] = {2, 3, 2, 2};
      unsigned which = in.below(5);
      ExprId e = which < 4 ? (which == 3 ? expr_flonum(2.5) : num(kP[which], kQ[which])) : pop();
      push(expr_apply(Op::Expt, {a, e}));
      break;
    }
    case 12:
    case 13: push(expr_apply(kUnary[in.below(12)], {pop()})); break;
    case 14: { // atan of two arguments
      ExprId x = pop(), y = pop();
      push(expr_apply(Op::Atan, {y, x}));
      break;
    }
    case 15: { // share the top
      ExprId a = pop();
      push(a);
      push(a);
      break;
    }
    }
  }
  if (stack.size() > kMaxOutputs) stack.erase(stack.begin(), stack.end() - kMaxOutputs);
  return stack;
}

// The interpreter's value of id at the point: generic arithmetic node by
// node. Throws sicm::Error where the interpreter would.
Value interpret(ExprId id, const std::vector<double> &point, std::vector<Value> &memo,
                std::vector<bool> &done) {
  if (id < done.size() && done[id]) return memo[id];
  const ExprNode n = expr_node(id);
  Value v;
  switch (n.kind) {
  case ExprKind::Rational:
  case ExprKind::Flonum: v = expr_number_value(id); break;
  case ExprKind::Symbol:
    for (int i = 0; i < kInputs; ++i)
      if (g_inputs[i] == n.sym) v = Value::flonum(point[i]);
    break;
  case ExprKind::Call: fuzz::fail("a Call node in a kernel");
  case ExprKind::Apply: {
    gcvec<Value> args;
    for (ExprId a : expr_arg_vector(id))
      args.push_back(interpret(a, point, memo, done));
    v = symbolic_apply(n.op, args.data(), static_cast<int>(args.size()));
    break;
  }
  }
  if (id >= done.size()) {
    done.resize(id + 1);
    memo.resize(id + 1);
  }
  done[id] = true;
  memo[id] = v;
  return v;
}

// Does id hold an integer power of magnitude 2^20 or more? (Chained powers
// reach them: (expt (expt u 17) 17) ... .)
bool has_huge_power(ExprId id) {
  if (expr_kind(id) != ExprKind::Apply) return false;
  int64_t n;
  if (expr_is_apply(id, Op::Expt) && expr_get_int64(expr_arg(id, 1), &n) &&
      (n >= (int64_t(1) << 20) || n <= -(int64_t(1) << 20)))
    return true;
  if (expr_is_apply(id, Op::Expt) && expr_is_exact_integer(expr_arg(id, 1)) &&
      !expr_get_int64(expr_arg(id, 1), &n))
    return true; // beyond int64
  for (ExprId a : expr_arg_vector(id))
    if (has_huge_power(a)) return true;
  return false;
}

std::string slurp(const std::string &path) {
  std::ifstream f(path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Compile src into a shared object; "" on success, else why not.
// -Wno-unused-variable: the emitter can leave a temporary unused (known bug:
// fuzz/crashes-found/README.md, emit-2); remove it with the fix.
std::string compile(const std::string &c_path, const std::string &so_path) {
  std::string log = c_path + ".log";
  const char *argv[] = {"cc",
                        "-std=c11",
                        "-O2",
                        "-Wall",
                        "-Wextra",
                        "-Werror",
                        "-Wno-unused-variable",
                        "-fPIC",
                        "-shared",
                        "-o",
                        so_path.c_str(),
                        c_path.c_str(),
                        "-lm",
                        nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 2, 1);
  pid_t pid;
  int rc = posix_spawnp(&pid, "cc", &fa, nullptr, const_cast<char **>(argv), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) fuzz::fail("cannot start cc");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  std::string out = slurp(log);
  unlink(log.c_str());
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && out.empty()) return "";
  return out.empty() ? "cc failed without a message" : out;
}

void check_kernel(const Trace &t, uint64_t seed) {
  std::string stem = g_dir + "/k" + std::to_string(g_serial++);
  std::string c_path = stem + ".c", so_path = stem + ".so";
  const std::string name = "sicm_kernel_fuzz";
  std::string src = emit_kernel_unit(t, name, "fuzz");
  std::ofstream(c_path) << src;
  std::string why = compile(c_path, so_path);
  if (!why.empty()) fuzz::fail("the emitted C does not compile cleanly:\n" + why + "\n" + src);
  void *so = dlopen(so_path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!so) fuzz::fail(std::string("dlopen: ") + dlerror());
  auto fn = reinterpret_cast<KernelFn>(dlsym(so, name.c_str()));
  if (!fn) fuzz::fail("the kernel's symbol is missing");

  fuzz::Rng rng(seed);
  std::vector<Symbol *> inputs(t.inputs.begin(), t.inputs.end());
  for (int p = 0; p < kPoints; ++p) {
    std::vector<double> point(kInputs);
    for (double &x : point)
      x = rng.uniform(-3, 3);
    std::vector<double> out(t.outputs.size(), NAN);
    fn(point.data(), out.data(), nullptr);
    fuzz::NumEval numeric(inputs, point);
    std::vector<Value> memo;
    std::vector<bool> done;
    g_stats.outputs += t.outputs.size();
    for (size_t j = 0; j < t.outputs.size(); ++j) {
      fuzz::Approx bound = numeric.eval(t.outputs[j]);
      // A value the interpreter cannot give (it raises for sqrt of a
      // negative) or an infinity on the way: not comparable.
      if (!numeric.all_finite()) { // later outputs may share the nodes that were not
        g_stats.skipped += t.outputs.size() - j;
        break;
      }
      double want;
      try {
        want = to_double(interpret(t.outputs[j], point, memo, done));
      } catch (const Error &) {
        g_stats.skipped += t.outputs.size() - j;
        break; // the interpreter refuses this point
      }
      double got = out[j];
      double diff = std::fabs(got - want);
      bool relative = diff <= kRelTol * std::max(std::fabs(got), std::fabs(want));
      if (std::isfinite(want) && (relative || diff <= kBoundFactor * bound.e)) {
        ++g_stats.compared;
        g_stats.by_bound += !relative;
        continue;
      }
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "output %zu at (%.17g, %.17g, %.17g, %.17g): kernel %.17g, interpreter "
                    "%.17g, rounding-error bound %.3g",
                    j, point[0], point[1], point[2], point[3], got, want, bound.e);
      fuzz::fail(std::string("the kernel disagrees with the interpreter\n") + buf +
                 "\n  expression: " + expr_debug_string(t.outputs[j]) + "\n" + src);
    }
  }
  dlclose(so);
  unlink(c_path.c_str());
  unlink(so_path.c_str());
}

} // namespace

void fuzz_setup() {
  const char *tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/sicm-fuzz-emit-XXXXXX";
  std::vector<char> buf(templ.begin(), templ.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) fuzz::fail("cannot make a temporary directory");
  g_dir = buf.data();
  std::atexit([] { rmdir(g_dir.c_str()); });
  std::atexit(print_stats);
  for (int i = 0; i < kInputs; ++i)
    g_inputs.push_back(make_uninterned_symbol("x" + std::to_string(i)).symbol());
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size == 0) return 0;
  fuzz::Bytes in(data, size);
  bool simplified = in.below(2) == 1;
  Trace t;
  t.inputs = g_inputs;
  t.outputs = decode(in);
  t.result_shape = Value::fixnum(0);
  if (t.outputs.empty()) return 0;
  if (simplified) {
    try {
      for (ExprId &o : t.outputs)
        o = simplify_expr(o);
    } catch (const Error &) {
      return 0; // a division by something that simplifies to zero
    }
  }
  // Known bug (fuzz/crashes-found/README.md, emit-1): a huge integer power
  // of a constant makes the C compiler run for minutes.
  for (ExprId o : t.outputs)
    if (has_huge_power(o)) return 0;
  ++g_stats.kernels;
  g_stats.simplified += simplified;
  check_kernel(t, fuzz::hash_bytes(data, size));
  return 0;
}
