// Primitives on native kernels: compile-procedure, kernel?, kernel-c-source.
//
// (compile-procedure proc sample ...) traces proc on arguments shaped like the
// samples and returns a kernel: an applicable object that flattens its
// arguments, runs the native code and rebuilds the result (always flonums). It
// prints as #[kernel NAME]. Arguments shaped like the samples but with leaves
// that are not numbers (symbols, or the run-time values of `sicm build`,
// which traces what a kernel computes into the executable) go to the
// procedure itself. A procedure that cannot be compiled is returned as it
// is, after a note on stderr saying why, so a program keeps working,
// interpreted; (kernel? x) tells the two apart.
#include <cstdio>
#include <string>
#include <vector>

#include "algebra/structure.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "codegen/kernel.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

void write_kernel(std::string &out, const void *obj, bool) {
  out += "#[kernel " + static_cast<const Kernel *>(obj)->name + "]";
}

std::string plural(size_t n, const char *word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

Value apply_kernel(void *obj, Value *args, int nargs);

const OpaqueKind kKernelKind = {"kernel", write_kernel, apply_kernel};

Value kernel_value(Kernel *k) {
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kKernelKind, k}));
}

Kernel *as_kernel(Value v) {
  if (!v.is(Tag::Opaque) || v.as<Opaque>()->kind != &kKernelKind) return nullptr;
  return static_cast<Kernel *>(v.as<Opaque>()->obj);
}

// Is v shaped like shape, whatever its leaves are?
bool has_structure_of(Value v, Value shape) {
  if (!is_structure(shape)) return !is_structure(v);
  if (!is_structure(v)) return false;
  Structure *a = as_structure(v), *b = as_structure(shape);
  if (a->up != b->up || a->len != b->len) return false;
  for (size_t i = 0; i < a->len; ++i)
    if (!has_structure_of(a->items[i], b->items[i])) return false;
  return true;
}

// Check the arguments against the kernel's shapes, flatten, run, rebuild.
Value apply_kernel(void *obj, Value *args, int nargs) {
  auto *k = static_cast<Kernel *>(obj);
  long expected = list_length(k->arg_shapes);
  if (nargs != expected)
    runtime_error(current_call_loc(),
                  "The procedure " + write_string(kernel_value(k)) + " has been called with " +
                      plural(static_cast<size_t>(nargs), "argument") + "; it requires exactly " +
                      plural(static_cast<size_t>(expected), "argument") + ".");
  thread_local std::vector<double> in, out;
  in.clear();
  Value shapes = k->arg_shapes;
  bool numbers = true, structured = true;
  Value s = shapes;
  for (int i = 0; i < nargs; ++i, s = cdr(s)) {
    numbers = numbers && value_has_shape(args[i], car(s));
    structured = structured && has_structure_of(args[i], car(s));
  }
  if (!numbers && structured && is_procedure(k->source))
    return apply_procedure(k->source, args, nargs);
  for (int i = 0; i < nargs; ++i, shapes = cdr(shapes)) {
    if (!value_has_shape(args[i], car(shapes))) wrong_type(args[i], i + 1, k->name.c_str());
    flatten_value(args[i], in, k->name.c_str());
  }
  out.resize(k->nout);
  kernel_call(k, in.data(), out.data());
  return kernel_result_value(k, out.data());
}

Value P_compile_procedure(Value *a, int n) {
  if (!is_procedure(a[0])) wrong_type(a[0], 1, "compile-procedure");
  Value samples = list_from(a + 1, static_cast<size_t>(n - 1));
  std::string why_not;
  Kernel *k = compile_kernel(a[0], samples, nullptr, &why_not);
  if (k) return kernel_value(k);
  std::fprintf(stderr, ";Note: compile-procedure: %s is interpreted: %s\n",
               write_string(a[0]).c_str(), why_not.c_str());
  return a[0];
}

Value P_kernel_p(Value *a, int) {
  return Value::boolean(as_kernel(a[0]) != nullptr);
}

Value P_kernel_c_source(Value *a, int) {
  Kernel *k = as_kernel(a[0]);
  if (!k) wrong_type(a[0], 1, "kernel-c-source");
  return make_string(k->c_source);
}

} // namespace

void install_kernel_primitives() {
  define_primitive("compile-procedure", 1, kVariadic, Stage::Pure, P_compile_procedure);
  define_primitive("kernel?", 1, 1, Stage::Pure, P_kernel_p);
  define_primitive("kernel-c-source", 1, 1, Stage::Pure, P_kernel_c_source);
}

} // namespace sicm
