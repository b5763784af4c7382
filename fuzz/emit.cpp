// Fuzz target: the C emitter, on random kernels decoded from the input.
//
// The bytes are a program for a small stack machine (decode below) that
// builds a DAG over the inputs x0..x3 with every operator of ops.def that the
// arena allows (I4: + and * with 2 to 4 arguments, / with 2, no -), small
// exact rationals and flonums, integer powers from -6 to 17 (the emitter
// writes them as products, by repeated squaring from 4 on, and negative ones
// as 1.0 / ...) and powers with rational or computed exponents (pow). Up to
// four of the values left on the stack are the kernel's outputs; a flag
// byte says whether they are rewritten locally first (rewrite_locally, as
// kernels that keep their traced DAG are), simplified first
// (kernel_output_form, as small kernels may be: an expansion that could
// pass kMaxExpressionNodes is then a sicm error, and the input is not
// used; a kernel of degree past kMaxSimplifiedDegree is not simplified,
// for time), or emitted as built (its other shapes: Div chains, nested
// negations, constants folded by nobody).
// Properties:
//   1. emit_kernel_unit's C compiles with `cc -std=c11 -O2 -Wall -Wextra
//      -Werror -fPIC -shared` (the JIT's flags and every warning an error);
//   2. at 3 points (each input uniform in [-3, 3]), every output of the
//      loaded kernel agrees with the interpreter's value of the same DAG
//      (for a rewritten kernel, of the DAG as built, before the rewrites)
//      (generic arithmetic on flonums, symbolic_apply node by node) to
//      |k - i| <= 1e-12 max(|k|, |i|), or, at an ill-conditioned point,
//      to 8 times the rounding-error bound of the DAG there (fuzz::NumEval),
//      since the C may round differently (x*x*x for pow(x, 3)) and a
//      cancellation magnifies that; two values closer than the smallest
//      normal double (DBL_MIN) agree, since neither has relative accuracy
//      left there. A point where the interpreter raises
//      (sqrt or log of a negative: sicm has no complex numbers, a division
//      by an exact zero) or where any value or bound is not finite is
//      skipped, and so is a NaN from the kernel where the argument of a
//      root, log, fractional power, asin or acos is known only to an
//      interval that reaches past the edge of its domain.
//   3. the C compiler finishes within kCompileSeconds (a kernel that makes
//      it run for minutes is a bug: emit-1).
// Starting the C compiler costs about 70 ms, so the kernels are compiled in
// batches: each input's unit is emitted at once (a failure of the emitter
// itself is the input's own) and kept with the input's bytes; every kBatch
// inputs, and at exit, the batch's units are concatenated into one
// translation unit (each unit verbatim but for the function's name, which
// is made unique: <math.h> and _GNU_SOURCE repeat harmlessly) and compiled
// with the same flags, loaded, and every kernel checked as above. A unit
// identical to one compiled before (about half of them: mutations that do
// not change the DAG) is not compiled again; its input is checked at its own
// points with the code loaded then. A failure is charged to the kernel it
// concerns (a diagnostic by its line; a disagreement by its kernel; a
// compiler killed at the time limit by compiling each unit alone), whose
// unit is compiled again alone to confirm and report it, and whose input's
// bytes are written to ARTIFACT_PREFIX/culprit-HASH (libFuzzer's own crash
// file is then only the input that completed the batch). Given input files
// rather than a corpus directory (reproduction), or with FUZZ_EMIT_BATCH=1,
// every input is compiled alone at once.
#include <dlfcn.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "cas/expr.hpp"
#include "cas/simplify.hpp"
#include "codegen/emit_c.hpp"
#include "codegen/kernel.hpp"
#include "codegen/local_rewrite.hpp"
#include "codegen/trace.hpp"
#include "common.hpp"

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
constexpr size_t kBatch = 256;      // kernels per C compilation
constexpr int kCompileSeconds = 20; // per unit alone
constexpr int kBatchSeconds = 120;  // per batch, then each unit alone
constexpr size_t kMaxUnitBytes = 256 << 10;
// FUZZ_VERBOSE: print each kernel's outputs as decoded (to reproduce).
bool g_verbose = false;
// sicm's --max-expression-nodes while an input is simplified: an expansion
// that could pass it is an error (a sicm::Error, which the target counts
// as "raised") before FLINT starts on it.
constexpr uint64_t kMaxExpressionNodes = 100'000;
constexpr double kMaxSimplifiedDegree = 256;

