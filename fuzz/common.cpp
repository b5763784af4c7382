// The fuzz targets' main() and shared helpers (see common.hpp).
#include "common.hpp"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_set>

#include "base/limits.hpp"
#include "base/number.hpp"
#include "base/value.hpp"
#include "cas/expr.hpp"
#include "eval/procedure.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
extern "C" int LLVMFuzzerRunDriver(int *argc, char ***argv,
                                   int (*callback)(const uint8_t *data, size_t size));

namespace {

// The stack reserved for evaluation, and the part kept free below the guard
// for primitives. compiler/driver/main.cpp reserves 256 MiB; here it is 60 MiB,
// because AddressSanitizer declines to clear its records of a stack larger
// than 64 MiB when an exception unwinds it, and then reports false
// stack-buffer-overflows (google/sanitizers issue 189). So deep recursion
// stops earlier here than in sicm (at about a fifth of the depth, less the
// sanitizer's larger frames); the error it gives is the same.
constexpr size_t kStackBytes = size_t(60) << 20;
constexpr size_t kStackGuardMargin = size_t(16) << 20;

char *g_stack_base;

struct Args {
  int argc;
  char **argv;
  int status;
};

// libFuzzer's -timeout is a SIGALRM whose handler acts only on the thread
// that runs the inputs; the signal goes to any thread that does not block
// it. So every thread blocks it (main() before the collector starts its
// threads; libFuzzer's own thread inherits the mask) except this one, which
// unblocks it once the inputs start.
void set_alarm_blocked(bool blocked) {
  sigset_t alarm;
  sigemptyset(&alarm);
  sigaddset(&alarm, SIGALRM);
  pthread_sigmask(blocked ? SIG_BLOCK : SIG_UNBLOCK, &alarm, nullptr);
}

int run_one(const uint8_t *data, size_t size) {
  static bool unblocked = false;
  if (!unblocked) {
    set_alarm_blocked(false);
    unblocked = true;
  }
  return LLVMFuzzerTestOneInput(data, size);
}

void *fuzz_thread(void *p) {
  Args *a = static_cast<Args *>(p);
  char base;
  g_stack_base = &base;
  fuzz::reset_stack_limit();
  fuzz_setup();
  a->status = LLVMFuzzerRunDriver(&a->argc, &a->argv, run_one);
  return nullptr;
}

} // namespace

// LeakSanitizer is off: symbols, and the std::strings inside them, live in
// memory of the garbage collector, which it does not scan, so every symbol's
// name would be reported as leaked. (Memory the program really loses is the
// collector's business, not the sanitizer's.)
extern "C" const char *__asan_default_options() {
  return "detect_leaks=0";
}

int main(int argc, char **argv) {
  set_alarm_blocked(true);
  GC_INIT();
  Args args{argc, argv, 0};
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, kStackBytes);
  pthread_t thread;
  if (pthread_create(&thread, &attr, fuzz_thread, &args) != 0) {
    std::fprintf(stderr, "fuzz: cannot start the fuzzing thread\n");
    return 1;
  }
  pthread_join(thread, nullptr);
  return args.status;
}

