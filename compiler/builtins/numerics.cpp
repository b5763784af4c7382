// Numerical primitives: definite-integral, minimize, nelder-mead,
// multidimensional-minimize, find-root, bisect, state-advancer, evolve,
// crossings, eigenvalues.
//
// The runtime's numerical modules (runtime/include/sicm/*.h) work on C
// functions of doubles. Here those functions are callbacks that apply a
// Scheme procedure: the double arguments become flonums (and a flat state
// vector becomes a structure of the initial state's shape), the procedure's
// result is converted back to doubles. Everything the runtime sees is a
// (C function, params) pair built in one place per kind of problem
// (ScalarCallback, VectorCallback, OdeCallback below). When the procedure is
// a native kernel (compile-procedure, codegen/kernel.hpp) of the right
// shape, the same callbacks run the kernel on the doubles directly, without
// making Scheme values. Which procedures run compiled, and how they are
// compiled, builtins/compiled_procedures.hpp decides: system derivatives as
// kernels, or by sicm build's partial evaluator when they test the state
// (pe/for_run.cpp), and bisect's function, when one interpreted call proves
// expensive, by the partial evaluator too, loops and tests included.
//
// Errors. A Scheme error (or a continuation escape) inside a callback must
// not unwind through the runtime's C frames: the callback catches it, tells
// the runtime to stop (a non-zero status, or NaN for functions that return a
// value) and every later call returns at once; when the runtime has returned
// and released its memory, the exception is rethrown. Failures of the
// runtime itself (a step size that underflows, no convergence, a tolerance
// that cannot be met) become run-time errors at the primitive's call site,
// with the runtime's message, which names the time and the state or the
// point where it failed. While a primitive runs, the runtime's error hook
// records messages instead of printing them.
#include "builtins/numerics.hpp"
#include "builtins/builtins.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "algebra/generic.hpp"
#include "algebra/structure.hpp"
#include "base/limits.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/compiled_procedures.hpp"
#include "builtins/crossing_events.hpp"
#include "builtins/integration_errors.hpp"
#include "builtins/integration_sites.hpp"
#include "builtins/numeric_arguments.hpp"
#include "builtins/numerics_defaults.hpp"
#include "builtins/progress_bar.hpp"
#include "codegen/jit.hpp"
#include "codegen/kernel.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"
#include "sicm/runtime.h"

namespace sicm {

namespace {

// ---- the runtime's error hook -------------------------------------------------

std::string g_runtime_message; // the last failure reported while a scope is active

void record_runtime_error(const char *reason, int) {
  g_runtime_message = reason;
}

// While alive, runtime failures are recorded in g_runtime_message instead of
// being printed on stderr.
class RuntimeErrorScope {
public:
  RuntimeErrorScope() : previous_(sicm_set_error_handler(record_runtime_error)) {
    g_runtime_message.clear();
  }
  ~RuntimeErrorScope() { sicm_set_error_handler(previous_); }
  RuntimeErrorScope(const RuntimeErrorScope &) = delete;
  RuntimeErrorScope &operator=(const RuntimeErrorScope &) = delete;

private:
  sicm_error_handler_t *previous_;
};

// The runtime's message without its "sicm_function_name: " prefix.
std::string reason_of(const std::string &message) {
  if (message.rfind("sicm_", 0) == 0) {
    size_t colon = message.find(": ");
    if (colon != std::string::npos) return message.substr(colon + 2);
  }
  return message.empty() ? std::string("the computation failed") : message;
}

[[noreturn]] void numeric_error(SrcLoc loc, const char *who, const std::string &what) {
  runtime_error(loc, std::string(who) + ": " + what);
}

// ---- arguments ------------------------------------------------------------------

bool is_missing(Value *a, int n, int i) {
  return i >= n || a[i].is(Tag::Default);
}

// The arguments' values, read after check_numeric_arguments
// (builtins/numeric_arguments.hpp) has checked them against the
// primitive's signature, as sicm build checks them.
double real_at(Value *a, int i) {
  return to_double(a[i]);
}

// An optional real: `fallback` when the argument is missing.
double optional_real(Value *a, int n, int i, double fallback) {
  return is_missing(a, n, i) ? fallback : to_double(a[i]);
}

std::string number_text(double x) {
  return number_to_string(Value::flonum(x));
}

// A native kernel made by compile-procedure, or null.
const Kernel *kernel_of(Value f) {
  if (!f.is(Tag::Opaque) || std::strcmp(f.as<Opaque>()->kind->name, "kernel") != 0) return nullptr;
  return static_cast<const Kernel *>(f.as<Opaque>()->obj);
}

// f as a kernel from one real to one real, or null.
const Kernel *scalar_kernel_of(Value f) {
  const Kernel *k = kernel_of(f);
  if (!k || list_length(k->arg_shapes) != 1 || is_structure(car(k->arg_shapes)) || k->nin != 1 ||
      k->nout != 1)
    return nullptr;
  return k;
}

// ---- callbacks ----------------------------------------------------------------

// What every callback shares: where the primitive was called (for errors
// raised inside the callback, since evaluating the procedure moves the
// evaluator's notion of the current call) and the first exception raised.
struct Callback {
  SrcLoc loc;
  const char *who;
  std::exception_ptr error;

