// Core primitives: registration, argument errors, equivalence, predicates,
// control (apply, values, promises, errors, continuations) and output.
#include <chrono>
#include <cstdio>
#include <ctime>

#include "algebra/structure.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "eval/analyze.hpp"
#include "eval/core.hpp"
#include "eval/effect_guard.hpp"
#include "eval/interp.hpp"
#include "eval/procedure.hpp"
#include "print/pretty.hpp"
#include "print/printer.hpp"

namespace sicm {

// ---- equivalence -------------------------------------------------------------

bool eqv(Value a, Value b) {
  if (eq(a, b)) return true;
  if (a.tag != b.tag) return false;
  switch (a.tag) {
  case Tag::Bignum:
  case Tag::Ratnum: return num_equal(a, b);
  case Tag::Recnum: // the parts are eqv?: 1+2i is not eqv? to 1.+2.i
    return eqv(num_real_part(a), num_real_part(b)) && eqv(num_imag_part(a), num_imag_part(b));
  case Tag::String: return a.p == b.p;
  default: return false;
  }
}

bool equal(Value a, Value b) {
  for (;;) {
    if (eqv(a, b)) return true;
    if (a.tag != b.tag) return false;
    switch (a.tag) {
    case Tag::Pair:
      check_stack();
      if (!equal(car(a), car(b))) return false;
      a = cdr(a);
      b = cdr(b);
      continue;
    case Tag::String: return string_view(a) == string_view(b);
    case Tag::Vector: {
      Vector *x = a.vector(), *y = b.vector();
      if (x->len != y->len) return false;
      for (size_t i = 0; i < x->len; ++i)
        if (!equal(x->items[i], y->items[i])) return false;
      return true;
    }
    case Tag::Flonum: return a.d == b.d;
    case Tag::Structure: {
      Structure *x = a.as<Structure>(), *y = b.as<Structure>();
      if (x->up != y->up || x->len != y->len) return false;
      for (size_t i = 0; i < x->len; ++i)
        if (!equal(x->items[i], y->items[i])) return false;
      return true;
    }
    case Tag::Matrix: {
      Matrix *x = a.as<Matrix>(), *y = b.as<Matrix>();
      if (x->rows != y->rows || x->cols != y->cols) return false;
      for (size_t i = 0; i < x->rows * x->cols; ++i)
        if (!equal(x->items[i], y->items[i])) return false;
      return true;
    }
    default: return false;
    }
  }
}

// ---- output ------------------------------------------------------------------

namespace {
std::string *g_capture = nullptr; // with-output-to-string redirects here
int g_column = 0;
OutputHook g_output_hook = nullptr;   // sicm build: output becomes residual statements
CaptureHook g_capture_hook = nullptr; // sicm build: may refuse output into a string
} // namespace

namespace {
PrintPreparer g_print_preparer = nullptr;
} // namespace

void set_print_preparer(PrintPreparer prepare) {
  g_print_preparer = prepare;
}
PrintPreparer print_preparer() {
  return g_print_preparer;
}

void set_output_hook(OutputHook hook) {
  g_output_hook = hook;
}

void set_capture_hook(CaptureHook hook) {
  g_capture_hook = hook;
}

void output(std::string_view s) {
  if (s.empty()) return;
  refuse_effect("output");
  if (g_capture) {
    if (g_capture_hook) g_capture_hook();
    g_capture->append(s);
  } else if (g_output_hook) {
    g_output_hook(s);
  } else {
    std::fwrite(s.data(), 1, s.size(), stdout);
  }
  size_t nl = s.rfind('\n');
  g_column = nl == std::string_view::npos ? g_column + static_cast<int>(s.size())
                                          : static_cast<int>(s.size() - nl - 1);
}

void flush_output() {
  std::fflush(stdout);
}

int output_column() {
  return g_column;
}

namespace {

Value P_display(Value *a, int) {
  output(display_string(a[0]));
  return Value::unspecified();
}
Value P_write(Value *a, int) {
  output(write_string(a[0]));
  return Value::unspecified();
}
Value P_write_string(Value *a, int) {
  arg_string(a, 0, "write-string");
  output(string_view(a[0]));
  return Value::unspecified();
}
Value P_write_char(Value *a, int) {
  if (!a[0].is(Tag::Char)) wrong_type(a[0], 1, "write-char");
  output(display_string(a[0]));
  return Value::unspecified();
}
Value P_newline(Value *, int) {
  output("\n");
  return Value::unspecified();
}
Value P_fresh_line(Value *, int) {
  if (g_column != 0) output("\n");
  return Value::unspecified();
}
Value P_write_line(Value *a, int) {
  output(write_string(a[0]));
  output("\n");
  return Value::unspecified();
}
Value P_pp(Value *a, int) {
  output(pretty_string(a[0]));
  output("\n");
  return Value::unspecified();
}
Value P_flush_output(Value *, int) {
  flush_output();
  return Value::unspecified();
}
Value P_with_output_to_string(Value *a, int n) {
  std::string buffer;
  std::string *saved = g_capture;
  g_capture = &buffer;
  try {
    if (n > 0) apply_procedure(a[0], nullptr, 0);
  } catch (...) {
    g_capture = saved;
    throw;
  }
  g_capture = saved;
  return make_string(buffer);
}

// ---- predicates and equivalence ----

Value P_eq(Value *a, int) {
  return Value::boolean(eq(a[0], a[1]));
}
Value P_eqv(Value *a, int) {
  return Value::boolean(eqv(a[0], a[1]));
}
Value P_equal(Value *a, int) {
  return Value::boolean(equal(a[0], a[1]));
}
Value P_not(Value *a, int) {
  return Value::boolean(a[0].is_false());
}
Value P_boolean_p(Value *a, int) {
  return Value::boolean(a[0].is(Tag::Bool));
}
Value P_procedure_p(Value *a, int) {
  return Value::boolean(is_procedure(a[0]));
}
Value P_default_object_p(Value *a, int) {
  return Value::boolean(a[0].is(Tag::Default));
}
Value P_eof_object_p(Value *a, int) {
  return Value::boolean(a[0].is(Tag::Eof));
}
Value P_eof_object(Value *, int) {
  return Value::eof();
}
Value P_promise_p(Value *a, int) {
  return Value::boolean(a[0].is(Tag::Promise));
}
Value P_boolean_eq(Value *a, int n) {
  for (int i = 0; i < n; ++i)
    if (!a[i].is(Tag::Bool)) wrong_type(a[i], i + 1, "boolean=?");
  for (int i = 1; i < n; ++i)
    if (a[i].b != a[0].b) return Value::boolean(false);
  return Value::boolean(true);
}

// ---- control ----

Value P_apply(Value *a, int n) {
  if (n == 1) return apply_procedure(a[0], nullptr, 0);
  gcvec<Value> args(a + 1, a + n - 1);
  Value last = a[n - 1];
  if (list_length(last) < 0) wrong_type(last, n, "apply");
  for (; is_pair(last); last = cdr(last))
    args.push_back(car(last));
  return apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
}

Value P_values(Value *a, int n) {
  if (n == 1) return a[0];
  Value *items = static_cast<Value *>(GC_MALLOC(sizeof(Value) * (n ? n : 1)));
  for (int i = 0; i < n; ++i)
    items[i] = a[i];
  return Value::object(Tag::Values, gc_new<MultipleValues>(MultipleValues{items, size_t(n)}));
}

Value P_call_with_values(Value *a, int) {
  Value v = apply_procedure(a[0], nullptr, 0);
  if (v.is(Tag::Values)) {
    MultipleValues *mv = v.as<MultipleValues>();
    return apply_procedure(a[1], mv->items, static_cast<int>(mv->len));
  }
  return apply_procedure(a[1], &v, 1);
}

Value P_force(Value *a, int) {
  return force_promise(a[0]);
}
Value P_make_promise(Value *a, int) {
  if (a[0].is(Tag::Promise)) return a[0];
  return Value::object(Tag::Promise, gc_new<Promise>(Promise{true, a[0], nullptr, nullptr}));
}

// (error "message" irritant ...): MIT prints the message, then each irritant
// written (strings in quotes), separated by spaces.
std::string error_message(Value *a, int n) {
  std::string msg = a[0].is(Tag::String) ? std::string(string_view(a[0])) : write_string(a[0]);
  for (int i = 1; i < n; ++i) {
    msg += ' ';
    msg += write_string(a[i]);
  }
  return msg;
}

Value P_error(Value *a, int n) {
  runtime_error(current_call_loc(), error_message(a, n));
}

Value P_warn(Value *a, int n) {
  flush_output();
  std::fprintf(stderr, ";Warning: %s\n", error_message(a, n).c_str());
  return Value::unspecified();
}

Value P_assert(Value *a, int) {
  if (a[0].is_false()) runtime_error(current_call_loc(), "Assertion failed");
  return Value::unspecified();
}

Value P_exit(Value *a, int n) {
  int code = 0;
  if (n > 0) {
    if (a[0].is(Tag::Fixnum))
      code = static_cast<int>(a[0].i & 0xff);
    else if (a[0].is(Tag::Bool))
      code = a[0].b ? 0 : 1;
  }
  flush_output();
  std::exit(code);
}

// MIT's runtime: the processor time used so far, in seconds.
Value P_runtime(Value *, int) {
  refuse_effect("runtime");
  return Value::flonum(static_cast<double>(std::clock()) / CLOCKS_PER_SEC);
}

Value P_real_time(Value *, int) {
  refuse_effect("real-time");
  using namespace std::chrono;
  double ms = duration<double, std::milli>(system_clock::now().time_since_epoch()).count();
  return Value::flonum(ms);
}

Value P_identity(Value *a, int) {
  return a[0];
}
Value P_void(Value *, int) {
  return Value::unspecified();
}

// Escape-only continuations: invoking one unwinds to its call/cc.
struct ContinuationThrow {
  uint64_t id;
  Value value; // also kept alive by the catching frame's stack copy
};
uint64_t g_next_continuation = 1;

Value P_continuation_invoke(Value *, int) {
  return Value::unspecified();
} // placeholder name

Value P_call_cc(Value *a, int) {
  uint64_t id = g_next_continuation++;
  // The continuation is a closure-like primitive carrying its id in a record.
  RecordType *type = gc_new<RecordType>();
  type->name = intern("continuation").symbol();
  Value *fields = static_cast<Value *>(GC_MALLOC(sizeof(Value)));
  fields[0] = Value::fixnum(static_cast<int64_t>(id));
  Value k = Value::object(Tag::Record, gc_new<Record>(Record{type, fields}));
  try {
    return apply_procedure(a[0], &k, 1);
  } catch (ContinuationThrow &t) {
    if (t.id != id) throw;
    return t.value;
  }
}

Value P_within_continuation(Value *a, int) {
  if (!a[0].is(Tag::Record) || a[0].as<Record>()->type->name->name != "continuation")
    wrong_type(a[0], 1, "within-continuation");
  Value v = apply_procedure(a[1], nullptr, 0);
  throw ContinuationThrow{static_cast<uint64_t>(a[0].as<Record>()->fields[0].i), v};
}

Value P_dynamic_wind(Value *a, int) {
  apply_procedure(a[0], nullptr, 0);
  Value result;
  try {
    result = apply_procedure(a[1], nullptr, 0);
  } catch (...) {
    apply_procedure(a[2], nullptr, 0);
    throw;
  }
  apply_procedure(a[2], nullptr, 0);
  return result;
}

Value P_eval(Value *a, int) {
  Node *n = analyze_form(a[0], current_call_loc(), nullptr);
  return eval(n, nullptr);
}

Value P_procedure_arity(Value *a, int) {
  if (a[0].is(Tag::Primitive)) {
    Primitive *p = a[0].as<Primitive>();
    return cons(Value::fixnum(p->min_args),
                p->max_args < 0 ? Value::boolean(false) : Value::fixnum(p->max_args));
  }
  if (!a[0].is(Tag::Closure)) wrong_type(a[0], 1, "procedure-arity");
  Lambda *l = a[0].as<Closure>()->lambda;
  return cons(Value::fixnum(l->nrequired),
              l->rest ? Value::boolean(false) : Value::fixnum(l->nrequired + l->noptional));
}

} // namespace

// Continuation objects are applied through apply_continuation (see eval hook).
bool is_continuation(Value v) {
  return v.is(Tag::Record) && v.as<Record>()->type->name->name == "continuation";
}

[[noreturn]] void throw_to_continuation(Value k, Value *args, int nargs) {
  Value v = nargs == 1 ? args[0] : P_values(args, nargs);
  throw ContinuationThrow{static_cast<uint64_t>(k.as<Record>()->fields[0].i), v};
}

void install_core_primitives() {
  define_primitive("display", 1, 2, Stage::Effect, P_display);
  define_primitive("write", 1, 2, Stage::Effect, P_write);
  define_primitive("write-string", 1, 2, Stage::Effect, P_write_string);
  define_primitive("write-char", 1, 2, Stage::Effect, P_write_char);
  define_primitive("newline", 0, 1, Stage::Effect, P_newline);
  define_primitive("fresh-line", 0, 1, Stage::Effect, P_fresh_line);
  define_primitive("write-line", 1, 2, Stage::Effect, P_write_line);
  define_primitive("pp", 1, 2, Stage::Effect, P_pp);
  define_primitive("flush-output", 0, 1, Stage::Effect, P_flush_output);
  define_primitive("with-output-to-string", 0, 1, Stage::Effect, P_with_output_to_string);

  define_primitive("eq?", 2, 2, Stage::Pure, P_eq);
  define_primitive("eqv?", 2, 2, Stage::Pure, P_eqv);
  define_primitive("equal?", 2, 2, Stage::Pure, P_equal);
  define_primitive("not", 1, 1, Stage::Pure, P_not);
  define_primitive("boolean?", 1, 1, Stage::Pure, P_boolean_p);
  define_primitive("boolean=?", 2, kVariadic, Stage::Pure, P_boolean_eq);
  define_primitive("procedure?", 1, 1, Stage::Pure, P_procedure_p);
  define_primitive("default-object?", 1, 1, Stage::Pure, P_default_object_p);
  define_primitive("eof-object?", 1, 1, Stage::Pure, P_eof_object_p);
  define_primitive("eof-object", 0, 0, Stage::Pure, P_eof_object);
  define_primitive("promise?", 1, 1, Stage::Pure, P_promise_p);

  define_primitive("apply", 1, kVariadic, Stage::Pure, P_apply);
  register_apply_primitive(intern("apply").symbol()->global);
  define_primitive("values", 0, kVariadic, Stage::Pure, P_values);
  define_primitive("call-with-values", 2, 2, Stage::Pure, P_call_with_values);
  define_primitive("force", 1, 1, Stage::Pure, P_force);
  define_primitive("make-promise", 1, 1, Stage::Pure, P_make_promise);
  define_primitive("error", 1, kVariadic, Stage::Effect, P_error);
  define_primitive("warn", 1, kVariadic, Stage::Effect, P_warn);
  define_primitive("assert", 1, kVariadic, Stage::Pure, P_assert);
  define_primitive("exit", 0, 1, Stage::Effect, P_exit);
  define_primitive("%exit", 0, 1, Stage::Effect, P_exit);
  define_primitive("runtime", 0, 0, Stage::Effect, P_runtime);
  define_primitive("real-time", 0, 0, Stage::Effect, P_real_time);
  define_primitive("identity", 1, 1, Stage::Pure, P_identity);
  define_primitive("void", 0, kVariadic, Stage::Pure, P_void);
  define_primitive("call-with-current-continuation", 1, 1, Stage::Pure, P_call_cc);
  define_primitive("call/cc", 1, 1, Stage::Pure, P_call_cc);
  define_primitive("call-with-escape-continuation", 1, 1, Stage::Pure, P_call_cc);
  define_primitive("within-continuation", 2, 2, Stage::Pure, P_within_continuation);
  define_primitive("dynamic-wind", 3, 3, Stage::Pure, P_dynamic_wind);
  define_primitive("eval", 1, 2, Stage::Pure, P_eval);
  define_primitive("procedure-arity", 1, 1, Stage::Pure, P_procedure_arity);
  (void)P_continuation_invoke;

  define_global("true", Value::boolean(true));
  define_global("false", Value::boolean(false));
  define_global("the-empty-stream", Value::nil());
  define_global("stream-nil", Value::nil());
  define_global("system-global-environment", Value::boolean(false));
  define_global("user-initial-environment", Value::boolean(false));
}

} // namespace sicm
