// Vector primitives, with MIT Scheme's names, semantics and errors.
#include <algorithm>
#include <cstdint>
#include <utility>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "eval/effect_guard.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {

bool supplied(Value *args, int nargs, int i) {
  return i < nargs && !args[i].is(Tag::Default);
}

Vector *arg_vector(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Vector)) wrong_type(args[i], i + 1, who);
  return args[i].vector();
}

// A length: MIT's guarantee of an index-fixnum reports a wrong type. Absurd
// sizes are refused as out of range rather than exhausting memory.
size_t arg_size(Value *args, int i, const char *who) {
  if (!args[i].is(Tag::Fixnum) || args[i].i < 0) wrong_type(args[i], i + 1, who);
  if (args[i].i > (int64_t{1} << 27)) bad_range(args[i], i + 1, who);
  return static_cast<size_t>(args[i].i);
}

// An element index of v: in [0, len).
size_t arg_element(Value *args, int i, Vector *v, const char *who) {
  if (!args[i].is(Tag::Fixnum)) wrong_type(args[i], i + 1, who);
  if (args[i].i < 0 || static_cast<size_t>(args[i].i) >= v->len) bad_range(args[i], i + 1, who);
  return static_cast<size_t>(args[i].i);
}

// Optional [start, end) arguments at positions i and i+1, checked as MIT does:
// end against the length first, then start against end.
std::pair<size_t, size_t> arg_span(Value *args, int nargs, int i, size_t len, const char *who) {
  size_t end = supplied(args, nargs, i + 1) ? arg_bounded(args, i + 1, 0, len, who) : len;
  size_t start = supplied(args, nargs, i) ? arg_bounded(args, i, 0, end, who) : 0;
  return {start, end};
}

Value slice(Vector *v, size_t start, size_t end) {
  Value out = make_vector(end - start, Value::boolean(false));
  for (size_t i = start; i < end; ++i)
    out.vector()->items[i - start] = v->items[i];
  return out;
}

Value list_of(Vector *v, size_t start, size_t end) {
  return list_from(v->items + start, end - start);
}

// Shared by vector-map and vector-for-each: the vectors are checked before any
// call, and iteration stops at the shortest one, as in R7RS.
size_t shortest(Value *args, int nargs, const char *who) {
  size_t n = SIZE_MAX;
  for (int i = 1; i < nargs; ++i)
    n = std::min(n, arg_vector(args, i, who)->len);
  return n;
}

Value map_or_for_each(Value *args, int nargs, bool collect, const char *who) {
  size_t n = shortest(args, nargs, who);
  Value result = collect ? make_vector(n, Value::boolean(false)) : Value::unspecified();
  gcvec<Value> call(static_cast<size_t>(nargs - 1));
  for (size_t k = 0; k < n; ++k) {
    for (int i = 1; i < nargs; ++i)
      call[i - 1] = args[i].vector()->items[k];
    Value v = apply_procedure(args[0], call.data(), nargs - 1);
    if (collect) result.vector()->items[k] = v;
  }
  return result;
}

void install_basics() {
  define_primitive("vector?", 1, 1, Stage::Pure,
                   [](Value *a, int) { return Value::boolean(a[0].is(Tag::Vector)); });
  // MIT fills with #f when no fill is given.
  define_primitive("make-vector", 1, 2, Stage::Pure, [](Value *a, int n) {
    size_t len = arg_size(a, 0, "make-vector");
    return make_vector(len, supplied(a, n, 1) ? a[1] : Value::boolean(false));
  });
  define_primitive("vector", 0, kVariadic, Stage::Pure, [](Value *a, int n) {
    Value v = make_vector(static_cast<size_t>(n), Value::boolean(false));
    for (int i = 0; i < n; ++i)
      v.vector()->items[i] = a[i];
    return v;
  });
  define_primitive("vector-length", 1, 1, Stage::Pure, [](Value *a, int) {
    return Value::fixnum(static_cast<int64_t>(arg_vector(a, 0, "vector-length")->len));
  });
  define_primitive("vector-ref", 2, 2, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-ref");
    return v->items[arg_element(a, 1, v, "vector-ref")];
  });
  define_primitive("vector-set!", 3, 3, Stage::Effect, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-set!");
    refuse_change_of(a[0], "vector-set!");
    v->items[arg_element(a, 1, v, "vector-set!")] = a[2];
    return Value::unspecified();
  });
  define_primitive("vector-first", 1, 1, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-first");
    if (v->len == 0) wrong_type(a[0], 1, "vector-first");
    return v->items[0];
  });
  define_primitive("vector-last", 1, 1, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-last");
    if (v->len == 0) wrong_type(a[0], 1, "vector-last");
    return v->items[v->len - 1];
  });
}

void install_conversions() {
  define_primitive("vector->list", 1, 3, Stage::Pure, [](Value *a, int n) {
    Vector *v = arg_vector(a, 0, "vector->list");
    auto [start, end] = arg_span(a, n, 1, v->len, "vector->list");
    return list_of(v, start, end);
  });
  define_primitive("subvector->list", 3, 3, Stage::Pure, [](Value *a, int n) {
    Vector *v = arg_vector(a, 0, "subvector->list");
    auto [start, end] = arg_span(a, n, 1, v->len, "subvector->list");
    return list_of(v, start, end);
  });
  define_primitive("list->vector", 1, 1, Stage::Pure, [](Value *a, int) {
    long len = list_length(a[0]);
    if (len < 0) wrong_type(a[0], 1, "list->vector");
    Value v = make_vector(static_cast<size_t>(len), Value::boolean(false));
    size_t i = 0;
    for (Value p = a[0]; is_pair(p); p = cdr(p))
      v.vector()->items[i++] = car(p);
    return v;
  });
}