std::string g_dir;             // a private temporary directory for the C and the objects
std::string g_artifact_prefix; // libFuzzer's -artifact_prefix ("" if not given)
size_t g_batch_size = kBatch;

// What the checks did, printed at exit (for docs/reliability.md).
struct Stats {
  unsigned long kernels = 0, simplified = 0, outputs = 0, compared = 0, by_bound = 0, skipped = 0,
                compilations = 0, reused = 0, too_large = 0, slow_batches = 0;
  double compile_seconds = 0;
} g_stats;

void print_stats() {
  const Stats &s = g_stats;
  std::fprintf(stderr,
               "emit stats: %lu kernels (%lu simplified; %lu the same C as one before, not "
               "compiled again) in %lu compilations (%.1f s), %lu output values: %lu compared "
               "(%lu within the error bound only), %lu skipped; %lu units too large to compile, "
               "%lu batches compiled unit by unit\n",
               s.kernels, s.simplified, s.reused, s.compilations, s.compile_seconds, s.outputs,
               s.compared, s.by_bound, s.skipped, s.too_large, s.slow_batches);
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
// node. Throws sicm::Error where the interpreter would, or where it would
// leave the reals.
// Values the interpreter computed, by node: a map in collected memory (the
// collector must see the Values; ids index the whole arena).
using ValueMemo = std::unordered_map<ExprId, Value, std::hash<ExprId>, std::equal_to<ExprId>,
                                     gc_allocator<std::pair<const ExprId, Value>>>;

Value interpret(ExprId id, const std::vector<double> &point, ValueMemo &memo) {
  if (auto it = memo.find(id); it != memo.end()) return it->second;
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
      args.push_back(interpret(a, point, memo));
    v = symbolic_apply(n.op, args.data(), static_cast<int>(args.size()));
    // Kernels compute with doubles: where the interpreter leaves the reals
    // (sqrt of a negative number) the kernel's NaN is right, and the
    // interpreter's value, real again after an even power, is no yardstick.
    if (is_recnum(v)) throw Error(ErrorKind::Runtime, SrcLoc{}, "a complex intermediate");
    break;
  }
  }
  memo[id] = v;
  return v;
}

// A bound on the degree of id as a power of its leaves: a leaf 1, (expt a
// n) |n| times a's, a product or quotient the sum of its arguments', anything
// else the largest of its arguments'; saturating at 2^80. Unsimplified
// kernels nest powers ((expt (expt u -4) -4) ...) that each stay small;
// simplified, such a chain reaches the simplifier's polynomials (and past
// its degree limit raises, simplify-6).
double degree(ExprId id, std::unordered_map<ExprId, double> &memo) {
  constexpr double kCap = 0x1p80;
  if (expr_kind(id) != ExprKind::Apply) return 1;
  if (auto it = memo.find(id); it != memo.end()) return it->second;
  std::vector<ExprId> args = expr_arg_vector(id);
  double d = 0;
  int64_t n;
  if (expr_is_apply(id, Op::Expt) && expr_get_int64(expr_arg(id, 1), &n) && n == 0) {
    d = 1; // (expt u 0) is 1
  } else if (expr_is_apply(id, Op::Mul) &&
             std::any_of(args.begin(), args.end(), expr_is_exact_zero)) {
    d = 1; // a product with an exact 0 is 0
  } else if (expr_is_apply(id, Op::Expt) && expr_get_int64(expr_arg(id, 1), &n)) {
    d = degree(args[0], memo) * std::max<double>(1, std::fabs(static_cast<double>(n)));
  } else {
    bool sum = expr_is_apply(id, Op::Mul) || expr_is_apply(id, Op::Div);
    for (ExprId a : args) {
      double da = degree(a, memo);
      d = sum ? d + da : std::max(d, da);
    }
  }
  d = std::min(d, kCap);
  memo[id] = d;
  return d;
}