  Callback(SrcLoc l, const char *w) : loc(l), who(w) {}
  // After the runtime has returned: raise what a callback caught.
  void rethrow_if_failed() {
    if (error) std::rethrow_exception(error);
  }
};

// A real function of one real variable (integrands, functions to minimize or
// to find a root of).
struct ScalarCallback : Callback {
  Value f;
  const Kernel *kernel; // f itself when it is a kernel of one real
  // compile_expensive: f compiled by the partial evaluator once one
  // interpreted call has taken kCompileAfterSteps steps (compiled: the result).
  bool compile_expensive = false, compile_tried = false;
  CompiledFn compiled = nullptr;
  bool nonfinite = false; // f returned a NaN or an infinity, first at bad_x
  double bad_x = 0, bad_value = 0;
  ScalarCallback(SrcLoc l, const char *w, Value fn)
      : Callback(l, w), f(fn), kernel(scalar_kernel_of(fn)) {}
  // The reason for a failure of the runtime: a non-finite value in Scheme's
  // words if there was one, else the runtime's message.
  std::string reason() const {
    if (nonfinite)
      return "the function is " + number_text(bad_value) + " at " + number_text(bad_x) +
             ", not a finite number";
    return reason_of(g_runtime_message);
  }
};

// The procedure's value as a double; a non-number is an error.
double real_result(const Callback &cb, Value r, const std::string &at) {
  // In sicm build (computing while compiling) a value known only at run
  // time is the compiler's "cannot compile" error (see wrong_type).
  if (RunTimeValueTest run_time = run_time_value_test(); run_time && run_time(r))
    wrong_type(r, 1, cb.who);
  if (!is_number(r))
    runtime_error(cb.loc, std::string(cb.who) + ": the function returned " + write_string(r) +
                              " at " + at + ", which is not a real number");
  return to_double(r);
}

// An interpreted call of bisect's function that takes more evaluator steps
// than this (some milliseconds) makes it worth compiling: the book's
// which-way? iterates a map thousands of times per call, and bisect calls
// it some fifty times; a cheap function is not worth the C compiler's
// tenth of a second.
constexpr uint64_t kCompileAfterSteps = 50000;

// Compile cb's procedure by the partial evaluator (compile_for_run), once.
void compile_expensive(ScalarCallback &cb) {
  cb.compile_tried = true;
  cb.compiled = compile_expensive_function(cb.f, cb.who);
}

double call_scalar(double x, void *data) {
  auto *cb = static_cast<ScalarCallback *>(data);
  if (cb->error) return NAN;
  try {
    double v;
    if (cb->kernel) {
      kernel_call(cb->kernel, &x, &v);
    } else if (!cb->compiled || cb->compiled(&x, &v, interrupt_flag()) != 0) {
      uint64_t steps = steps_taken();
      Value arg = Value::flonum(x);
      Value r = apply_procedure(cb->f, &arg, 1);
      v = real_result(*cb, r, number_text(x));
      if (cb->compile_expensive && !cb->compile_tried && steps_taken() - steps > kCompileAfterSteps)
        compile_expensive(*cb);
    }
    if (!std::isfinite(v) && !cb->nonfinite) {
      cb->nonfinite = true;
      cb->bad_x = x;
      cb->bad_value = v;
    }
    return v;
  } catch (...) {
    cb->error = std::current_exception();
    return NAN;
  }
}

double call_scalar_abs(double x, void *data) {
  return std::fabs(call_scalar(x, data));
}

// A real function of n real variables, which the procedure receives as a
// vector (nelder-mead) or a list (multidimensional-minimize).
struct VectorCallback : Callback {
  Value f;
  size_t n;
  bool as_list;
  VectorCallback(SrcLoc l, const char *w, Value fn, size_t dim, bool list)
      : Callback(l, w), f(fn), n(dim), as_list(list) {}
};

Value point_value(const double *x, size_t n, bool as_list) {
  if (as_list) {
    Value v = Value::nil();
    for (size_t i = n; i-- > 0;)
      v = cons(Value::flonum(x[i]), v);
    return v;
  }
  Value v = make_vector(n, Value::unspecified());
  Value *items = v.vector()->items;
  for (size_t i = 0; i < n; ++i)
    items[i] = Value::flonum(x[i]);
  return v;
}

double call_vector(const double *x, void *data) {
  auto *cb = static_cast<VectorCallback *>(data);
  if (cb->error) return NAN;
  try {
    Value arg = point_value(x, cb->n, cb->as_list);
    Value r = apply_procedure(cb->f, &arg, 1);
    if (!is_number(r)) {
      Value point = point_value(x, cb->n, cb->as_list);
      return real_result(*cb, r, write_string(point));
    }
    return to_double(r);
  } catch (...) {
    cb->error = std::current_exception();
    return NAN;
  }
}

// ---- states: structures flattened to arrays of doubles ---------------------

// The shape of a state: up and down structures and vectors, nested, with
// real numbers at the leaves. The shape is recorded once, as a preorder code
// (0 for a leaf, (length << 2) | kind for a container), so that converting a
// flat array to a state and a state to an array walk the code, not the
// initial state, and allocate nothing but the new state's own structures.
class StateShape {
public:
  // Record the shape of v; false if some leaf is not a real number.
  bool describe(Value v) {
    code_.clear();
    dim_ = 0;
    return add(v);
  }
  size_t dim() const { return dim_; }
  // The state's first component is a number: by convention, the time.
  bool time_first() const { return code_.size() > 1 && code_[0] != kLeaf && code_[1] == kLeaf; }

  // A fresh state of this shape whose leaves are the flonums y[0 .. dim).
  Value build(const double *y) const {
    size_t pc = 0;
    return build_at(pc, y);
  }
  // Store v's leaves in out[0 .. dim) if v has this shape (up and down are
  // not told apart, and an exact 0 stands for a zero substructure); false if
  // it has not, or if a leaf is not a real number.
  bool read(Value v, double *out) const {
    size_t pc = 0;
    return read_at(v, pc, out);
  }

private:
  static constexpr uint32_t kLeaf = 0, kUp = 1, kDown = 2, kVector = 3;

  bool add(Value v) {
    if (is_number(v)) {
      code_.push_back(kLeaf);
      ++dim_;
      return true;
    }
    const Value *items;
    size_t len;
    uint32_t kind;
    if (is_structure(v)) {
      items = as_structure(v)->items;
      len = as_structure(v)->len;
      kind = as_structure(v)->up ? kUp : kDown;
    } else if (v.is(Tag::Vector)) {
      items = v.vector()->items;
      len = v.vector()->len;
      kind = kVector;
    } else {
      return false;
    }
    code_.push_back(static_cast<uint32_t>(len << 2) | kind);
    for (size_t i = 0; i < len; ++i)
      if (!add(items[i])) return false;
    return true;
  }

  Value build_at(size_t &pc, const double *&y) const {
    uint32_t c = code_[pc++];
    if (c == kLeaf) return Value::flonum(*y++);
    size_t len = c >> 2;
    Value v = (c & 3) == kVector ? make_vector(len, Value::unspecified())
                                 : make_structure((c & 3) == kUp, len);
    Value *items = v.is(Tag::Vector) ? v.vector()->items : as_structure(v)->items;
    for (size_t i = 0; i < len; ++i)
      items[i] = build_at(pc, y);
    return v;
  }

