// Registering primitives and their argument errors (see primitive.hpp).
#include "base/primitive.hpp"

#include "base/error.hpp"

namespace sicm {

// ---- registration and argument errors --------------------------------------

namespace {
gcvec<Value> g_defined; // static, hence a root for the collector
} // namespace

void define_primitive(const char *name, int min_args, int max_args, Stage stage, PrimFn fn) {
  Primitive *p = gc_new<Primitive>(Primitive{name, min_args, max_args, fn, stage});
  Value v = Value::object(Tag::Primitive, p);
  g_defined.push_back(v);
  define_global(name, v);
}

std::vector<const Primitive *> defined_primitives() {
  std::vector<const Primitive *> all;
  for (Value v : g_defined)
    all.push_back(v.as<Primitive>());
  return all;
}

void define_global(const char *name, Value v) {
  Symbol *s = intern(name).symbol();
  s->global = v;
  s->bound = true;
}

namespace {
const char *ordinal(int n) {
  static const char *const names[] = {"zeroth", "first",   "second", "third", "fourth", "fifth",
                                      "sixth",  "seventh", "eighth", "ninth", "tenth"};
  return n >= 0 && n <= 10 ? names[n] : "nth";
}
} // namespace

namespace {

RunTimeValueTest g_run_time_value_test = nullptr;
RunTimeWriter g_run_time_writer = nullptr;

// Can an argument error about obj, which holds run-time values, be written
// now? Only when obj is a structure, vector or list (its kind, known now,
// is what is wrong) and the error is certain to happen where it is raised.
bool writable_when_run(Value obj) {
  return g_run_time_writer && !g_run_time_value_test(obj) && raised_at_top_level();
}

// A primitive that only sicm run computes, given a value known only at run
// time by sicm build.
void refuse_run_time_argument(Value obj, int argpos, const char *who) {
  if (!g_run_time_value_test || !holds_run_time_value(obj) || writable_when_run(obj)) return;
  bool number = g_run_time_value_test(obj);
  throw Error(ErrorKind::Syntax, ErrorCause::CannotCompile, current_call_loc(),
              std::string("cannot compile: ") + who + " of " +
                  (number ? "a number known only at run time"
                          : "a value that holds numbers known only at run time") +
                  " (its " + ordinal(argpos) + " argument)",
              kCannotCompileNote);
}

} // namespace

void set_run_time_value_test(RunTimeValueTest test) {
  g_run_time_value_test = test;
}

RunTimeValueTest run_time_value_test() {
  return g_run_time_value_test;
}

void set_run_time_writer(RunTimeWriter writer) {
  g_run_time_writer = writer;
}

namespace {
// obj as an argument error writes it (see RunTimeWriter).
std::string written_argument(Value obj) {
  if (g_run_time_value_test && holds_run_time_value(obj)) return g_run_time_writer(obj);
  return written(obj);
}
} // namespace

bool holds_run_time_value(Value v, int depth) {
  if (!g_run_time_value_test) return false;
  if (g_run_time_value_test(v)) return true;
  if (depth == 0) return false;
  const Value *items = nullptr;
  size_t len = 0;
  if (v.is(Tag::Structure)) {
    items = v.as<Structure>()->items;
    len = v.as<Structure>()->len;
  } else if (v.is(Tag::Vector)) {
    items = v.vector()->items;
    len = v.vector()->len;
  } else if (v.is(Tag::Pair)) {
    return holds_run_time_value(car(v), depth - 1) || holds_run_time_value(cdr(v), depth - 1);
  }
  for (size_t i = 0; i < len && i < 64; ++i)
    if (holds_run_time_value(items[i], depth - 1)) return true;
  return false;
}

void wrong_type(Value obj, int argpos, const char *who) {
  refuse_run_time_argument(obj, argpos, who);
  runtime_error(current_call_loc(), "The object " + written_argument(obj) + ", passed as the " +
                                        ordinal(argpos) + " argument to " + who +
                                        ", is not the correct type.");
}

void bad_range(Value obj, int argpos, const char *who) {
  refuse_run_time_argument(obj, argpos, who);
  runtime_error(current_call_loc(), "The object " + written_argument(obj) + ", passed as the " +
                                        ordinal(argpos) + " argument to " + who +
                                        ", is not in the correct range.");
}

void bad_range(Value obj, int argpos, const char *who, const std::string &rule) {
  refuse_run_time_argument(obj, argpos, who);
  runtime_error(current_call_loc(), "The object " + written_argument(obj) + ", passed as the " +
                                        ordinal(argpos) + " argument to " + who +
                                        ", is not in the correct range (" + rule + ").");
}

int64_t arg_fixnum(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Fixnum)) wrong_type(args[i], i + 1, who);
  return args[i].i;
}

size_t arg_index(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Fixnum)) wrong_type(args[i], i + 1, who);
  if (args[i].i < 0) bad_range(args[i], i + 1, who);
  return static_cast<size_t>(args[i].i);
}

size_t arg_bounded(Value *args, int i, size_t lo, size_t hi, const char *who) {
  if (!args[i].is(Tag::Fixnum)) wrong_type(args[i], i + 1, who);
  if (args[i].i < 0 || static_cast<size_t>(args[i].i) < lo || static_cast<size_t>(args[i].i) > hi)
    bad_range(args[i], i + 1, who);
  return static_cast<size_t>(args[i].i);
}

std::string_view arg_string(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::String)) wrong_type(args[i], i + 1, who);
  return string_view(args[i]);
}

Symbol *arg_symbol(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Symbol)) wrong_type(args[i], i + 1, who);
  return args[i].symbol();
}

} // namespace sicm
