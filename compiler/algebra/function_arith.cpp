// Arithmetic on procedures: (+ f g), (* 3 f), (sin f), (compose f g) as applicable objects.
//
// SICM treats a procedure as a function to be added, multiplied and composed
// like any quantity: (+ f g) is the procedure x |-> (+ (f x) (g x)), (* 3 f)
// is x |-> (* 3 (f x)), (sin f) is x |-> (sin (f x)). A combination is built
// at once and evaluated when applied; the operation at that point is the
// generic one, so the values the functions return may be numbers,
// expressions, structures or procedures in turn. Operands that are not
// procedures act as constant functions.
//
// The objects are opaque values whose apply runs a C++ function (NativeProc).
// They print as MIT prints an anonymous lambda, #[compound-procedure 12],
// numbered by the printer's hash table: each carries a dummy Closure so that
// the printer's own numbering serves them too.
#include <algorithm>
#include <string>

#include "algebra/generic.hpp"
#include "base/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

Lambda g_anonymous_lambda; // what the printer sees of a NativeProc: no name

void write_native(std::string &out, const void *obj, bool display) {
  auto *p = static_cast<const NativeProc *>(obj);
  print_value(out, Value::object(Tag::Closure, &p->print_as), display);
}

Value apply_native(void *obj, Value *args, int nargs) {
  auto *p = static_cast<NativeProc *>(obj);
  return p->fn(p, args, nargs);
}

const OpaqueKind kNativeKind = {"compound-procedure", write_native, apply_native};

// The value of an operand at the arguments: procedures are called (on a copy
// of the arguments, so that one callee cannot disturb what the next sees),
// and so are structures and matrices, entry by entry (scmutils'
// coerce-to-function applies whatever is not a number); other values are
// constants.
Value operand_value(Value f, const Value *args, int nargs) {
  if (!is_procedure(f) && !f.is(Tag::Structure) && !f.is(Tag::Matrix)) return f;
  constexpr int kSmall = 8;
  if (nargs <= kSmall) {
    Value copy[kSmall];
    std::copy(args, args + nargs, copy);
    return apply_procedure(f, copy, nargs);
  }
  gcvec<Value> copy(args, args + nargs);
  return apply_procedure(f, copy.data(), nargs);
}

Value call_unary(NativeProc *self, Value *args, int nargs) {
  return g_unary(static_cast<UnaryOp>(self->op), operand_value(self->a, args, nargs));
}

Value call_binary(NativeProc *self, Value *args, int nargs) {
  Value a = operand_value(self->a, args, nargs);
  Value b = operand_value(self->b, args, nargs);
  return g_binary(static_cast<BinaryOp>(self->op), a, b);
}

// items[0] is applied last: (compose f g h) calls h on the arguments, then
// g, then f, each on the single value of the one before.
Value call_compose(NativeProc *self, Value *args, int nargs) {
  if (self->nitems == 0) {
    if (nargs != 1) native_arity_error(self, nargs, 1);
    return args[0];
  }
  // Applied, never taken as a constant: a structure of functions composes too.
  gcvec<Value> copy(args, args + nargs);
  Value v = apply_procedure(self->items[self->nitems - 1], copy.data(), nargs);
  for (size_t i = self->nitems - 1; i-- > 0;)
    v = apply_procedure(self->items[i], &v, 1);
  return v;
}

Value function_unary(UnaryOp op, Value f) {
  if (op == UnaryOp::ZeroP) arith_wrong_type(op, f);
  return make_native_procedure(call_unary, static_cast<int>(op), f, Value::nil());
}

Value function_binary(BinaryOp op, Value a, Value b) {
  if (!is_arithmetic(a)) arith_wrong_type(op, a, 1);
  if (!is_arithmetic(b)) arith_wrong_type(op, b, 2);
  if (op == BinaryOp::Equal) arith_wrong_type(op, is_procedure(a) ? a : b, is_procedure(a) ? 1 : 2);
  return make_native_procedure(call_binary, static_cast<int>(op), a, b);
}

const ArithType kFunctionType = {"function", 30, is_procedure, function_unary, function_binary};

} // namespace

Value make_native_procedure(NativeFn fn, int op, Value a, Value b, const Value *items,
                            size_t nitems) {
  NativeProc *p = gc_new<NativeProc>();
  p->fn = fn;
  p->op = op;
  p->a = a;
  p->b = b;
  p->nitems = nitems;
  p->items = nullptr;
  if (nitems) {
    p->items = static_cast<Value *>(GC_MALLOC(nitems * sizeof(Value)));
    if (!p->items) throw std::bad_alloc();
    std::copy(items, items + nitems, p->items);
  }
  p->print_as.lambda = &g_anonymous_lambda;
  p->print_as.env = nullptr;
  Opaque *o = gc_new<Opaque>(Opaque{&kNativeKind, p});
  return Value::object(Tag::Opaque, o);
}

void native_arity_error(NativeProc *self, int given, int required) {
  native_arity_error(self, given, required, required);
}

void native_arity_error(NativeProc *self, int given, int min, int max) {
  auto plural = [](int n) { return std::to_string(n) + (n == 1 ? " argument" : " arguments"); };
  std::string name;
  write_native(name, self, false);
  runtime_error(current_call_loc(),
                "The procedure " + name + " has been called with " + plural(given) +
                    "; it requires " +
                    (min == max ? "exactly " + plural(min)
                                : "between " + std::to_string(min) + " and " + plural(max)) +
                    ".");
}

Value function_combination(BinaryOp op, Value a, Value b) {
  return make_native_procedure(call_binary, static_cast<int>(op), a, b);
}

Value compose_procedures(const Value *fs, size_t n) {
  if (n == 1) return fs[0];
  return make_native_procedure(call_compose, 0, Value::nil(), Value::nil(), fs, n);
}

void register_function_arith() {
  register_arith_type(&kFunctionType);
}

} // namespace sicm
