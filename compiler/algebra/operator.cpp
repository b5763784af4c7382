// D and partial: derivatives of any procedure by forward-mode AD, and the
// arithmetic of operators.
//
// (D f) is a procedure; applied to x it perturbs x by a fresh infinitesimal
// e, calls f, and extracts the coefficient of e from the result. A
// structured argument is perturbed one scalar leaf at a time, and the
// derivatives are arranged in the dual shape of the argument (the derivative
// of a function of an up tuple is a down tuple of partials); several
// arguments give a down tuple with one entry per argument. (partial i j ...)
// differentiates with respect to one component only: with several
// arguments, i chooses the argument and the rest of the path goes inside it.
#include <string>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/operator.hpp"
#include "algebra/series.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

// ---- derivatives -------------------------------------------------------------

// Copy of v with the component at path[k..] replaced by leaf.
Value replace_at(Value v, const gcvec<Value> &path, size_t k, Value leaf) {
  if (k == path.size()) return leaf;
  Structure *s = as_structure(v);
  size_t i = static_cast<size_t>(path[k].i);
  Value out = make_structure_from(s->up, s->items, s->len);
  as_structure(out)->items[i] = replace_at(s->items[i], path, k + 1, leaf);
  return out;
}

Value select_at(Value v, const gcvec<Value> &path, size_t k, const char *who) {
  for (; k < path.size(); ++k) {
    if (!is_structure(v)) bad_range(path[k], static_cast<int>(k + 1), who);
    size_t i = static_cast<size_t>(path[k].i);
    if (i >= as_structure(v)->len) bad_range(path[k], static_cast<int>(k + 1), who);
    v = as_structure(v)->items[i];
  }
  return v;
}

// The number of scalar leaves of x (numbers, symbolic values,
// differentials) if x is made of them alone, else 0.
size_t scalar_leaves(Value x) {
  if (is_structure(x)) {
    size_t n = 0;
    Structure *s = as_structure(x);
    for (size_t i = 0; i < s->len; ++i) {
      size_t k = scalar_leaves(s->items[i]);
      if (k == 0 && !(is_structure(s->items[i]) && as_structure(s->items[i])->len == 0)) return 0;
      n += k;
    }
    return n;
  }
  return is_number(x) || is_symbolic(x) || is_differential(x) ? 1 : 0;
}

// x with leaf k (depth first) plus e_(first + k).
Value perturb_leaves(Value x, uint32_t first, uint32_t &k) {
  if (!is_structure(x)) return add_infinitesimal(x, first + k++);
  Structure *s = as_structure(x);
  Value out = make_structure(s->up, s->len);
  for (size_t i = 0; i < s->len; ++i)
    as_structure(out)->items[i] = perturb_leaves(s->items[i], first, k);
  return out;
}

// The dual of x's shape (every orientation flipped) whose leaf k is the
// coefficient of e_(first + k) in r.
Value gradient_of(Value r, Value x, uint32_t first, uint32_t &k) {
  if (!is_structure(x)) return extract_tangent(r, first + k++);
  Structure *s = as_structure(x);
  Value out = make_structure(!s->up, s->len);
  for (size_t i = 0; i < s->len; ++i)
    as_structure(out)->items[i] = gradient_of(r, s->items[i], first, k);
  return out;
}

// d f(args) / d (component `path` of argument `arg`), where that component
// is the scalar or structure `x`: a structure gives its dual of partials,
// all from one evaluation of f when x is made of scalars (each perturbed by
// its own tag of one gradient group: differential.hpp).
Value derivative_at(Value f, gcvec<Value> args, size_t arg, gcvec<Value> path, Value x) {
  if (size_t n = is_structure(x) ? scalar_leaves(x) : 0; n >= 2) {
    uint32_t first = fresh_gradient_tags(static_cast<uint32_t>(n)), k = 0;
    args[arg] = replace_at(args[arg], path, 0, perturb_leaves(x, first, k));
    Value r = apply_procedure(f, args.data(), static_cast<int>(args.size()));
    k = 0;
    return gradient_of(r, x, first, k);
  }
  if (is_structure(x)) {
    Structure *s = as_structure(x);
    Value out = make_structure(!s->up, s->len);
    for (size_t i = 0; i < s->len; ++i) {
      gcvec<Value> sub = path;
      sub.push_back(Value::fixnum(static_cast<int64_t>(i)));
      as_structure(out)->items[i] = derivative_at(f, args, arg, sub, s->items[i]);
    }
    return out;
  }
  uint32_t e = fresh_differential_tag();
  args[arg] = replace_at(args[arg], path, 0, add_infinitesimal(x, e));
  Value r = apply_procedure(f, args.data(), static_cast<int>(args.size()));
  return extract_tangent(r, e);
}