  // Skip the subtree at pc, writing zeros for its leaves.
  void zero_at(size_t &pc, double *&out) const {
    uint32_t c = code_[pc++];
    if (c == kLeaf) {
      *out++ = 0.0;
      return;
    }
    for (size_t i = 0, len = c >> 2; i < len; ++i)
      zero_at(pc, out);
  }

  bool read_at(Value v, size_t &pc, double *&out) const {
    uint32_t c = code_[pc];
    if (c == kLeaf) {
      ++pc;
      if (!is_number(v)) return false;
      *out++ = to_double(v);
      return true;
    }
    if (is_exact_zero(v)) {
      zero_at(pc, out);
      return true;
    }
    ++pc;
    const Value *items;
    size_t len;
    if (is_structure(v)) {
      items = as_structure(v)->items;
      len = as_structure(v)->len;
    } else if (v.is(Tag::Vector)) {
      items = v.vector()->items;
      len = v.vector()->len;
    } else {
      return false;
    }
    if (len != (c >> 2)) return false;
    for (size_t i = 0; i < len; ++i)
      if (!read_at(items[i], pc, out)) return false;
    return true;
  }

  std::vector<uint32_t> code_;
  size_t dim_ = 0;
};

// The system derivative of an ODE: a procedure from a state to a state of
// the same shape (its derivative).
struct OdeCallback : Callback {
  Value sysder;
  const StateShape *shape;
  const Kernel *kernel = nullptr;   // sysder itself when it is a kernel on the state's shape
  CompiledFn compiled = nullptr;    // else sysder compiled by the partial evaluator, if it was
  const Kernel *jacobian = nullptr; // (D sysder) on the state's shape, for implicit methods
  std::vector<double> jacobian_out;
  // Every derivative computed so far had exactly 1 as its time component:
  // then the time component of the solution is exactly the integrator's
  // time, and results carry that instead of the sum of the steps.
  bool time_rate_one = true;
  OdeCallback(SrcLoc l, const char *w, Value f, const StateShape *s)
      : Callback(l, w), sysder(f), shape(s) {}
};

int call_sysder(double, const double *y, double *dydt, void *data) {
  auto *cb = static_cast<OdeCallback *>(data);
  if (cb->error) return 1;
  if (cb->kernel) {
    kernel_call(cb->kernel, y, dydt);
    if (cb->shape->time_first() && dydt[0] != 1.0) cb->time_rate_one = false;
    return 0;
  }
  // A compiled derivative gives up (1) where the interpreter must compute:
  // then it does, for this state.
  if (cb->compiled && cb->compiled(y, dydt, interrupt_flag()) == 0) {
    if (cb->shape->time_first() && dydt[0] != 1.0) cb->time_rate_one = false;
    return 0;
  }
  try {
    Value state = cb->shape->build(y);
    Value d = apply_procedure(cb->sysder, &state, 1);
    if (!cb->shape->read(d, dydt)) derivative_shape_error(cb->loc, cb->who, d, cb->shape->build(y));
    if (cb->shape->time_first() && dydt[0] != 1.0) cb->time_rate_one = false;
    return 0;
  } catch (...) {
    cb->error = std::current_exception();
    return 1;
  }
}

// The analytic Jacobian of a compiled system derivative: the kernel of
// (D sysder) gives d f_i / d y_j at out[j * dim + i] (a down structure over
// the state's components of up structures of the derivative's), the runtime
// wants it row-major. The rhs does not depend on the integrator's time
// (time is a state component), so df/dt is 0.
int call_jacobian(double, const double *y, double *dfdy, double *dfdt, void *data) {
  auto *cb = static_cast<OdeCallback *>(data);
  size_t n = cb->shape->dim();
  cb->jacobian_out.resize(n * n);
  kernel_call(cb->jacobian, y, cb->jacobian_out.data());
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j)
      dfdy[i * n + j] = cb->jacobian_out[j * n + i];
    dfdt[i] = 0.0;
  }
  return 0;
}

// Frees an integrator, first adding what it cost to --stats (sicm/stats.h):
// its call site, primitive and tolerance, and the seconds counted in *seconds.
struct OdeDeleter {
  SrcLoc loc;
  const char *who = "";
  double tolerance = 0;
  const double *seconds = nullptr;
  void operator()(sicm_ode *o) const {
    if (sicm_stats_enabled() && seconds) {
      sicm_stats_add(loc_text(loc).c_str(), who, sicm_ode_name(o), tolerance, sicm_ode_get_stats(o),
                     *seconds);
      sicm_stats_add_events(loc_text(loc).c_str(), who, sicm_ode_name(o), tolerance,
                            sicm_ode_get_event_stats(o));
    }
    sicm_ode_free(o);
  }
};
using OdePtr = std::unique_ptr<sicm_ode, OdeDeleter>;

// ---- integrators by name ------------------------------------------------------

Symbol *g_method_variable = nullptr; // *ode-integration-method*

// Fails, saying so, if name is an integrator sicm does not provide.
void check_provided(const std::string &name, const char *who) {
  std::string why = integrator_not_provided(name);
  if (!why.empty()) runtime_error(current_call_loc(), std::string(who) + ": " + why);
}

// The integrator named by argument i, or by *ode-integration-method* when
// the argument is missing.
const sicm_ode_step_type *arg_integrator(Value *a, int n, int i, const char *who) {
  if (is_missing(a, n, i)) {
    Value m = g_method_variable->bound ? g_method_variable->global : Value::unspecified();
    const sicm_ode_step_type *T = is_symbol(m) ? integrator_named(symbol_name(m)) : nullptr;
    if (!T && is_symbol(m)) check_provided(symbol_name(m), who);
    if (!T)
      runtime_error(current_call_loc(), std::string(who) + ": *ode-integration-method* is " +
                                            write_string(m) + ", which names no integrator (" +
                                            integrator_list() + ")");
    return T;
  }
  return integrator_named(symbol_name(a[i])); // a name checked by check_numeric_arguments
}