void install_slices() {
  define_primitive("subvector", 3, 3, Stage::Pure, [](Value *a, int n) {
    Vector *v = arg_vector(a, 0, "subvector");
    auto [start, end] = arg_span(a, n, 1, v->len, "subvector");
    return slice(v, start, end);
  });
  define_primitive("vector-head", 2, 2, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-head");
    return slice(v, 0, arg_bounded(a, 1, 0, v->len, "vector-head"));
  });
  define_primitive("vector-tail", 2, 2, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-tail");
    return slice(v, arg_bounded(a, 1, 0, v->len, "vector-tail"), v->len);
  });
  define_primitive("vector-copy", 1, 3, Stage::Pure, [](Value *a, int n) {
    Vector *v = arg_vector(a, 0, "vector-copy");
    auto [start, end] = arg_span(a, n, 1, v->len, "vector-copy");
    return slice(v, start, end);
  });
  // (vector-copy! to at from [start end]), R7RS; overlapping ranges are safe.
  define_primitive("vector-copy!", 3, 5, Stage::Effect, [](Value *a, int n) {
    Vector *to = arg_vector(a, 0, "vector-copy!");
    refuse_change_of(a[0], "vector-copy!");
    size_t at = arg_bounded(a, 1, 0, to->len, "vector-copy!");
    Vector *from = arg_vector(a, 2, "vector-copy!");
    auto [start, end] = arg_span(a, n, 3, from->len, "vector-copy!");
    if (end - start > to->len - at) bad_range(a[2], 3, "vector-copy!");
    if (at <= start) {
      for (size_t i = start; i < end; ++i)
        to->items[at + i - start] = from->items[i];
    } else {
      for (size_t i = end; i-- > start;)
        to->items[at + i - start] = from->items[i];
    }
    return Value::unspecified();
  });
  define_primitive("vector-append", 0, kVariadic, Stage::Pure, [](Value *a, int n) {
    size_t total = 0;
    for (int i = 0; i < n; ++i)
      total += arg_vector(a, i, "vector-append")->len;
    Value out = make_vector(total, Value::boolean(false));
    size_t k = 0;
    for (int i = 0; i < n; ++i)
      for (size_t j = 0; j < a[i].vector()->len; ++j)
        out.vector()->items[k++] = a[i].vector()->items[j];
    return out;
  });
  // (vector-grow v n): a longer copy; MIT leaves the new slots unassigned, we use #f.
  define_primitive("vector-grow", 2, 2, Stage::Pure, [](Value *a, int) {
    Vector *v = arg_vector(a, 0, "vector-grow");
    size_t len = arg_size(a, 1, "vector-grow");
    if (len < v->len) bad_range(a[1], 2, "vector-grow");
    Value out = make_vector(len, Value::boolean(false));
    for (size_t i = 0; i < v->len; ++i)
      out.vector()->items[i] = v->items[i];
    return out;
  });
  define_primitive("vector-fill!", 2, 4, Stage::Effect, [](Value *a, int n) {
    Vector *v = arg_vector(a, 0, "vector-fill!");
    refuse_change_of(a[0], "vector-fill!");
    auto [start, end] = arg_span(a, n, 2, v->len, "vector-fill!");
    for (size_t i = start; i < end; ++i)
      v->items[i] = a[1];
    return Value::unspecified();
  });
}

void install_higher_order() {
  define_primitive("vector-map", 2, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return map_or_for_each(a, n, true, "vector-map"); });
  define_primitive("vector-for-each", 2, kVariadic, Stage::Pure,
                   [](Value *a, int n) { return map_or_for_each(a, n, false, "vector-for-each"); });
  // (make-initialized-vector n proc): element i is (proc i).
  define_primitive("make-initialized-vector", 2, 2, Stage::Pure, [](Value *a, int) {
    size_t len = arg_size(a, 0, "make-initialized-vector");
    Value out = make_vector(len, Value::boolean(false));
    for (size_t i = 0; i < len; ++i) {
      Value index = Value::fixnum(static_cast<int64_t>(i));
      out.vector()->items[i] = apply_procedure(a[1], &index, 1);
    }
    return out;
  });
  // (vector-binary-search v key key-compare): v is sorted, (key-compare key
  // element) is negative, zero or positive; the matching element or #f.
  define_primitive("vector-binary-search", 3, 3, Stage::Pure, [](Value *a, int) {
    arg_vector(a, 0, "vector-binary-search");
    size_t low = 0, high = a[0].vector()->len; // search [low, high)
    while (low < high) {
      size_t mid = low + (high - low) / 2;
      Value call[2] = {a[1], a[0].vector()->items[mid]};
      Value c = apply_procedure(a[2], call, 2);
      // MIT compares the answer with <, which names its integer primitive.
      if (!is_number(c)) wrong_type(c, 1, "integer-less?");
      int sign = num_sign(c);
      if (sign == 0) return call[1];
      if (sign < 0)
        high = mid;
      else
        low = mid + 1;
    }
    return Value::boolean(false);
  });
}

} // namespace

void install_vector_primitives() {
  install_basics();
  install_conversions();
  install_slices();
  install_higher_order();
}

} // namespace sicm
