// Literal functions: named unknown functions whose applications are
// expressions, (f t), and whose derivatives are literal functions too.
//
// A literal function carries its type, (-> DOMAIN RANGE): DOMAIN is Real,
// (X Real Real ...) for several arguments, or (UP ...)/(DOWN ...) for one
// structured argument; RANGE is Real or a structure type, in which case the
// value is a structure of component functions named f^0, f^1, ...
//
// Applied to arguments carrying an infinitesimal e (inside D), it applies the
// chain rule itself: f(a0 + a1·e) = f(a0) + Σ ∂_i f(a0)·a1_i·e over every
// scalar component i of the arguments, where ∂_i f is the literal function
// ((partial i ...) f), or (D f) for a function of one real argument, whose
// own derivative is ((expt D 2) f), and so on.
#include <array>
#include <string>

#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "algebra/operator.hpp"
#include "algebra/structure.hpp"
#include "algebra/symbolic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "eval/procedure.hpp"
#include "print/printer.hpp"

namespace sicm {

namespace {

struct LiteralFunction {
  Value base;   // the symbol it was made from
  Value head;   // what it prints as in applications: f, (D f), ((partial 0) f)
  Value domain; // Real, (X ...), (UP ...) or (DOWN ...)
  Value range;  // Real (structure-valued ones are structures of literal functions)
  int order;    // for one real argument: how many times D was applied
  Value *path;  // for partials: the path so far (fixnums); GC memory
  size_t npath;
};

Value literal_apply(void *obj, Value *args, int nargs);
void write_literal(std::string &out, const void *obj, bool display) {
  print_value(out, expression_to_datum(static_cast<const LiteralFunction *>(obj)->head), display);
}
const OpaqueKind kLiteralKind = {"literal-function", write_literal, literal_apply};

bool is_symbol_named(Value v, const char *name) {
  return is_symbol(v) && symbol_name(v) == name;
}

// Number of arguments the domain type takes.
size_t domain_arity(Value domain) {
  if (is_pair(domain) && is_symbol_named(car(domain), "X"))
    return static_cast<size_t>(list_length(cdr(domain)));
  return 1;
}

bool real_domain(Value domain) {
  return is_symbol_named(domain, "Real");
}

Value wrap(LiteralFunction *lf) {
  return Value::object(Tag::Opaque, gc_new<Opaque>(Opaque{&kLiteralKind, lf}));
}

// The literal function ∂f/∂(component `path` of the arguments).
Value literal_partial(LiteralFunction *f, const gcvec<Value> &path) {
  LiteralFunction *d = gc_new<LiteralFunction>(*f);
  if (real_domain(f->domain)) {
    d->order = f->order + 1;
    Value D = intern("D");
    Value op =
        d->order == 1
            ? D
            : symbolic_apply(Op::Expt, std::array<Value, 2>{D, Value::fixnum(d->order)}.data(), 2);
    d->head = symbolic_call(op, &f->base, 1);
    return wrap(d);
  }
  Value partial = symbolic_call(intern("partial"), path.data(), static_cast<int>(path.size()));
  d->head = symbolic_call(partial, &f->head, 1);
  d->order = 0;
  return wrap(d);
}

// Σ over scalar leaves of `tangent` (a component of argument `arg`, at
// `path`) of ∂f/∂leaf (at the finite arguments) times the leaf's tangent.
Value chain_sum(LiteralFunction *f, const gcvec<Value> &finite, bool several, size_t arg,
                gcvec<Value> path, Value tangent) {
  if (is_structure(tangent)) {
    Value sum = Value::fixnum(0);
    Structure *s = as_structure(tangent);
    for (size_t i = 0; i < s->len; ++i) {
      gcvec<Value> sub = path;
      sub.push_back(Value::fixnum(static_cast<int64_t>(i)));
      sum = g_add(sum, chain_sum(f, finite, several, arg, sub, s->items[i]));
    }
    return sum;
  }
  if (is_exact_zero(tangent)) return Value::fixnum(0);
  gcvec<Value> full;
  if (several) full.push_back(Value::fixnum(static_cast<int64_t>(arg)));
  full.insert(full.end(), path.begin(), path.end());
  Value partial = literal_partial(f, full);
  Value at =
      apply_procedure(partial, const_cast<Value *>(finite.data()), static_cast<int>(finite.size()));
  return g_mul(at, tangent);
}

Value literal_apply(void *obj, Value *args, int nargs) {
  LiteralFunction *f = static_cast<LiteralFunction *>(obj);
  size_t arity = domain_arity(f->domain);
  if (static_cast<size_t>(nargs) != arity)
    runtime_error(current_call_loc(), "The procedure " + write_string(wrap(f)) +
                                          " has been called with " + std::to_string(nargs) +
                                          " argument" + (nargs == 1 ? "" : "s") +
                                          "; it requires exactly " + std::to_string(arity) +
                                          " argument" + (arity == 1 ? "" : "s") + ".");
  uint32_t e = 0;
  for (int i = 0; i < nargs; ++i)
    e = std::max(e, max_differential_tag(args[i]));
  if (e == 0) return symbolic_call(f->head, args, nargs);
  gcvec<Value> finite(static_cast<size_t>(nargs)), tangent(static_cast<size_t>(nargs));
  for (int i = 0; i < nargs; ++i)
    split_differential(args[i], e, &finite[i], &tangent[i]);
  Value value = literal_apply(obj, finite.data(), nargs);
  Value slope = Value::fixnum(0);
  for (int i = 0; i < nargs; ++i)
    slope = g_add(slope, chain_sum(f, finite, nargs > 1, static_cast<size_t>(i), {}, tangent[i]));
  return g_add(value, times_infinitesimal(slope, e));
}

bool structure_type(Value range) {
  return is_pair(range) &&
         (is_symbol_named(car(range), "UP") || is_symbol_named(car(range), "DOWN"));
}

// A literal function named `name` from `domain` to `range`. As in scmutils,
// one whose values are structures is a structure of literal functions, one
// per component, named with the component's index: ^i for up, _i for down
// (q^0, q^1; C^1^0, C^2_0 for nested structures), so that D, Gamma and
// Lagrange-equations treat each component as a function of its own.
Value literal_function_of(Value name, Value domain, Value range) {
  if (structure_type(range)) {
    bool up = is_symbol_named(car(range), "UP");
    long n = list_length(cdr(range));
    Value out = make_structure(up, static_cast<size_t>(n));
    Value component = cdr(range);
    for (long i = 0; i < n; ++i, component = cdr(component)) {
      Value sub = intern(symbol_name(name) + (up ? "^" : "_") + std::to_string(i));
      as_structure(out)->items[i] = literal_function_of(sub, domain, car(component));
    }
    return out;
  }
  LiteralFunction *lf = gc_new<LiteralFunction>();
  lf->base = name;
  lf->head = name;
  lf->domain = domain;
  lf->range = range;
  lf->order = 0;
  return wrap(lf);
}

// (literal-function 'f [type])
Value P_literal_function(Value *a, int n) {
  if (!is_symbol(a[0])) wrong_type(a[0], 1, "literal-function");
  Value type = n > 1 ? a[1] : list({intern("->"), intern("Real"), intern("Real")});
  if (list_length(type) != 3 || !is_symbol_named(car(type), "->"))
    wrong_type(type, 2, "literal-function");
  Value range = car(cdr(cdr(type)));
  for (Value r = structure_type(range) ? cdr(range) : Value::nil(); is_pair(r); r = cdr(r))
    if (!is_symbol_named(car(r), "Real") && !structure_type(car(r)))
      wrong_type(type, 2, "literal-function");
  return literal_function_of(a[0], car(cdr(type)), range);
}

Value P_literal_function_p(Value *a, int) {
  return Value::boolean(is_literal_function(a[0]));
}

} // namespace

bool is_literal_function(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kLiteralKind;
}

Value make_literal_function(Value name, Value type) {
  Value args[2] = {name, type};
  return P_literal_function(args, type.is(Tag::Unspecified) ? 1 : 2);
}

void install_literal_function_primitives() {
  define_primitive("literal-function", 1, 2, Stage::Pure, P_literal_function);
  define_primitive("literal-function?", 1, 1, Stage::Pure, P_literal_function_p);
}

} // namespace sicm