// ---- events -------------------------------------------------------------------------

// The event procedure of crossings: a real function of the state, computed
// by the interpreter (flonums stay flonums), then, once it has been called
// often enough, by the function sicm build's partial evaluator makes of it
// (compiled_event), which computes as the interpreter does and as the
// built program's does: the same numbers either way. And the states at the
// crossings found.
struct EventCallback : Callback {
  Value event;
  const StateShape *shape;
  Value sample; // a state of that shape, for compiled_event
  CompiledFn compiled = nullptr;
  gcvec<Value> found;
  size_t most = 0; // stop after this many crossings (0: no limit)
  EventCallback(SrcLoc l, const char *w, Value e, const StateShape *s, Value state)
      : Callback(l, w), event(e), shape(s), sample(state) {
    compiled = compiled_event(event, sample, 0, who);
  }
};

double call_event(double, const double *y, void *data) {
  auto *cb = static_cast<EventCallback *>(data);
  if (cb->error) return NAN;
  double value;
  // A compiled event gives up (1) where the interpreter must compute.
  if (cb->compiled && cb->compiled(y, &value, interrupt_flag()) == 0) return value;
  try {
    Value state = cb->shape->build(y);
    Value g = apply_procedure(cb->event, &state, 1);
    if (!cb->compiled) cb->compiled = compiled_event(cb->event, cb->sample, 1, cb->who);
    if (!is_number(g) || !is_real(g))
      runtime_error(cb->loc, std::string(cb->who) + ": the event procedure returned " +
                                 write_string(g) + " for the state " + write_string(state) +
                                 ", which is not a real number");
    return to_double(g);
  } catch (...) {
    cb->error = std::current_exception();
    return NAN;
  }
}

int record_crossing(size_t, double, const double *y, void *data) {
  auto *cb = static_cast<EventCallback *>(data);
  cb->found.push_back(cb->shape->build(y));
  return cb->most && cb->found.size() >= cb->most; // non-zero: the integration stops here
}

// The runtime's direction of an event: 'up, 'down or 'both
// (check_numeric_arguments has checked the symbol).
int event_direction(Value v) {
  const std::string &name = symbol_name(v);
  return name == "up"     ? SICM_ODE_EVENT_UP
         : name == "down" ? SICM_ODE_EVENT_DOWN
                          : SICM_ODE_EVENT_BOTH;
}

// The events given to evolve or state-advancer (on-crossing and
// stop-on-crossing, builtins/crossing_events.hpp): each event's function
// computed as crossings' is (EventCallback), and at each crossing, in time
// order, the event's procedure called with the state there (as a monitor
// is called), or the integration stopped.
struct EvolveEvents : Callback {
  std::vector<std::unique_ptr<EventCallback>> functions; // their Values live in the call's a[]
  std::vector<const CrossingEvent *> events;
  std::vector<sicm_ode_event> table;
  const StateShape *shape;
  bool stopped = false; // an event stopped the integration
  EvolveEvents(SrcLoc l, const char *w, Value *a, int n, const StateShape *s, Value state)
      : Callback(l, w), shape(s) {
    for (int i = 0; i < n; ++i) {
      events.push_back(as_crossing_event(a[i]));
      functions.push_back(std::make_unique<EventCallback>(l, w, events.back()->event, s, state));
      table.push_back({call_event, functions.back().get(), crossing_direction(*events.back()), 0});
    }
  }
  void attach(sicm_ode *ode);
  // After the runtime has returned: raise what an event or a procedure raised.
  void rethrow_all() {
    for (auto &f : functions)
      f->rethrow_if_failed();
    rethrow_if_failed();
  }
};

int on_crossing(size_t i, double, const double *y, void *data) {
  auto *e = static_cast<EvolveEvents *>(data);
  if (e->error) return 1;
  if (e->events[i]->stops()) {
    e->stopped = true;
    return 1; // non-zero: the integration stops here
  }
  try {
    Value state = e->shape->build(y);
    apply_procedure(e->events[i]->action, &state, 1);
    return 0;
  } catch (...) {
    e->error = std::current_exception();
    return 1;
  }
}

void EvolveEvents::attach(sicm_ode *ode) {
  if (!table.empty() && sicm_ode_set_events(ode, table.data(), table.size(), on_crossing, this))
    numeric_error(loc, who, reason_of(g_runtime_message));
}

// ---- one integration problem ----------------------------------------------------

// A state, flattened, with its shape and the system derivative's callback.
struct OdeProblem {
  StateShape shape;
  std::vector<double> y;
  OdeCallback cb;
  double t0;                             // the integrator's starting time: the state's time, or 0
  std::vector<const char *> probe_texts; // the kernel's, for the integrator
  double seconds = 0;                    // spent integrating, for --stats

  // taylor: the integration will use the taylor method, so a derivative
  // compiled here is compiled with its Taylor coefficients.
  OdeProblem(SrcLoc loc, const char *who, Value sysder, Value state, int argpos, bool taylor)
      : cb(loc, who, sysder, &shape) {
    if (!shape.describe(state) || shape.dim() == 0) wrong_type(state, argpos, who);
    y.resize(shape.dim());
    shape.read(state, y.data());
    const Kernel *k = kernel_of(sysder);
    if (k && list_length(k->arg_shapes) == 1 && value_has_shape(state, car(k->arg_shapes)) &&
        k->nin == shape.dim() && k->nout == shape.dim())
      cb.kernel = k;
    else
      cb.kernel = auto_kernel(sysder, state, shape.dim(), taylor);
    if (!cb.kernel && !taylor) cb.compiled = auto_residual(sysder, state, who);
    t0 = shape.time_first() && std::isfinite(y[0]) ? y[0] : 0.0;
  }