std::string slurp(const std::string &path) {
  std::ifstream f(path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// Compile src into a shared object; "" on success, else why not (the
// compiler's messages, or that it ran past kCompileSeconds and was killed).
std::string compile(const std::string &c_path, const std::string &so_path,
                    int seconds = kCompileSeconds) {
  std::string log = c_path + ".log";
  const char *argv[] = {"cc",           "-std=c11", "-O2",     "-Wall", "-Wextra",
                        "-Werror",      "-fPIC",    "-shared", "-o",    so_path.c_str(),
                        c_path.c_str(), "-lm",      nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 2, 1);
  posix_spawnattr_t attr; // its own process group, so that a kill reaches cc1 too
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  auto start = std::chrono::steady_clock::now();
  pid_t pid;
  int rc = posix_spawnp(&pid, "cc", &fa, &attr, const_cast<char **>(argv), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) fuzz::fail("cannot start cc");
  int status = 0;
  bool killed = false;
  for (auto pause = std::chrono::microseconds(200);;) {
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) fuzz::fail("waitpid failed");
    if (!killed && std::chrono::steady_clock::now() - start > std::chrono::seconds(seconds)) {
      kill(-pid, SIGKILL);
      killed = true;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
  ++g_stats.compilations;
  g_stats.compile_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string out = slurp(log);
  unlink(log.c_str());
  if (killed)
    return "the C compiler ran for more than " + std::to_string(seconds) + " s and was killed";
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && out.empty()) return "";
  return out.empty() ? "cc failed without a message" : out;
}

// An input whose kernel waits in the batch.
struct Pending {
  std::vector<uint8_t> bytes;
  std::vector<ExprId> outputs;
  std::string name, src; // the C function's name and its translation unit
  uint64_t key = 0;      // hash of the unit as emitted under kName
  size_t first_line = 0; // where src starts in the batch's file (1-based)
  long same_as = -1;     // an earlier kernel of the batch with the same unit
};
std::vector<Pending> g_batch;

// Kernels compiled and loaded before, by the hash of their unit (the C
// emitted under kName): the same C is not compiled again, but checked at
// the new input's own points with the code loaded before. Their shared
// objects stay loaded, up to kMaxLoaded of them.
const std::string kName = "sicm_kernel_fuzz";
constexpr size_t kMaxLoaded = 2048;
std::unordered_map<uint64_t, KernelFn> g_compiled;
std::vector<void *> g_loaded;
std::unordered_map<uint64_t, size_t> g_in_batch; // key -> index in g_batch

uint64_t unit_key(const std::string &src) {
  uint64_t h = fuzz::hash_bytes(reinterpret_cast<const uint8_t *>(src.data()), src.size());
  return h ^ (src.size() * 0x9e3779b97f4a7c15ULL);
}

std::string hex(uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// Write the input to ARTIFACT_PREFIX/culprit-HASH and fail with what.
[[noreturn]] void fail_for(const Pending &k, const std::string &what) {
  std::string path =
      g_artifact_prefix + "culprit-" + hex(fuzz::hash_bytes(k.bytes.data(), k.bytes.size()));
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char *>(k.bytes.data()),
             static_cast<std::streamsize>(k.bytes.size()));
  fuzz::fail(what + "\nThe input that shows this is saved as " + path +
             " (reproduce: build/fuzz/fuzz-emit " + path + ")");
}

// Check one loaded kernel against the interpreter (property 2).
void check_kernel(const Pending &k, KernelFn fn) {
  fuzz::Rng rng(fuzz::hash_bytes(k.bytes.data(), k.bytes.size()));
  std::vector<Symbol *> inputs(g_inputs.begin(), g_inputs.end());
  const std::vector<ExprId> &outputs = k.outputs;
  for (int p = 0; p < kPoints; ++p) {
    std::vector<double> point(kInputs);
    for (double &x : point)
      x = rng.uniform(-3, 3);
    std::vector<double> out(outputs.size(), NAN);
    fn(point.data(), out.data(), nullptr);
    fuzz::NumEval numeric(inputs, point);
    ValueMemo memo;
    g_stats.outputs += outputs.size();
    for (size_t j = 0; j < outputs.size(); ++j) {
      fuzz::Approx bound = numeric.eval(outputs[j]);
      // A value the interpreter cannot give (a complex one, for sqrt of a
      // negative) or an infinity on the way: not comparable.
      if (!numeric.all_finite()) { // later outputs may share the nodes that were not
        g_stats.skipped += outputs.size() - j;
        break;
      }
      double want;
      try {
        want = to_double(interpret(outputs[j], point, memo));
      } catch (const Error &) {
        g_stats.skipped += outputs.size() - j;
        break; // the interpreter refuses this point
      }
      double got = out[j];
      // The interpreter overflowed where the evaluator of the bound did not
      // (a power of 1e112): equal infinities agree, others are skipped, as
      // the property says of values that are not finite.
      if (!std::isfinite(want)) {
        if (got == want) {
          ++g_stats.compared;
        } else {
          ++g_stats.skipped;
        }
        continue;
      }
      double diff = std::fabs(got - want);
      bool relative = diff <= kRelTol * std::max(std::fabs(got), std::fabs(want));
      // Below the smallest normal double a result has no relative accuracy
      // left, and the C and the interpreter may reach it differently: for
      // x^-1536, the C's 1.0 / (x^1536) overflows to 1/inf = 0 where the
      // interpreter's (x^-256)^6 gives the subnormal 1.35e-310.
      bool both_tiny = diff <= DBL_MIN;
      // A bound as large as the value says nothing is known of it: then a
      // NaN from the kernel (sqrt or acos of tan of 1e44, whose argument
      // rounded to the other side of the domain's edge) is no finding.
      // So is a NaN where an argument's interval reached past its domain's
      // edge (Approx::edge): the C rounded to the other side of it.
      bool unknown = std::isnan(got) && (bound.edge || kBoundFactor * bound.e >= std::fabs(want));
      if (std::isfinite(want) &&
          (relative || both_tiny || unknown || diff <= kBoundFactor * bound.e)) {
        ++g_stats.compared;
        g_stats.by_bound += !relative;
        continue;
      }
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "output %zu at (%.17g, %.17g, %.17g, %.17g): kernel %.17g, interpreter "
                    "%.17g, rounding-error bound %.3g",
                    j, point[0], point[1], point[2], point[3], got, want, bound.e);
      fail_for(k, std::string("the kernel disagrees with the interpreter\n") + buf +
                      "\n  expression: " + expr_debug_string(outputs[j]) + "\n" + k.src);
    }
  }
}

// The kernel of the batch whose unit holds the first line of a diagnostic
// about path in the compiler's output, or nullptr.
const Pending *culprit_of(const std::string &why, const std::string &path) {
  std::string key = path + ":";
  for (size_t at = why.find(key); at != std::string::npos; at = why.find(key, at + 1)) {
    size_t line = std::strtoul(why.c_str() + at + key.size(), nullptr, 10);
    if (line == 0) continue; // "path: In function ...", not a line
    const Pending *found = nullptr;
    for (const Pending &k : g_batch)
      if (k.same_as < 0 && k.first_line <= line) found = &k;
    return found;
  }
  return nullptr;
}

void check_batch();
void set_alarm_blocked(bool blocked) {
  sigset_t alarm;
  sigemptyset(&alarm);
  sigaddset(&alarm, SIGALRM);
  pthread_sigmask(blocked ? SIG_BLOCK : SIG_UNBLOCK, &alarm, nullptr);
}

// Check the batch, then empty it. libFuzzer's -timeout would charge the
// batch's time to the input that completed it, so its alarm is held off
// meanwhile; compile() bounds the compiler's time instead.
void flush() {
  if (g_batch.empty()) return;
  set_alarm_blocked(true);
  check_batch();
  g_batch.clear();
  g_in_batch.clear();
  set_alarm_blocked(false);
}

void check_batch() {
  std::string stem = g_dir + "/b" + std::to_string(g_serial++);
  std::string c_path = stem + ".c", so_path = stem + ".so";
  std::string all;
  size_t line = 1;
  for (Pending &k : g_batch) {
    if (k.same_as >= 0) continue;
    k.first_line = line;
    all += k.src;
    line += static_cast<size_t>(std::count(k.src.begin(), k.src.end(), '\n'));
  }
  std::ofstream(c_path) << all;
  std::string why = compile(c_path, so_path, kBatchSeconds);
  if (!why.empty()) {
    // Charge the failure to one kernel and confirm it alone: a diagnostic
    // names its line; a compiler that ran too long, or a diagnostic
    // without a line, is looked for kernel by kernel.
    std::vector<const Pending *> suspects;
    if (const Pending *k = culprit_of(why, c_path)) suspects.push_back(k);
    for (const Pending &k : g_batch)
      if (k.same_as < 0 && (suspects.empty() || &k != suspects[0])) suspects.push_back(&k);
    // If every unit compiles alone (the batch only took too long), each
    // is checked alone too, and the batch is done.
    std::vector<KernelFn> alone_fns(g_batch.size());
    std::vector<void *> handles;
    for (const Pending *k : suspects) {
      std::string one_c = stem + "-" + k->name + ".c", one_so = stem + "-" + k->name + ".so";
      std::ofstream(one_c) << k->src;
      std::string alone = compile(one_c, one_so);
      unlink(one_c.c_str());
      if (!alone.empty())
        fail_for(*k, "the emitted C does not compile cleanly:\n" + alone + "\n" + k->src);
      void *h = dlopen(one_so.c_str(), RTLD_NOW | RTLD_LOCAL);
      unlink(one_so.c_str());
      if (!h) fuzz::fail(std::string("dlopen: ") + dlerror());
      handles.push_back(h);
      alone_fns[static_cast<size_t>(k - g_batch.data())] =
          reinterpret_cast<KernelFn>(dlsym(h, k->name.c_str()));
    }
    if (why.find("was killed") != std::string::npos) {
      ++g_stats.slow_batches;
      for (size_t i = 0; i < g_batch.size(); ++i) {
        const Pending &k = g_batch[i];
        KernelFn fn = alone_fns[k.same_as >= 0 ? static_cast<size_t>(k.same_as) : i];
        if (!fn) fail_for(k, "the kernel's symbol is missing");
        check_kernel(k, fn);
      }
      for (void *h : handles)
        dlclose(h);
      unlink(c_path.c_str());
      return;
    }
    fail_for(g_batch.back(),
             "the batch of " + std::to_string(g_batch.size()) + " kernels (" + c_path +
                 ", kept) does not compile, though each kernel alone does:\n" + why);
  }
  void *so = dlopen(so_path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!so) fuzz::fail(std::string("dlopen: ") + dlerror());
  std::vector<KernelFn> fns;
  for (const Pending &k : g_batch) {
    KernelFn fn = k.same_as >= 0 ? fns[static_cast<size_t>(k.same_as)]
                                 : reinterpret_cast<KernelFn>(dlsym(so, k.name.c_str()));
    if (!fn) fail_for(k, "the kernel's symbol is missing");
    fns.push_back(fn);
    check_kernel(k, fn);
  }
  unlink(c_path.c_str());
  unlink(so_path.c_str());
  if (g_loaded.size() == kMaxLoaded) { // forget them all
    g_compiled.clear();
    for (void *h : g_loaded)
      dlclose(h);
    g_loaded.clear();
  }
  g_loaded.push_back(so);
  for (size_t i = 0; i < g_batch.size(); ++i)
    g_compiled.emplace(g_batch[i].key, fns[i]);
}

// libFuzzer's -artifact_prefix, and whether an argument is a file rather
// than a corpus directory (then libFuzzer runs each file once: reproduction).
void read_command_line(bool *reproducing) {
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string arg;
  bool first = true;
  *reproducing = false;
  while (std::getline(f, arg, '\0')) {
    if (first) {
      first = false;
      continue;
    }
    const std::string prefix = "-artifact_prefix=";
    if (arg.compare(0, prefix.size(), prefix) == 0) g_artifact_prefix = arg.substr(prefix.size());
    struct stat st;
    if (!arg.empty() && arg[0] != '-' && stat(arg.c_str(), &st) == 0 && S_ISREG(st.st_mode))
      *reproducing = true;
  }
}

} // namespace