// The procedure (D f) or ((partial path...) f): a = f, items = the path.
Value derivative_apply(NativeProc *self, Value *argv, int nargs) {
  Value f = self->a;
  gcvec<Value> args(argv, argv + nargs);
  gcvec<Value> path(self->items, self->items + self->nitems);
  if (path.empty()) {
    if (nargs == 1) return derivative_at(f, args, 0, {}, args[0]);
    Value out = make_structure(false, static_cast<size_t>(nargs));
    for (int i = 0; i < nargs; ++i)
      as_structure(out)->items[i] = derivative_at(f, args, static_cast<size_t>(i), {}, args[i]);
    return out;
  }
  size_t arg = 0;
  if (nargs > 1) {
    arg = static_cast<size_t>(path[0].i);
    if (arg >= static_cast<size_t>(nargs)) bad_range(path[0], 1, "partial");
    path.erase(path.begin());
  }
  Value x = select_at(args[arg], path, 0, "partial");
  return derivative_at(f, args, arg, path, x);
}

// ---- operators ---------------------------------------------------------------

enum class OperatorKind {
  Derivative,
  Compose,
  Sum,
  Scale,
  Identity,
  Exp,    // (exp x): applied to f, the series sum_k x^k f / k!
  Custom, // made by make-operator from a procedure on functions
};

struct Operator {
  OperatorKind kind;
  Value name;  // the datum it prints as: D, (partial 0), (expt D 2), ...
  Value a, b;  // Compose: a after b; Sum: a + b; Scale: coefficient a, operator b
  Value *path; // Derivative: the partial path (fixnums)
  size_t npath;
};

void write_operator(std::string &out, const void *obj, bool display) {
  print_value(out, static_cast<const Operator *>(obj)->name, display);
}

Value operator_apply(void *obj, Value *args, int nargs);
const OpaqueKind kOperatorKind = {"operator", write_operator, operator_apply};

Operator *as_operator(Value v) {
  return static_cast<Operator *>(v.as<Opaque>()->obj);
}

Value make_operator(OperatorKind kind, Value name, Value a, Value b) {
  Operator *op = gc_new<Operator>(Operator{kind, name, a, b, nullptr, 0});
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kOperatorKind, op}));
}

Value make_derivative(const gcvec<Value> &path) {
  Value name =
      path.empty() ? intern("D") : cons(intern("partial"), list_from(path.data(), path.size()));
  Value op = make_operator(OperatorKind::Derivative, name, Value(), Value());
  Operator *o = as_operator(op);
  o->npath = path.size();
  o->path = static_cast<Value *>(GC_MALLOC(sizeof(Value) * (path.size() + 1)));
  std::copy(path.begin(), path.end(), o->path);
  return op;
}

Value operator_apply(void *obj, Value *args, int nargs) {
  Value self = Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kOperatorKind, obj}));
  if (nargs != 1)
    runtime_error(current_call_loc(), "The operator " + write_string(self) +
                                          " has been called with " + std::to_string(nargs) +
                                          " arguments; it requires exactly 1 argument.");
  return apply_operator(self, args[0]);
}

Value compose(Value a, Value b);

Value operator_unary(UnaryOp op, Value x) {
  if (op == UnaryOp::Neg)
    return make_operator(OperatorKind::Scale, list({intern("-"), as_operator(x)->name}),
                         Value::fixnum(-1), x);
  if (op == UnaryOp::Square) return compose(x, x);
  if (op == UnaryOp::Cube) return compose(x, compose(x, x));
  if (op == UnaryOp::Exp)
    return make_operator(OperatorKind::Exp, list({intern("exp"), as_operator(x)->name}), x,
                         Value());
  arith_wrong_type(op, x);
}

Value scale(Value c, Value op) {
  return make_operator(OperatorKind::Scale, list({intern("*"), c, as_operator(op)->name}), c, op);
}

Value compose(Value a, Value b) {
  return make_operator(OperatorKind::Compose,
                       list({intern("*"), as_operator(a)->name, as_operator(b)->name}), a, b);
}

Value identity_operator() {
  return make_operator(OperatorKind::Identity, intern("I"), Value(), Value());
}

// (expt op n): op composed with itself n times, printed (expt D n).
Value operator_power(Value op, Value n) {
  auto k = to_int64(n);
  if (!k || *k < 0) arith_wrong_type(BinaryOp::Expt, n, 2);
  Value result = identity_operator();
  for (int64_t i = 0; i < *k; ++i)
    result = i == 0 ? op : compose(op, result);
  if (*k > 1) as_operator(result)->name = list({intern("expt"), as_operator(op)->name, n});
  return result;
}

Value as_operator_term(Value v) {
  return is_operator(v) ? v : scale(v, identity_operator());
}