  // max_steps: the most steps to one output time (the user's max-steps
  // argument), 0 for the runtime's default.
  OdePtr make_integrator(const sicm_ode_step_type *T, double eps, unsigned long max_steps) {
    OdePtr ode(sicm_ode_alloc(T, shape.dim(), call_sysder, &cb, eps, eps),
               OdeDeleter{cb.loc, cb.who, eps, &seconds});
    if (!ode) numeric_error(cb.loc, cb.who, reason_of(g_runtime_message));
    if (max_steps && sicm_ode_set_max_steps(ode.get(), max_steps))
      numeric_error(cb.loc, cb.who, reason_of(g_runtime_message));
    // What the compiled derivative divides by, to name a singularity where
    // the integration fails.
    if (cb.kernel && cb.kernel->singular_factors) {
      probe_texts.clear();
      for (const std::string &text : cb.kernel->singular_texts)
        probe_texts.push_back(text.c_str());
      sicm_ode_set_singularity_probe(ode.get(), cb.kernel->singular_factors,
                                     kernel_params(cb.kernel), probe_texts.size(),
                                     probe_texts.data());
    }
    if (T == sicm_ode_step_taylor || T == sicm_ode_step_taylor_extended) use_taylor(ode.get(), T);
    // Implicit methods solve with the Jacobian: from a kernel of (D sysder)
    // when the derivative itself compiled, else by finite differences.
    if ((T == sicm_ode_step_msbdf || T == sicm_ode_step_cvode_bdf) && cb.kernel) {
      cb.jacobian = jacobian_kernel(cb.sysder, shape.build(y.data()), shape.dim());
      if (cb.jacobian) sicm_ode_set_jacobian(ode.get(), call_jacobian);
    }
    return ode;
  }

  // The taylor method takes its coefficients from the compiled derivative,
  // compiled again with them if it was compiled without; errors at the
  // call site when there are none.
  void use_taylor(sicm_ode *ode, const sicm_ode_step_type *T) {
    if (cb.kernel && !cb.kernel->taylor) {
      const Kernel *k = auto_kernel(cb.sysder, shape.build(y.data()), shape.dim(), true);
      if (k) cb.kernel = k;
    }
    if (cb.kernel && cb.kernel->taylor) {
      if (T == sicm_ode_step_taylor_extended)
        sicm_ode_set_taylor_extended(ode, cb.kernel->taylor_extended, taylor_params(cb.kernel));
      else
        sicm_ode_set_taylor(ode, cb.kernel->taylor, taylor_params(cb.kernel));
      return;
    }
    const char *method = sicm_ode_step_type_name(T);
    if (!cb.kernel) // not one expression of the state, which the build says alike
      taylor_refused(cb.loc, cb.who, method,
                     jit_limit_reached() ? TaylorRefusal::KernelLimit
                                         : TaylorRefusal::NotOneExpression);
    taylor_refused(cb.loc, cb.who, method, TaylorRefusal::NoRecurrence,
                   cb.kernel->taylor_why_not.empty() ? "no Taylor coefficients"
                                                     : cb.kernel->taylor_why_not);
  }

  // For sicm bench: this integration, from the current state over [t0, t1].
  void record_site(const char *who, double t1, double eps, const sicm_ode_step_type *T) {
    if (!recording_integration_sites()) return;
    record_integration_site(IntegrationSite{
        // An interpreted kernel is recorded as none: sicm bench gives its
        // functions the numbers of p[] (kernel_params, codegen/kernel.hpp).
        loc_text(cb.loc), who, cb.kernel && !cb.kernel->interpreted ? cb.kernel->fn : nullptr,
        cb.kernel ? cb.kernel->taylor : nullptr, cb.kernel ? cb.kernel->taylor_extended : nullptr,
        cb.kernel ? cb.kernel->params : std::vector<double>(), y, shape.time_first(), t0, t1, eps,
        sicm_ode_step_type_name(T)});
  }

  // Advance the integrator to t1 (to an event's crossing, if one stops it
  // there); errors at the call site on failure.
  void evolve_to(sicm_ode *ode, double &t, double t1, EvolveEvents *events = nullptr) {
    const bool timed = sicm_stats_enabled(); // the clock only for --stats
    const double start = timed ? sicm_stats_clock() : 0;
    int status = sicm_ode_evolve(ode, &t, t1, y.data());
    if (timed) seconds += sicm_stats_clock() - start;
    cb.rethrow_if_failed();
    if (events) events->rethrow_all();
    if (status != SICM_SUCCESS) numeric_error(cb.loc, cb.who, sicm_ode_last_error(ode));
  }

  // The state at integrator time t: the current leaves, with the time
  // component exactly t when the time advances at rate 1.
  Value state_at(double t) {
    if (!shape.time_first() || !cb.time_rate_one) return shape.build(y.data());
    double saved = y[0];
    y[0] = t;
    Value s = shape.build(y.data());
    y[0] = saved;
    return s;
  }
};

// The flat system derivative: (sysder . params), applied once.
Value apply_sysder(Value *a, int n, const char *who) {
  if (!is_procedure(a[0])) wrong_type(a[0], 1, who); // as sicm build's sysder_of
  return apply_procedure(a[0], a + 1, n - 1);
}

Lambda g_advancer_lambda; // what the printer shows of the procedures made here
Lambda g_evolver_lambda;

Value make_named_procedure(NativeFn fn, Value sysder, Lambda *lambda) {
  Value p = make_native_procedure(fn, 0, sysder, Value::nil());
  static_cast<NativeProc *>(p.as<Opaque>()->obj)->print_as.lambda = lambda;
  return p;
}

// The optional max-steps argument at a[i] (check_numeric_arguments made it
// a count): the most steps to one output time; 0 for the runtime's default.
unsigned long optional_max_steps(Value *a, int n, int i) {
  return is_missing(a, n, i) ? 0 : static_cast<unsigned long>(a[i].i);
}

// ((state-advancer sysder . params) state dt [eps [integrator [max-steps]]]
// event ...): the state dt later, or at the crossing of an event that
// stops it.
Value advance_state(NativeProc *self, Value *a, int all) {
  static const char who[] = "state-advancer";
  const int n = arguments_before_events(a, all, 2, who);
  check_numeric_arguments(who, a, n, self);
  SrcLoc loc = current_call_loc();
  double dt = real_at(a, 1);
  double eps = optional_real(a, n, 2, kAdvancerTolerance);
  const sicm_ode_step_type *T = arg_integrator(a, n, 3, who);
  check_reachable_tolerance(loc, who, T, eps);
  const unsigned long max_steps = optional_max_steps(a, n, 4);
  OdeProblem p(loc, who, self->a, a[0], 1,
               T == sicm_ode_step_taylor || T == sicm_ode_step_taylor_extended ||
                   recording_integration_sites());
  double t = p.t0, t1 = p.t0 + dt;
  p.record_site(who, t1, eps, T);
  EvolveEvents events(loc, who, a + n, all - n, &p.shape, a[0]);
  {
    RuntimeErrorScope scope;
    OdePtr ode = p.make_integrator(T, eps, max_steps);
    events.attach(ode.get());
    p.evolve_to(ode.get(), t, t1, &events);
  }
  return events.stopped ? p.shape.build(p.y.data()) : p.state_at(t1);
}