void fuzz_setup() {
  const char *tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/sicm-fuzz-emit-XXXXXX";
  std::vector<char> buf(templ.begin(), templ.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) fuzz::fail("cannot make a temporary directory");
  g_dir = buf.data();
  bool reproducing;
  read_command_line(&reproducing);
  g_verbose = std::getenv("FUZZ_VERBOSE") != nullptr;
  if (reproducing) g_batch_size = 1;
  if (const char *n = std::getenv("FUZZ_EMIT_BATCH"); n && std::atoi(n) > 0)
    g_batch_size = static_cast<size_t>(std::atoi(n));
  // atexit runs these last first: the batch left at exit is checked, then
  // the statistics printed, then the directory removed.
  std::atexit([] { rmdir(g_dir.c_str()); });
  std::atexit(print_stats);
  std::atexit(flush);
  fuzz::limit_expression_nodes(kMaxExpressionNodes);
  for (int i = 0; i < kInputs; ++i)
    g_inputs.push_back(make_uninterned_symbol("x" + std::to_string(i)).symbol());
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size == 0) return 0;
  fuzz::Bytes in(data, size);
  // 0: emitted as built; 1: simplified first; 2: rewritten locally first
  // (codegen/local_rewrite.hpp, as kernels that keep their traced DAG are),
  // and then compared with the interpreter's value of the DAG as built: the
  // rewrites must keep the function.
  unsigned form = in.below(3);
  bool simplified = form == 1, rewritten = form == 2;
  // The expression budget starts here, not after decoding: the nodes decode
  // builds would otherwise count against what the last input left, and a
  // limit error there is outside every handler.
  fuzz::begin_input();
  Trace t;
  t.inputs = g_inputs;
  t.outputs = decode(in);
  t.result_shape = Value::fixnum(0);
  if (t.outputs.empty()) return 0;
  // Expansions that could not fit kMaxExpressionNodes are a sicm error
  // before FLINT starts (emit-3, fixed); one that fits but multiplies the
  // kernel's size is computed as traced (kernel_output_form). The target's
  // budget: a kernel whose degree as a power of its leaves passes
  // kMaxSimplifiedDegree is emitted as built, not simplified. The
  // simplifier's exact arithmetic on such a kernel is right but slow, as
  // expanding is: (u^-5)^-1)^4)^-3)^-4)^-4 with u a sum of three terms is
  // u^-960, and its gcds took FLINT minutes within 10^5 terms.
  std::unordered_map<ExprId, double> degrees;
  if (simplified)
    for (ExprId o : t.outputs)
      if (degree(o, degrees) > kMaxSimplifiedDegree) simplified = false;
  if (g_verbose)
    for (ExprId o : t.outputs)
      std::fprintf(stderr, "output%s: %s\n", simplified ? " (to simplify)" : "",
                   expr_debug_string(o).c_str());
  if (simplified) {
    try {
      for (ExprId &o : t.outputs)
        o = kernel_output_form(o, simplify_expr(o)); // as trace_procedure does
    } catch (const Error &) {
      return 0; // a division by something that simplifies to zero
    }
  }
  ++g_stats.kernels;
  g_stats.simplified += simplified;
  Pending k;
  k.bytes.assign(data, data + size);
  k.outputs.assign(t.outputs.begin(), t.outputs.end());
  if (rewritten) t.outputs = rewrite_locally(t.outputs);
  k.src = emit_kernel_unit(t, kName, "fuzz");
  // A guard on the target's budget: units over kMaxUnitBytes are not
  // compiled, but counted at exit. Since emit-3 was fixed (an expanded
  // power of a sum made a megabyte of C that gcc -O2 took minutes on)
  // there should be none.
  if (k.src.size() > kMaxUnitBytes) {
    ++g_stats.too_large;
    --g_stats.kernels;
    g_stats.simplified -= simplified;
    return 0;
  }
  k.key = unit_key(k.src);
  if (auto it = g_compiled.find(k.key); it != g_compiled.end()) {
    ++g_stats.reused;
    k.name = kName;
    check_kernel(k, it->second);
    return 0;
  }
  if (auto it = g_in_batch.find(k.key); it != g_in_batch.end()) {
    ++g_stats.reused;
    k.same_as = static_cast<long>(it->second);
  } else {
    // The unit under a name of its own in the batch: kName occurs only in
    // the prototype and the definition.
    k.name = kName + "_" + std::to_string(g_batch.size());
    for (size_t at = 0; (at = k.src.find(kName + "(", at)) != std::string::npos;
         at += k.name.size())
      k.src.replace(at, kName.size(), k.name);
    g_in_batch.emplace(k.key, g_batch.size());
  }
  g_batch.push_back(std::move(k));
  if (g_batch.size() >= g_batch_size) flush();
  return 0;
}
