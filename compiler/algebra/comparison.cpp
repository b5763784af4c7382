// Comparisons through differentials: <, >, <=, >=, positive?, negative?, max
// and min compare the finite parts of differential objects, so a function
// that tests its argument (a piecewise potential, (max x 0)) has a
// derivative wherever the test does not change.
//
// scmutils' rule (kernel/diff.scm, diff:binary-comparator): a comparison
// with a differential compares the finite parts, so (< x 0) of x + dx is
// (< x 0). scmutils extends =, <, <=, > and >= so; positive? and negative?
// here mean (> x 0) and (< x 0), and max and min choose the argument whose
// finite part MIT's max and min choose, the whole differential, with MIT's
// rule that an inexact argument makes the result inexact applied to its
// finite part. Everything else is MIT's: the comparisons of numbers are the
// number primitives installed before these (builtins/number.cpp), called on
// the finite parts, so errors name the same procedures (a symbol compared is
// "passed as the first argument to integer-less?"). = and zero? are generic
// arithmetic's (algebra/generic.cpp, differential.cpp).
#include "algebra/differential.hpp"
#include "algebra/generic.hpp"
#include "base/error.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"

namespace sicm {

namespace {

// The number primitives these extend, by name, as bound when installed.
struct Extended {
  const char *name;
  PrimFn numbers = nullptr;
};

Extended g_less{"<"}, g_greater{">"}, g_less_eq{"<="}, g_greater_eq{">="}, g_positive{"positive?"},
    g_negative{"negative?"}, g_max{"max"}, g_min{"min"};

bool any_differential(Value *args, int n) {
  for (int i = 0; i < n; ++i)
    if (is_differential(args[i])) return true;
  return false;
}

// The numbers' primitive on the finite parts of the arguments.
template <Extended *E> Value compare_finite_parts(Value *args, int n) {
  if (!any_differential(args, n)) return E->numbers(args, n);
  gcvec<Value> finite(args, args + n);
  for (Value &v : finite)
    v = differential_finite_part(v);
  return E->numbers(finite.data(), n);
}

// max or min: the argument whose finite part the numbers' primitive chose
// (the first of equal ones, as MIT keeps the first), inexact if any is.
template <Extended *E> Value choose_by_finite_parts(Value *args, int n) {
  if (!any_differential(args, n)) return E->numbers(args, n);
  gcvec<Value> finite(args, args + n);
  for (Value &v : finite)
    v = differential_finite_part(v);
  Value chosen = E->numbers(finite.data(), n);
  for (int i = 0; i < n; ++i) {
    if (num_compare(finite[i], chosen) != 0) continue;
    if (!is_differential(args[i])) return chosen;
    return chosen.is(Tag::Flonum) && !finite[i].is(Tag::Flonum) ? with_finite_part(args[i], chosen)
                                                                : args[i];
  }
  return chosen; // a NaN: no differential is chosen
}

void extend(Extended *e, int min_args, int max_args, PrimFn fn) {
  Symbol *s = intern(e->name).symbol();
  SICM_ASSERT(s->bound && s->global.is(Tag::Primitive));
  e->numbers = s->global.as<Primitive>()->fn;
  define_primitive(e->name, min_args, max_args, Stage::Pure, fn);
}

} // namespace

void install_differential_comparisons() {
  extend(&g_less, 1, kVariadic, compare_finite_parts<&g_less>);
  extend(&g_greater, 1, kVariadic, compare_finite_parts<&g_greater>);
  extend(&g_less_eq, 1, kVariadic, compare_finite_parts<&g_less_eq>);
  extend(&g_greater_eq, 1, kVariadic, compare_finite_parts<&g_greater_eq>);
  extend(&g_positive, 1, 1, compare_finite_parts<&g_positive>);
  extend(&g_negative, 1, 1, compare_finite_parts<&g_negative>);
  extend(&g_max, 1, kVariadic, choose_by_finite_parts<&g_max>);
  extend(&g_min, 1, kVariadic, choose_by_finite_parts<&g_min>);
}

} // namespace sicm