Value operator_binary(BinaryOp op, Value a, Value b) {
  bool oa = is_operator(a), ob = is_operator(b);
  switch (op) {
  case BinaryOp::Mul:
    if (oa && ob) return compose(a, b);
    if (ob && is_arithmetic(a) && !is_procedure(a)) return scale(a, b);
    if (oa && is_arithmetic(b) && !is_procedure(b)) return scale(b, a);
    break;
  case BinaryOp::Div:
    if (oa && !ob && is_arithmetic(b) && !is_procedure(b))
      return scale(g_unary(UnaryOp::Invert, b), a);
    break;
  case BinaryOp::Add:
  case BinaryOp::Sub: {
    // Operators add to operators and to numbers or symbols (multiples of
    // the identity operator), not to other procedures.
    auto addable = [](Value v) { return is_operator(v) || (is_arithmetic(v) && !is_procedure(v)); };
    if (!addable(a) || !addable(b)) break;
    Value x = as_operator_term(a), y = as_operator_term(b);
    if (op == BinaryOp::Sub) y = scale(Value::fixnum(-1), y);
    return make_operator(OperatorKind::Sum,
                         list({intern(op == BinaryOp::Add ? "+" : "-"),
                               oa ? as_operator(a)->name : a, ob ? as_operator(b)->name : b}),
                         x, y);
  }
  case BinaryOp::Expt:
    if (oa && !ob) return operator_power(a, b);
    break;
  default: break;
  }
  arith_wrong_type(op, oa ? b : a, oa ? 2 : 1);
}

bool operator_member(Value v) {
  return is_operator(v);
}
const ArithType kOperatorArith = {"operator", 40, operator_member, operator_unary, operator_binary};

// ---- primitives ----------------------------------------------------------------

Value P_partial(Value *a, int n) {
  gcvec<Value> path;
  for (int i = 0; i < n; ++i) {
    arg_index(a, i, "partial");
    path.push_back(a[i]);
  }
  return make_derivative(path);
}

Value P_operator_p(Value *a, int) {
  return Value::boolean(is_operator(a[0]));
}

// (make-operator procedure [name]): an operator from a procedure that maps
// functions to functions, so that operator arithmetic (and exp) apply to it.
Value P_make_operator(Value *a, int n) {
  if (!is_procedure(a[0])) wrong_type(a[0], 1, "make-operator");
  return make_operator(OperatorKind::Custom, n > 1 ? a[1] : intern("operator"), a[0], Value());
}

} // namespace

bool is_operator(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kOperatorKind;
}

bool is_derivative_multiple(Value op, Value *c) {
  if (!is_operator(op)) return false;
  Operator *o = as_operator(op);
  if (o->kind == OperatorKind::Derivative && o->npath == 0) {
    *c = Value::fixnum(1);
    return true;
  }
  Value inner;
  if (o->kind == OperatorKind::Scale && !is_operator(o->a) &&
      is_derivative_multiple(o->b, &inner)) {
    *c = g_mul(o->a, inner);
    return true;
  }
  return false;
}

Value derivative_of(Value f, const std::vector<int> &path) {
  gcvec<Value> items;
  for (int i : path)
    items.push_back(Value::fixnum(i));
  return make_native_procedure(derivative_apply, 0, f, Value::unspecified(), items.data(),
                               items.size());
}

Value apply_operator(Value opv, Value f) {
  Operator *op = as_operator(opv);
  switch (op->kind) {
  case OperatorKind::Derivative: {
    std::vector<int> path;
    for (size_t i = 0; i < op->npath; ++i)
      path.push_back(static_cast<int>(op->path[i].i));
    return derivative_of(f, path);
  }
  case OperatorKind::Compose: return apply_operator(op->a, apply_operator(op->b, f));
  case OperatorKind::Sum: return g_add(apply_operator(op->a, f), apply_operator(op->b, f));
  case OperatorKind::Scale: return g_mul(op->a, apply_operator(op->b, f));
  case OperatorKind::Identity: return f;
  case OperatorKind::Exp: return make_exp_series(op->a, f);
  case OperatorKind::Custom: return apply_procedure(op->a, &f, 1);
  }
  internal_failure(__FILE__, __LINE__, "unknown operator kind");
}

void install_operator_primitives() {
  register_arith_type(&kOperatorArith);
  define_global("D", make_derivative({}));
  define_primitive("partial", 1, kVariadic, Stage::Pure, P_partial);
  // scmutils's procedure form of D, made an operator as well, so that
  // operator arithmetic applies: (square derivative) is the second derivative.
  Value derivative = make_derivative({});
  as_operator(derivative)->name = intern("derivative");
  define_global("derivative", derivative);
  define_primitive("operator?", 1, 1, Stage::Pure, P_operator_p);
  define_primitive("make-operator", 1, 2, Stage::Pure, P_make_operator);
  define_global("I", identity_operator());
}

} // namespace sicm