Value P_state_advancer(Value *a, int n) {
  return make_named_procedure(advance_state, apply_sysder(a, n, "state-advancer"),
                              &g_advancer_lambda);
}

// ((evolve sysder . params) state monitor dt final-time [eps [integrator
// [max-steps]]] event ...):
// calls (monitor state) at the initial state and every dt until the final
// time (the last interval is shortened to end there), and each event's
// procedure at its crossings between; returns the final state, or the state
// at the crossing of an event that stops the integration.
Value run_evolve(NativeProc *self, Value *a, int all) {
  static const char who[] = "evolve";
  const int n = arguments_before_events(a, all, 4, who);
  check_numeric_arguments(who, a, n, self);
  SrcLoc loc = current_call_loc();
  check_monitor_arity(loc, who, a[1]);
  Value monitor = a[1];
  double dt = real_at(a, 2);
  double t_final = real_at(a, 3);
  double eps = optional_real(a, n, 4, kAdvancerTolerance);
  const sicm_ode_step_type *T = arg_integrator(a, n, 5, who);
  check_reachable_tolerance(loc, who, T, eps);
  const unsigned long max_steps = optional_max_steps(a, n, 6);
  OdeProblem p(loc, who, self->a, a[0], 1,
               T == sicm_ode_step_taylor || T == sicm_ode_step_taylor_extended ||
                   recording_integration_sites());
  p.record_site(who, t_final, eps, T);

  Value state = a[0];
  apply_procedure(monitor, &state, 1);
  // The times of the other calls: the runtime's schedule, which built
  // programs walk too (sicm_drive_evolve).
  sicm_monitor_schedule schedule;
  if (const char *why_not = sicm_monitor_schedule_start(&schedule, p.t0, dt, t_final))
    runtime_error(loc, std::string(who) + ": " + why_not);
  EvolveEvents events(loc, who, a + n, all - n, &p.shape, a[0]);
  RuntimeErrorScope scope;
  OdePtr ode = p.make_integrator(T, eps, max_steps);
  sicm_ode_set_horizon(ode.get(), t_final);
  events.attach(ode.get());
  double t = p.t0, tk;
  ProgressBar progress(p.t0, t_final);
  while (sicm_monitor_schedule_next(&schedule, t, &tk)) {
    p.evolve_to(ode.get(), t, tk, &events);
    if (events.stopped) return p.shape.build(p.y.data());
    state = p.state_at(tk);
    apply_procedure(monitor, &state, 1);
    progress.update(tk);
  }
  return state;
}

Value P_evolve(Value *a, int n) {
  return make_named_procedure(run_evolve, apply_sysder(a, n, "evolve"), &g_evolver_lambda);
}

// ---- crossings ----------------------------------------------------------------------

// ((crossings sysder . params) state event direction t-final [eps [integrator
// [count]]]): the states where (event state) crosses 0 in direction between
// the state's time and t-final, in time order, located inside the integrator
// (sicm_ode_set_events); the first count of them only, the integration
// stopping at the last, when count is given.
Value run_crossings(NativeProc *self, Value *a, int n) {
  static const char who[] = "crossings";
  check_numeric_arguments(who, a, n, self);
  SrcLoc loc = current_call_loc();
  check_monitor_arity(loc, who, a[1]);
  const int direction = event_direction(a[2]);
  double t_final = real_at(a, 3);
  double eps = optional_real(a, n, 4, kAdvancerTolerance);
  const sicm_ode_step_type *T = arg_integrator(a, n, 5, who);
  check_reachable_tolerance(loc, who, T, eps);
  OdeProblem p(loc, who, self->a, a[0], 1,
               T == sicm_ode_step_taylor || T == sicm_ode_step_taylor_extended);
  EventCallback events(loc, who, a[1], &p.shape, a[0]);
  events.most = is_missing(a, n, 6) ? 0 : static_cast<size_t>(a[6].i);
  {
    RuntimeErrorScope scope;
    OdePtr ode = p.make_integrator(T, eps, 0);
    const sicm_ode_event event = {call_event, &events, direction, 0};
    sicm_ode_set_events(ode.get(), &event, 1, record_crossing, &events);
    double t = p.t0;
    const bool timed = sicm_stats_enabled(); // the clock only for --stats
    const double start = timed ? sicm_stats_clock() : 0;
    const int status = sicm_ode_evolve(ode.get(), &t, t_final, p.y.data());
    if (timed) p.seconds += sicm_stats_clock() - start;
    p.cb.rethrow_if_failed();
    events.rethrow_if_failed();
    if (status != SICM_SUCCESS) numeric_error(loc, who, sicm_ode_last_error(ode.get()));
  }
  return list_from(events.found.data(), events.found.size());
}

Lambda g_crossings_lambda;

} // namespace

Value crossings_now(NativeProc *self, Value *a, int n) {
  return run_crossings(self, a, n);
}