namespace fuzz {

void limit_expression_nodes(uint64_t nodes) {
  sicm::Limits limits;
  limits.max_expression_nodes = nodes;
  limits.max_steps = sicm::kUnlimited;
  limits.max_memory = sicm::kUnlimited; // libFuzzer's -rss_limit_mb watches memory
  sicm::set_expression_node_counter(sicm::expr_count);
  sicm::set_limits(limits, false);
}

void begin_input() {
  sicm::begin_evaluation(sicm::SrcLoc{});
}

void reset_stack_limit() {
  sicm::set_stack_limit(g_stack_base, kStackBytes - kStackGuardMargin);
}

void fail(const std::string &what) {
  std::fprintf(stderr, "\n==== fuzz property violated ====\n%s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

uint64_t Rng::next() {
  uint64_t z = (s_ += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double Rng::uniform(double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(next() >> 11) * 0x1p-53);
}

uint64_t hash_bytes(const uint8_t *data, size_t size) {
  uint64_t h = 1469598103934665603ULL; // FNV-1a
  for (size_t i = 0; i < size; ++i)
    h = (h ^ data[i]) * 1099511628211ULL;
  return h;
}

using namespace sicm;

namespace {

using C = std::complex<double>;
constexpr double kU = DBL_EPSILON / 2; // unit roundoff
constexpr double kEta = 0x1p-1074;     // the smallest subnormal, a bound on underflow's error
const C kNaN(NAN, NAN);

bool finite(C z) {
  return std::isfinite(z.real()) && std::isfinite(z.imag());
}

// f(a) with derivative df at a.
Approx unary(C v, C df, const Approx &a) {
  return {v, std::abs(df) * a.e + 2 * kU * std::abs(v)};
}

// z^k by repeated squaring, k >= 0.
C ipow(C z, uint64_t k) {
  C r = 1;
  for (; k; k >>= 1, z *= z)
    if (k & 1) r *= z;
  return r;
}

C power(C b, int64_t k) {
  if (k >= 0) return ipow(b, static_cast<uint64_t>(k));
  return C(1) / ipow(b, 0 - static_cast<uint64_t>(k));
}

double number_error(double v) {
  return v == std::trunc(v) && std::fabs(v) < 0x1p53 ? 0 : kU * std::fabs(v);
}

} // namespace

Approx NumEval::eval(ExprId id) {
  Approx r = node(id);
  if (!finite(r.v) || !std::isfinite(r.e)) finite_ = false;
  return r;
}

Approx NumEval::node(ExprId id) {
  auto hit = memo_.find(id);
  if (hit != memo_.end()) return hit->second;
  Approx r;
  const ExprNode n = expr_node(id);
  switch (n.kind) {
  case ExprKind::Rational: {
    double v = to_double(expr_number_value(id));
    r = {v, number_error(v)};
    break;
  }
  case ExprKind::Flonum: r = {n.d, number_error(n.d)}; break; // rounded by the simplifier, perhaps
  case ExprKind::Symbol: {
    r = {kNaN, NAN};
    for (size_t i = 0; i < symbols_.size(); ++i)
      if (symbols_[i] == n.sym) r = {point_[i], 0};
    break;
  }
  case ExprKind::Call: r = {kNaN, NAN}; break;
  case ExprKind::Apply: {
    std::vector<ExprId> ids = expr_arg_vector(id);
    std::vector<Approx> a;
    for (ExprId k : ids)
      a.push_back(eval(k));
    C x = a[0].v;
    // The singular places of the operators: a denominator, the base of a
    // negative or fractional power, the argument of sqrt and log.
    auto near_singular = [](const Approx &t) { return t.e > 0.01 * std::abs(t.v); };
    int64_t k0 = 0;
    bool singular_arg =
        (n.op == Op::Div && near_singular(a.back())) ||
        ((n.op == Op::Sqrt || n.op == Op::Log) && near_singular(a[0])) ||
        (n.op == Op::Expt && !(expr_get_int64(ids[1], &k0) && k0 >= 0) && near_singular(a[0]));
    if (singular_arg) degenerate_ = true;
    // The argument's real interval [v - e, v + e] against the domain's
    // edge: 0 for sqrt, log and fractional powers, -1 and 1 for asin, acos.
    auto crosses = [](const Approx &t, double edge) {
      return t.v.imag() == 0 && t.v.real() - t.e <= edge && edge <= t.v.real() + t.e;
    };
    bool at_edge =
        ((n.op == Op::Sqrt || n.op == Op::Log) && crosses(a[0], 0)) ||
        (n.op == Op::Expt && !expr_get_int64(ids[1], &k0) && crosses(a[0], 0)) ||
        ((n.op == Op::Asin || n.op == Op::Acos) && (crosses(a[0], -1) || crosses(a[0], 1)));
    switch (n.op) {
    case Op::Add: {
      C s = 0;
      double e = 0, mag = 0;
      for (const Approx &t : a) {
        s += t.v;
        e += t.e;
        mag += std::abs(s);
      }
      r = {s, e + kU * mag};
      break;
    }
    case Op::Mul: {
      // Factor by factor, keeping the product of the errors: |pq - p'q'| <=
      // |p| e_q + e_p |q| + e_p e_q. The first-order sum alone claims an
      // exact 0 for the square of a factor known only to be near 0 (a
      // kernel's 1/cosh^6 overflowed to 0 where the interpreter's was
      // 5e-309, and the root and square of it differed by 2e-307).
      C p = a[0].v;
      double e = a[0].e;
      for (size_t i = 1; i < a.size(); ++i) {
        e = std::abs(p) * a[i].e + e * std::abs(a[i].v) + e * a[i].e;
        p *= a[i].v;
      }
      r = {p, e + a.size() * 2 * kU * std::abs(p)};
      break;
    }
    case Op::Sub: { // never built (I4)
      C s = a.size() == 1 ? -x : x;
      double e = a[0].e;
      for (size_t i = 1; i < a.size(); ++i) {
        s -= a[i].v;
        e += a[i].e + kU * std::abs(s);
      }
      r = {s, e};
      break;
    }
    case Op::Div: {
      if (a.size() == 1) {
        C q = C(1) / x;
        r = {q, a[0].e / std::norm(x) + 2 * kU * std::abs(q)};
      } else {
        C q = x / a[1].v;
        r = {q, a[0].e / std::abs(a[1].v) + std::abs(q / a[1].v) * a[1].e + 2 * kU * std::abs(q)};
      }
      break;
    }
    case Op::Expt: {
      int64_t k;
      // An integer power by repeated squaring, whatever its size: complex
      // pow (exp(k log x)) gives a negative real base an imaginary part of
      // about k pi u |v| (2e30 i for (-2.35)^119), and tan of that is i, a
      // value whose derivative 1 + tan^2 hides the argument's error.
      if (expr_get_int64(ids[1], &k)) {
        C v = power(x, k);
        // The largest derivative on the argument's interval (mean value
        // theorem), not the one at x: for k > 1 near 0 that is 0; for k < 0
        // it is at the end nearest 0, and unbounded when the interval holds
        // 0 (x = 7e7 known to 4e25, to the -4th, claimed 7e-14).
        double m = std::abs(x), e = a[0].e;
        C d = k == 0  ? C(0)
              : k > 1 ? static_cast<double>(k) * power(m + e, k - 1)
              : k < 0 ? (e >= m ? C(INFINITY) : static_cast<double>(-k) * power(m - e, k - 1))
                      : C(1);
        // Rounding: each squaring doubles the relative error it is given,
        // so x^k by squaring is off by about |k| units (x^72: 41 ulps, where
        // 2 log2 k claimed 14 and tan of it missed a pole).
        double steps = 2 * (1 + std::log2(1 + std::fabs(static_cast<double>(k)))) +
                       std::fabs(static_cast<double>(k));
        r = {v, std::abs(d) * a[0].e + steps * kU * std::abs(v)};
      } else {
        C c = a[1].v, v = std::pow(x, c);
        C db = c * std::pow(x, c - 1.0), dc = std::log(x) * v;
        r = {v, std::abs(db) * a[0].e + std::abs(dc) * a[1].e + 4 * kU * std::abs(v)};
      }
      break;
    }
    case Op::Sqrt: {
      C s = std::sqrt(x);
      if (std::find(negative_.begin(), negative_.end(), id) != negative_.end()) s = -s;
      // Near a zero argument the first-order bound e/(2|s|) grows without
      // limit (and is inf/NaN at 0), but a root moves at most sqrt(e) when
      // its argument moves by e (|sqrt a - sqrt b| <= sqrt|a - b| on one
      // branch): (sqrt (sqrt (expt (- x x') 4))) with x' = x rounded is a
      // few ulps of x, not infinitely uncertain (simplify-7).
      double e = a[0].e == 0 ? 0 : std::min(0.5 * a[0].e / std::abs(s), std::sqrt(a[0].e));
      r = {s, e + 2 * kU * std::abs(s)};
      break;
    }
    case Op::Exp: {
      // Not first order: |exp(p + d) - exp(p)| <= |exp(p)| (exp|d| - 1).
      // With the derivative at the computed p, an exponent that cancelled
      // to -1000 (an expanded 16th power, 1e3 off) claimed an exact 0.
      C v = std::exp(x);
      r = {v, std::abs(v) * std::expm1(a[0].e) + 2 * kU * std::abs(v)};
      break;
    }
    case Op::Log: r = unary(std::log(x), C(1) / x, a[0]); break;
    // |sin''| <= 1 on the reals: the second-order term keeps the bound
    // honest where the argument's error is large (sin of x^72 = 5e14,
    // known to 0.8), which the derivative at the computed point is not.
    case Op::Sin:
      r = unary(std::sin(x), std::cos(x), a[0]);
      r.e += 0.5 * a[0].e * a[0].e;
      break;
    case Op::Cos:
      r = unary(std::cos(x), std::sin(x), a[0]);
      r.e += 0.5 * a[0].e * a[0].e;
      break;
    case Op::Tan: {
      C t = std::tan(x);
      r = unary(t, 1.0 + t * t, a[0]);
      // Not first order either: tan of an argument known to e lies between
      // the tangents of x - e and x + e, unless a pole lies between them,
      // where it may be anything (tan of tan of tan of x0^5, the argument
      // 1e8 off, claimed 1e191 for values 1e107 and 1e246 apart).
      if (x.imag() == 0 && a[0].e > 0) {
        double lo = x.real() - a[0].e, hi = x.real() + a[0].e;
        if (std::floor(lo / M_PI - 0.5) != std::floor(hi / M_PI - 0.5)) {
          r.e = INFINITY;
        } else {
          for (double end : {lo, hi})
            r.e = std::max(r.e, std::fabs(std::tan(end) - t.real()) + 2 * kU * std::abs(t));
        }
      }
      break;
    }
    case Op::Asin: r = unary(std::asin(x), C(1) / std::sqrt(1.0 - x * x), a[0]); break;
    case Op::Acos: r = unary(std::acos(x), C(1) / std::sqrt(1.0 - x * x), a[0]); break;
    case Op::Atan:
      if (a.size() == 1) {
        r = unary(std::atan(x), C(1) / (1.0 + x * x), a[0]);
      } else if (x.imag() == 0 && a[1].v.imag() == 0) {
        double y = x.real(), xx = a[1].v.real(), v = std::atan2(y, xx);
        double ey = a[0].e, ex = a[1].e;
        r = {v, (std::fabs(xx) * ey + std::fabs(y) * ex) / (xx * xx + y * y)};
        // Not only first order: near the origin atan2 turns fast, and a y
        // known to 0.6 at 0.5 over x = 0.04 may lie on either side of 0
        // (emit-6: the first-order bound there was 0.1, the two sides
        // differ by 2.7). The angle of every point of the box of (x, y)
        // and its errors lies between those of its corners, unless the box
        // holds the origin or crosses the branch cut (x < 0, either sign of
        // y: -pi or pi), where the value is known to 2 pi only.
        if (std::fabs(y) <= ey && xx <= ex) {
          r.e = 2 * M_PI;
        } else {
          for (double cy : {y - ey, y + ey})
            for (double cx : {xx - ex, xx + ex})
              r.e = std::max(r.e, std::fabs(std::atan2(cy, cx) - v));
        }
        r.e += 2 * kU * std::fabs(v);
      } else {
        r = {kNaN, NAN}; // atan2 of complex values: not needed
      }
      break;
    case Op::Sinh: r = unary(std::sinh(x), std::cosh(x), a[0]); break;
    case Op::Cosh: r = unary(std::cosh(x), std::sinh(x), a[0]); break;
    case Op::Abs: r = {std::abs(x), a[0].e + kU * std::abs(x)}; break;
    }
    // Underflow: below the normal range a result's error is absolute, up to
    // half the smallest subnormal (fl(x op y) = (x op y)(1 + d) + h, |h| <=
    // 2^-1075). A factor that underflowed to 0 then carries a bound that
    // the other factors scale, instead of claiming an exact 0.
    r.e += kEta;
    // A value below the smallest normal double has absolute accuracy only,
    // and another correct order of evaluation may not reach it at all:
    // ((x^192)^-4) is 1e-316 as pow(y, -4) and 0 as C's 1.0 / (y * y * y
    // * y), whose y^4 overflowed. A root then makes either a normal number
    // (1e-158 against 0). Such a value is known to DBL_MIN.
    if (std::abs(r.v) < DBL_MIN) r.e = std::max(r.e, DBL_MIN);
    r.edge = at_edge || std::any_of(a.begin(), a.end(), [](const Approx &t) { return t.edge; });
    break;
  }
  }
  if (!finite(r.v) || !std::isfinite(r.e)) finite_ = false;
  memo_.emplace(id, r);
  return r;
}

std::vector<ExprId> sqrt_nodes(ExprId root) {
  std::vector<ExprId> out, stack{root};
  std::unordered_set<ExprId> seen;
  while (!stack.empty()) {
    ExprId id = stack.back();
    stack.pop_back();
    if (!seen.insert(id).second || expr_kind(id) != ExprKind::Apply) continue;
    if (expr_is_apply(id, Op::Sqrt)) out.push_back(id);
    for (ExprId k : expr_arg_vector(id))
      stack.push_back(k);
  }
  std::sort(out.begin(), out.end());
  return out;
}

} // namespace fuzz