namespace {

Value P_crossings(Value *a, int n) {
  return make_named_procedure(run_crossings, apply_sysder(a, n, "crossings"), &g_crossings_lambda);
}

// ---- quadrature -------------------------------------------------------------------

// A limit of integration: a real, or :+infinity / :-infinity.
double limit_at(Value *a, int i) {
  if (is_symbol(a[i])) {
    const std::string &s = symbol_name(a[i]);
    return s == ":+infinity" || s == "+infinity" ? INFINITY : -INFINITY;
  }
  return to_double(a[i]);
}

// (definite-integral f a b [tolerance [compile?]]): the integral of f from a
// to b to the relative tolerance (default 1e-11), by adaptive Gauss-Kronrod.
Value P_definite_integral(Value *a, int n) {
  static const char who[] = "definite-integral";
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  double lo = limit_at(a, 1), hi = limit_at(a, 2);
  double tol = optional_real(a, n, 3, kIntegralTolerance);
  if (lo == hi) return Value::fixnum(0);
  ScalarCallback cb(loc, who, f);
  RuntimeErrorScope scope;
  double result = 0;
  int status = sicm_quad_integrate(call_scalar, &cb, lo, hi, tol, &result);
  cb.rethrow_if_failed();
  if (status == SICM_ETOL) {
    // A purely relative test cannot be met when the integral is much smaller
    // than the integrand (cancellation, as in the action of a path close to
    // the true one): rounding errors of the size of the integral of |f| times
    // the machine epsilon swamp it. Then the tolerance is taken relative to
    // the integral of |f| instead, and the integral is computed again.
    std::string message = cb.reason();
    double magnitude = 0;
    int s2 = sicm_quad_integrate(call_scalar_abs, &cb, lo, hi, 1e-3, &magnitude);
    cb.rethrow_if_failed();
    if (s2 == SICM_SUCCESS && magnitude > 2 * std::fabs(result)) {
      if (result == 0) return Value::flonum(0.0);
      double relaxed = tol * magnitude / std::fabs(result);
      status = sicm_quad_integrate(call_scalar, &cb, lo, hi, relaxed, &result);
      cb.rethrow_if_failed();
      if (status == SICM_SUCCESS) return Value::flonum(result);
    }
    numeric_error(loc, who, message);
  }
  if (status != SICM_SUCCESS) numeric_error(loc, who, cb.reason());
  return Value::flonum(result);
}

// ---- minimization -----------------------------------------------------------------

// (minimize f a b [tolerance]): Brent's method on [a, b]; the list
// (argument value iterations), as scmutils' brent-min returns it.
Value minimize_with(const char *who, Value *a, int n) {
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  double lo = real_at(a, 1), hi = real_at(a, 2);
  double tol = optional_real(a, n, 3, kMinimizeTolerance);
  if (lo > hi) std::swap(lo, hi);
  ScalarCallback cb(loc, who, f);
  double xmin = 0, fmin = 0;
  int iterations = 0;
  {
    RuntimeErrorScope scope;
    int status = sicm_min_brent(call_scalar, &cb, lo, hi, tol, &xmin, &fmin, &iterations);
    cb.rethrow_if_failed();
    if (status != SICM_SUCCESS) numeric_error(loc, who, cb.reason());
  }
  return list({Value::flonum(xmin), Value::flonum(fmin), Value::fixnum(iterations)});
}

Value P_minimize(Value *a, int n) {
  return minimize_with("minimize", a, n);
}
Value P_brent_min(Value *a, int n) {
  return minimize_with("brent-min", a, n);
}

// The starting point of a multidimensional minimization: a list or a vector
// of reals.
std::vector<double> point_at(Value *a, int i, bool &is_list) {
  std::vector<double> x;
  is_list = !a[i].is(Tag::Vector);
  if (is_list) {
    for (Value l = a[i]; is_pair(l); l = cdr(l))
      x.push_back(to_double(car(l)));
  } else {
    Vector *v = a[i].vector();
    for (size_t k = 0; k < v->len; ++k)
      x.push_back(to_double(v->items[k]));
  }
  return x;
}

struct NelderMeadResult {
  int status;
  std::vector<double> x;
  double fmin = 0;
  int iterations = 0;
};

NelderMeadResult nelder_mead(VectorCallback &cb, std::vector<double> x, double step, double tol,
                             int max_iter) {
  NelderMeadResult r;
  RuntimeErrorScope scope;
  r.status = sicm_min_nelder_mead(call_vector, &cb, x.size(), x.data(), step, tol, max_iter,
                                  &r.fmin, &r.iterations);
  cb.rethrow_if_failed();
  if (r.status != SICM_SUCCESS && r.status != SICM_EMAXITER)
    numeric_error(cb.loc, cb.who, reason_of(g_runtime_message));
  r.x = std::move(x);
  return r;
}

// (nelder-mead f start-point start-step epsilon max-iterations): the downhill
// simplex method from a vector (or list) start point; f receives vectors.
// epsilon bounds the final simplex size. Returns scmutils' form
// (ok (best-point . value) iterations), or maxcount instead of ok when the
// iterations ran out.
Value P_nelder_mead(Value *a, int n) {
  static const char who[] = "nelder-mead";
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  bool is_list;
  std::vector<double> x = point_at(a, 1, is_list);
  double step = optional_real(a, n, 2, kNelderStep);
  double tol = optional_real(a, n, 3, kNelderTolerance);
  int max_iter = is_missing(a, n, 4) ? kNelderMaxIter : static_cast<int>(a[4].i);
  VectorCallback cb(loc, who, f, x.size(), false);
  NelderMeadResult r = nelder_mead(cb, std::move(x), step, tol, max_iter);
  Value best = cons(point_value(r.x.data(), r.x.size(), false), Value::flonum(r.fmin));
  return list(
      {intern(r.status == SICM_SUCCESS ? "ok" : "maxcount"), best, Value::fixnum(r.iterations)});
}

// (multidimensional-minimize f initial): the point near initial (a list or a
// vector of reals) where f, a function of such a list or vector, is least,
// by Nelder-Mead; the result has the initial point's type.
Value P_multidimensional_minimize(Value *a, int n) {
  static const char who[] = "multidimensional-minimize";
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  bool is_list;
  std::vector<double> x = point_at(a, 1, is_list);
  double tol = optional_real(a, n, 2, kNelderTolerance);
  VectorCallback cb(loc, who, f, x.size(), is_list);
  NelderMeadResult r = nelder_mead(cb, std::move(x), kNelderStep, tol, kNelderMaxIter * 20);
  if (r.status != SICM_SUCCESS) {
    char reason[SICM_MIN_FAILURE_BUFSIZE]; // the words built programs use (sicm/min.h)
    numeric_error(loc, who,
                  sicm_min_nelder_mead_failure(reason, r.iterations, r.x.size(), r.x.data(), r.fmin,
                                               is_list));
  }
  return point_value(r.x.data(), r.x.size(), is_list);
}

// ---- roots --------------------------------------------------------------------------

// (find-root f a b [tolerance]): a root of f in [a, b], where f changes sign,
// by Brent's method (full precision by default).
Value P_find_root(Value *a, int n) {
  static const char who[] = "find-root";
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  double lo = real_at(a, 1), hi = real_at(a, 2);
  double tol = optional_real(a, n, 3, 0.0);
  if (lo > hi) std::swap(lo, hi);
  ScalarCallback cb(loc, who, f);
  double f_lo = call_scalar(lo, &cb), f_hi = call_scalar(hi, &cb);
  cb.rethrow_if_failed();
  if (f_lo == 0) return Value::flonum(lo);
  if (f_hi == 0) return Value::flonum(hi);
  if (std::isfinite(f_lo) && std::isfinite(f_hi) && (f_lo > 0) == (f_hi > 0))
    numeric_error(loc, who,
                  "the function is " + number_text(f_lo) + " at " + number_text(lo) + " and " +
                      number_text(f_hi) + " at " + number_text(hi) +
                      ": the interval does not bracket a root");
  double root = 0;
  RuntimeErrorScope scope;
  int status = sicm_root_brent(call_scalar, &cb, lo, hi, tol, &root);
  cb.rethrow_if_failed();
  if (status != SICM_SUCCESS) numeric_error(loc, who, cb.reason());
  return Value::flonum(root);
}

// (bisect f x0 x1 eps [n-break]): a root of f between x0 and x1 by
// bisection (then, after n-break halvings, by false position), until the
// ends are close-enuf? to eps; f's values need only have the right signs.
// The runtime's sicm_root_bisect takes the steps, as in built programs.
Value P_bisect(Value *a, int n) {
  static const char who[] = "bisect";
  check_numeric_arguments(who, a, n);
  SrcLoc loc = current_call_loc();
  Value f = a[0];
  double x0 = real_at(a, 1), x1 = real_at(a, 2);
  double eps = real_at(a, 3);
  long n_break = is_missing(a, n, 4) ? kBisectBreak : static_cast<long>(a[4].i);
  ScalarCallback cb(loc, who, f);
  cb.compile_expensive = true;
  double root = 0, bracket[2], values[2];
  int status = sicm_root_bisect(call_scalar, &cb, x0, x1, eps, n_break, kBisectMaxIter, &root,
                                bracket, values);
  cb.rethrow_if_failed();
  if (status == SICM_EBRACKET)
    numeric_error(loc, who,
                  "root not bounded: the function is " + number_text(values[0]) + " at " +
                      number_text(bracket[0]) + " and " + number_text(values[1]) + " at " +
                      number_text(bracket[1]));
  if (status != SICM_SUCCESS)
    numeric_error(loc, who,
                  "no convergence in " + std::to_string(kBisectMaxIter) +
                      " iterations; the root is between " + number_text(bracket[0]) + " and " +
                      number_text(bracket[1]));
  return Value::flonum(root);
}

// ---- eigenvalues ----------------------------------------------------------------

// (eigenvalues M): the eigenvalues of the square matrix M of real numbers, by
// the runtime (Eigen), as a list ordered by decreasing modulus: a real one a
// flonum, a complex one a complex number. Conjugate pairs come with im > 0
// first.
Value P_eigenvalues(Value *a, int) {
  static const char who[] = "eigenvalues";
  SrcLoc loc = current_call_loc();
  if (!is_matrix(a[0])) wrong_type(a[0], 1, who);
  Matrix *m = a[0].as<Matrix>();
  if (m->rows != m->cols || m->rows == 0) wrong_type(a[0], 1, who);
  size_t n = m->rows;
  std::vector<double> entries(n * n), re(n), im(n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      Value x = matrix_at(m, i, j);
      if (!is_real(x))
        numeric_error(loc, who,
                      "the entry (" + std::to_string(i) + ", " + std::to_string(j) + ") is " +
                          write_string(x) + ", not a real number");
      entries[i * n + j] = to_double(x);
    }
  RuntimeErrorScope scope;
  if (sicm_linalg_eigenvalues(n, entries.data(), re.data(), im.data()) != SICM_SUCCESS)
    numeric_error(loc, who, reason_of(g_runtime_message));
  Value result = Value::nil();
  for (size_t k = n; k-- > 0;) {
    Value z = im[k] == 0 ? Value::flonum(re[k])
                         : make_rectangular(Value::flonum(re[k]), Value::flonum(im[k]));
    result = cons(z, result);
  }
  return result;
}

} // namespace

void install_numerics_primitives() {
  g_method_variable = intern("*ode-integration-method*").symbol();
  define_global("*ode-integration-method*", intern("bulirsch-stoer"));
  g_advancer_lambda.name = intern("state-advancer").symbol();
  g_evolver_lambda.name = intern("evolve").symbol();
  g_crossings_lambda.name = intern("crossings").symbol();

  define_primitive("definite-integral", 3, 5, Stage::RunTime, P_definite_integral);
  define_primitive("minimize", 3, 4, Stage::RunTime, P_minimize);
  define_primitive("brent-min", 3, 4, Stage::RunTime, P_brent_min);
  define_primitive("nelder-mead", 2, 5, Stage::RunTime, P_nelder_mead);
  define_primitive("multidimensional-minimize", 2, 3, Stage::RunTime, P_multidimensional_minimize);
  define_primitive("find-root", 3, 4, Stage::RunTime, P_find_root);
  define_primitive("bisect", 4, 5, Stage::RunTime, P_bisect);
  define_primitive("state-advancer", 1, kVariadic, Stage::RunTime, P_state_advancer);
  define_primitive("evolve", 1, kVariadic, Stage::RunTime, P_evolve);
  define_primitive("crossings", 1, kVariadic, Stage::RunTime, P_crossings);
  define_primitive("eigenvalues", 1, 1, Stage::Pure, P_eigenvalues);
  define_primitive("matrix->eigenvalues", 1, 1, Stage::Pure, P_eigenvalues);
}

} // namespace sicm
