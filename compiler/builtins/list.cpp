// List primitives: pairs, the MIT list library the book uses, higher-order
// procedures (map, for-each, reduce, folds, sort) and streams.
#include <algorithm>
#include <cstdint>

#include "base/number.hpp"
#include "base/primitive.hpp"
#include "builtins/builtins.hpp"
#include "eval/captured_assignment.hpp"
#include "eval/core.hpp"
#include "eval/effect_guard.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {

Value require_pair(Value *a, int i, const char *who) {
  if (!is_pair(a[i])) wrong_type(a[i], i + 1, who);
  return a[i];
}

long require_list(Value *a, int i, const char *who) {
  long n = list_length(a[i]);
  if (n < 0) wrong_type(a[i], i + 1, who);
  return n;
}

Value P_cons(Value *a, int) {
  return cons(a[0], a[1]);
}
Value P_car(Value *a, int) {
  return car(require_pair(a, 0, "car"));
}
Value P_cdr(Value *a, int) {
  return cdr(require_pair(a, 0, "cdr"));
}
Value P_set_car(Value *a, int) {
  refuse_change_of(require_pair(a, 0, "set-car!"), "set-car!");
  a[0].pair()->car = a[1];
  return Value::unspecified();
}
Value P_set_cdr(Value *a, int) {
  refuse_change_of(require_pair(a, 0, "set-cdr!"), "set-cdr!");
  a[0].pair()->cdr = a[1];
  return Value::unspecified();
}

// c[ad]+r accessors: the path is read right to left, as the name says.
template <const char *Name> Value cxr(Value *a, int) {
  Value v = a[0];
  const char *path = Name + 1;
  size_t len = std::char_traits<char>::length(path) - 1; // drop the final 'r'
  for (size_t i = len; i-- > 0;) {
    if (!is_pair(v)) wrong_type(a[0], 1, Name);
    v = path[i] == 'a' ? car(v) : cdr(v);
  }
  return v;
}
constexpr char kCaar[] = "caar", kCadr[] = "cadr", kCdar[] = "cdar", kCddr[] = "cddr",
               kCaaar[] = "caaar", kCaadr[] = "caadr", kCadar[] = "cadar", kCaddr[] = "caddr",
               kCdaar[] = "cdaar", kCdadr[] = "cdadr", kCddar[] = "cddar", kCdddr[] = "cdddr",
               kCadddr[] = "cadddr", kCddddr[] = "cddddr";

Value P_pair_p(Value *a, int) {
  return Value::boolean(is_pair(a[0]));
}
Value P_null_p(Value *a, int) {
  return Value::boolean(is_null(a[0]));
}
Value P_list_p(Value *a, int) {
  return Value::boolean(list_length(a[0]) >= 0);
}
Value P_list(Value *a, int n) {
  return list_from(a, static_cast<size_t>(n));
}
Value P_cons_star(Value *a, int n) {
  return list_from(a, static_cast<size_t>(n - 1), a[n - 1]);
}
Value P_make_list(Value *a, int n) {
  size_t k = arg_index(a, 0, "make-list");
  Value fill = n > 1 ? a[1] : Value::unspecified();
  Value r = Value::nil();
  for (size_t i = 0; i < k; ++i)
    r = cons(fill, r);
  return r;
}
Value P_length(Value *a, int) {
  return Value::fixnum(require_list(a, 0, "length"));
}

Value P_append(Value *a, int n) {
  if (n == 0) return Value::nil();
  Value result = a[n - 1];
  for (int i = n - 1; i-- > 0;) {
    require_list(a, i, "append");
    gcvec<Value> items = list_to_vector(a[i]);
    result = list_from(items.data(), items.size(), result);
  }
  return result;
}

Value P_append_bang(Value *a, int n) {
  Value result = Value::nil();
  Value last = Value::nil();
  for (int i = 0; i < n; ++i) {
    if (is_null(a[i])) continue;
    if (is_null(result)) {
      result = a[i];
    } else {
      Value p = last;
      while (is_pair(cdr(p)))
        p = cdr(p);
      refuse_change_of(p, "append!");
      p.pair()->cdr = a[i];
    }
    last = a[i];
  }
  return result;
}

Value P_reverse(Value *a, int) {
  require_list(a, 0, "reverse");
  Value r = Value::nil();
  for (Value p = a[0]; is_pair(p); p = cdr(p))
    r = cons(car(p), r);
  return r;
}

Value P_list_tail(Value *a, int) {
  size_t k = arg_index(a, 1, "list-tail");
  Value p = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(p)) bad_range(a[1], 2, "list-tail");
    p = cdr(p);
  }
  return p;
}

Value P_list_head(Value *a, int) {
  size_t k = arg_index(a, 1, "list-head");
  gcvec<Value> items;
  Value p = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(p)) bad_range(a[1], 2, "list-head");
    items.push_back(car(p));
    p = cdr(p);
  }
  return list_from(items.data(), items.size());
}

Value P_sublist(Value *a, int) {
  long n = require_list(a, 0, "sublist");
  size_t s = arg_index(a, 1, "sublist"), e = arg_index(a, 2, "sublist");
  if (e > static_cast<size_t>(n)) bad_range(a[2], 3, "sublist");
  if (s > e) bad_range(a[1], 2, "sublist");
  gcvec<Value> items = list_to_vector(a[0]);
  return list_from(items.data() + s, e - s);
}

Value P_list_ref(Value *a, int) {
  size_t k = arg_index(a, 1, "list-ref");
  Value p = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(p)) bad_range(a[1], 2, "list-ref");
    p = cdr(p);
  }
  if (!is_pair(p)) bad_range(a[1], 2, "list-ref");
  return car(p);
}

Value P_last_pair(Value *a, int) {
  Value p = require_pair(a, 0, "last-pair");
  while (is_pair(cdr(p)))
    p = cdr(p);
  return p;
}

Value P_last(Value *a, int) {
  Value p = require_pair(a, 0, "last");
  while (is_pair(cdr(p)))
    p = cdr(p);
  return car(p);
}

Value P_except_last_pair(Value *a, int) {
  require_pair(a, 0, "except-last-pair!");
  gcvec<Value> items = list_to_vector(a[0]);
  return list_from(items.data(), items.size() - 1);
}

template <int N> Value nth(Value *a, int) {
  static const char *const names[] = {"first", "second",  "third",  "fourth", "fifth",
                                      "sixth", "seventh", "eighth", "ninth",  "tenth"};
  Value p = a[0];
  for (int i = 0; i < N; ++i) {
    if (!is_pair(p)) wrong_type(a[0], 1, names[N]);
    p = cdr(p);
  }
  if (!is_pair(p)) wrong_type(a[0], 1, names[N]);
  return car(p);
}

Value P_list_copy(Value *a, int) {
  gcvec<Value> items;
  Value p = a[0];
  for (; is_pair(p); p = cdr(p))
    items.push_back(car(p));
  return list_from(items.data(), items.size(), p);
}

template <bool (*Same)(Value, Value)> Value member_generic(Value x, Value list) {
  for (Value p = list; is_pair(p); p = cdr(p))
    if (Same(x, car(p))) return p;
  return Value::boolean(false);
}
Value P_memq(Value *a, int) {
  return member_generic<eq>(a[0], a[1]);
}
Value P_memv(Value *a, int) {
  return member_generic<eqv>(a[0], a[1]);
}
Value P_member(Value *a, int n) {
  if (n < 3) return member_generic<equal>(a[0], a[1]);
  for (Value p = a[1]; is_pair(p); p = cdr(p)) {
    Value args[2] = {a[0], car(p)};
    if (apply_procedure(a[2], args, 2).truthy()) return p;
  }
  return Value::boolean(false);
}

template <bool (*Same)(Value, Value)> Value assoc_generic(Value x, Value alist, const char *who) {
  if (list_length(alist) < 0) wrong_type(alist, 2, who);
  for (Value p = alist; is_pair(p); p = cdr(p)) {
    Value entry = car(p);
    if (!is_pair(entry)) {
      Value bad = alist;
      wrong_type(bad, 2, who);
    }
    if (Same(x, car(entry))) return entry;
  }
  return Value::boolean(false);
}
Value P_assq(Value *a, int) {
  return assoc_generic<eq>(a[0], a[1], "assq");
}
Value P_assv(Value *a, int) {
  return assoc_generic<eqv>(a[0], a[1], "assv");
}
// (assoc x alist [same?]): with a third argument, entries are compared by
// calling it; the alist is checked as for two arguments (an entry that is
// not a pair is MIT's wrong-type error, not a crash).
Value P_assoc(Value *a, int n) {
  if (n < 3) return assoc_generic<equal>(a[0], a[1], "assoc");
  if (list_length(a[1]) < 0) wrong_type(a[1], 2, "assoc");
  for (Value p = a[1]; is_pair(p); p = cdr(p)) {
    Value entry = car(p);
    if (!is_pair(entry)) wrong_type(a[1], 2, "assoc");
    Value args[2] = {a[0], car(entry)};
    if (apply_procedure(a[2], args, 2).truthy()) return entry;
  }
  return Value::boolean(false);
}

Value call1(Value f, Value x) {
  return apply_procedure(f, &x, 1);
}
Value call2(Value f, Value x, Value y) {
  Value args[2] = {x, y};
  return apply_procedure(f, args, 2);
}

// map and for-each over one or more lists, stopping at the shortest.
Value map_generic(Value *a, int n, bool collect, const char *who) {
  gcvec<Value> lists(a + 1, a + n);
  for (int i = 1; i < n; ++i)
    if (list_length(a[i]) < 0 && !is_pair(a[i])) wrong_type(a[i], i + 1, who);
  gcvec<Value> results, args(lists.size());
  for (;;) {
    for (size_t i = 0; i < lists.size(); ++i) {
      if (!is_pair(lists[i]))
        return collect ? list_from(results.data(), results.size()) : Value::boolean(true);
      args[i] = car(lists[i]);
      lists[i] = cdr(lists[i]);
    }
    Value r = apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
    if (collect) results.push_back(r);
  }
}
Value P_map(Value *a, int n) {
  return map_generic(a, n, true, "map");
}
Value P_for_each(Value *a, int n) {
  map_generic(a, n, false, "for-each");
  return Value::unspecified();
}
// parallel-map and parallel-for-each mean map and for-each; members may run
// at the same time (in built executables, on threads and MPI ranks), so the
// procedure may not assign variables it does not own. The interpreter runs
// them in order: its output is what the executable's is.
Value P_parallel_map(Value *a, int n) {
  require_no_captured_assignment(a[0], "parallel-map");
  return map_generic(a, n, true, "parallel-map");
}
Value P_parallel_for_each(Value *a, int n) {
  require_no_captured_assignment(a[0], "parallel-for-each");
  map_generic(a, n, false, "parallel-for-each");
  return Value::unspecified();
}
Value P_append_map(Value *a, int n) {
  Value lists = map_generic(a, n, true, "append-map");
  gcvec<Value> parts = list_to_vector(lists);
  return P_append(parts.data(), static_cast<int>(parts.size()));
}

Value P_filter(Value *a, int) {
  require_list(a, 1, "filter");
  gcvec<Value> out;
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (call1(a[0], car(p)).truthy()) out.push_back(car(p));
  return list_from(out.data(), out.size());
}
Value P_remove(Value *a, int) {
  require_list(a, 1, "remove");
  gcvec<Value> out;
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (call1(a[0], car(p)).is_false()) out.push_back(car(p));
  return list_from(out.data(), out.size());
}
Value P_partition(Value *a, int) {
  gcvec<Value> in, out;
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    (call1(a[0], car(p)).truthy() ? in : out).push_back(car(p));
  Value vals[2] = {list_from(in.data(), in.size()), list_from(out.data(), out.size())};
  Value *items = static_cast<Value *>(GC_MALLOC(sizeof(vals)));
  items[0] = vals[0];
  items[1] = vals[1];
  return Value::object(Tag::Values, gc_new<MultipleValues>(MultipleValues{items, 2}));
}
Value P_delete(Value *a, int) {
  require_list(a, 1, "delete");
  gcvec<Value> out;
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (!equal(a[0], car(p))) out.push_back(car(p));
  return list_from(out.data(), out.size());
}
Value P_delete_duplicates(Value *a, int n) {
  require_list(a, 0, "delete-duplicates");
  gcvec<Value> out;
  for (Value p = a[0]; is_pair(p); p = cdr(p)) {
    bool seen = false;
    for (Value q : out)
      if (n > 1 ? call2(a[1], q, car(p)).truthy() : equal(q, car(p))) seen = true;
    if (!seen) out.push_back(car(p));
  }
  return list_from(out.data(), out.size());
}

Value P_find(Value *a, int) {
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (call1(a[0], car(p)).truthy()) return car(p);
  return Value::boolean(false);
}
Value P_find_tail(Value *a, int) {
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (call1(a[0], car(p)).truthy()) return p;
  return Value::boolean(false);
}
Value P_list_index(Value *a, int) {
  int64_t i = 0;
  for (Value p = a[1]; is_pair(p); p = cdr(p), ++i)
    if (call1(a[0], car(p)).truthy()) return Value::fixnum(i);
  return Value::boolean(false);
}
Value P_count(Value *a, int) {
  int64_t k = 0;
  for (Value p = a[1]; is_pair(p); p = cdr(p))
    if (call1(a[0], car(p)).truthy()) ++k;
  return Value::fixnum(k);
}

// any / every over one or more lists.
Value any_every(Value *a, int n, bool any) {
  gcvec<Value> lists(a + 1, a + n), args(lists.size());
  Value last = Value::boolean(!any);
  for (;;) {
    for (size_t i = 0; i < lists.size(); ++i) {
      if (!is_pair(lists[i])) return last;
      args[i] = car(lists[i]);
      lists[i] = cdr(lists[i]);
    }
    last = apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
    if (any ? last.truthy() : last.is_false()) return last;
  }
}
Value P_any(Value *a, int n) {
  return any_every(a, n, true);
}
Value P_every(Value *a, int n) {
  return any_every(a, n, false);
}

// MIT: (reduce + 0 '(1 2 3)) folds left: (+ 3 (+ 2 1)).
Value P_reduce(Value *a, int) {
  require_list(a, 2, "reduce");
  Value p = a[2];
  if (is_null(p)) return a[1];
  Value acc = car(p);
  for (p = cdr(p); is_pair(p); p = cdr(p))
    acc = call2(a[0], car(p), acc);
  return acc;
}
Value P_reduce_left(Value *a, int) {
  require_list(a, 2, "reduce-left");
  Value p = a[2];
  if (is_null(p)) return a[1];
  Value acc = car(p);
  for (p = cdr(p); is_pair(p); p = cdr(p))
    acc = call2(a[0], acc, car(p));
  return acc;
}
Value P_reduce_right(Value *a, int) {
  require_list(a, 2, "reduce-right");
  gcvec<Value> items = list_to_vector(a[2]);
  if (items.empty()) return a[1];
  Value acc = items.back();
  for (size_t i = items.size() - 1; i-- > 0;)
    acc = call2(a[0], items[i], acc);
  return acc;
}

// (fold-left f init l1 l2 ...) and (fold-right f init l1 l2 ...).
Value fold_generic(Value *a, int n, bool left, const char *who) {
  gcvec<gcvec<Value>> lists; // all in collected memory, so scanned
  size_t len = SIZE_MAX;
  for (int i = 2; i < n; ++i) {
    require_list(a, i, who);
    lists.push_back(list_to_vector(a[i]));
    len = std::min(len, lists.back().size());
  }
  if (lists.empty()) return a[1];
  Value acc = a[1];
  gcvec<Value> args(lists.size() + 1);
  for (size_t k = 0; k < len; ++k) {
    size_t j = left ? k : len - 1 - k;
    if (left) {
      args[0] = acc;
      for (size_t i = 0; i < lists.size(); ++i)
        args[i + 1] = lists[i][j];
    } else {
      for (size_t i = 0; i < lists.size(); ++i)
        args[i] = lists[i][j];
      args[lists.size()] = acc;
    }
    acc = apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
  }
  return acc;
}
Value P_fold_left(Value *a, int n) {
  return fold_generic(a, n, true, "fold-left");
}
Value P_fold_right(Value *a, int n) {
  return fold_generic(a, n, false, "fold-right");
}
// SRFI-1 fold: (fold kons knil list): (kons elem acc).
Value P_fold(Value *a, int) {
  require_list(a, 2, "fold");
  Value acc = a[1];
  for (Value p = a[2]; is_pair(p); p = cdr(p))
    acc = call2(a[0], car(p), acc);
  return acc;
}

// (iota count [start [step]])
Value P_iota(Value *a, int n) {
  size_t count = arg_index(a, 0, "iota");
  Value start = n > 1 ? a[1] : Value::fixnum(0);
  Value step = n > 2 ? a[2] : Value::fixnum(1);
  if (!is_number(start)) wrong_type(start, 2, "iota");
  if (!is_number(step)) wrong_type(step, 3, "iota");
  gcvec<Value> items;
  for (size_t i = 0; i < count; ++i)
    items.push_back(num_add(start, num_mul(Value::fixnum(static_cast<int64_t>(i)), step)));
  return list_from(items.data(), items.size());
}

// Stable merge sort of a list or vector by a "less than" procedure. Written
// here rather than std::stable_sort because that keeps elements in a malloc'd
// buffer the collector cannot see while the user's procedure allocates.
void merge_sort(gcvec<Value> &items, gcvec<Value> &tmp, size_t lo, size_t hi, Value less) {
  if (hi - lo < 2) return;
  size_t mid = lo + (hi - lo) / 2;
  merge_sort(items, tmp, lo, mid, less);
  merge_sort(items, tmp, mid, hi, less);
  size_t i = lo, j = mid, k = lo;
  while (i < mid && j < hi)
    tmp[k++] = call2(less, items[j], items[i]).truthy() ? items[j++] : items[i++];
  while (i < mid)
    tmp[k++] = items[i++];
  while (j < hi)
    tmp[k++] = items[j++];
  for (k = lo; k < hi; ++k)
    items[k] = tmp[k];
}

Value P_sort(Value *a, int) {
  gcvec<Value> items;
  bool is_vec = a[0].is(Tag::Vector);
  if (is_vec) {
    items.assign(a[0].vector()->items, a[0].vector()->items + a[0].vector()->len);
  } else {
    require_list(a, 0, "sort");
    items = list_to_vector(a[0]);
  }
  if (!is_procedure(a[1])) wrong_type(a[1], 2, "sort");
  gcvec<Value> tmp(items.size());
  merge_sort(items, tmp, 0, items.size(), a[1]);
  if (!is_vec) return list_from(items.data(), items.size());
  Value v = make_vector(items.size(), Value::nil());
  for (size_t i = 0; i < items.size(); ++i)
    v.vector()->items[i] = items[i];
  return v;
}

// ---- streams (cons-stream makes a pair whose cdr is a promise) ----

Value P_stream_pair_p(Value *a, int) {
  return Value::boolean(is_pair(a[0]) && cdr(a[0]).is(Tag::Promise));
}
Value P_stream_car(Value *a, int) {
  if (!is_pair(a[0])) wrong_type(a[0], 1, "stream-car");
  return car(a[0]);
}
Value P_stream_cdr(Value *a, int) {
  if (!is_pair(a[0])) wrong_type(a[0], 1, "stream-cdr");
  return force_promise(cdr(a[0]));
}
Value P_stream_tail(Value *a, int) {
  size_t k = arg_index(a, 1, "stream-tail");
  Value s = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(s)) bad_range(a[1], 2, "stream-tail");
    s = force_promise(cdr(s));
  }
  return s;
}
Value P_stream_head(Value *a, int) {
  size_t k = arg_index(a, 1, "stream-head");
  gcvec<Value> items;
  Value s = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(s)) bad_range(a[1], 2, "stream-head");
    items.push_back(car(s));
    if (i + 1 < k) s = force_promise(cdr(s));
  }
  return list_from(items.data(), items.size());
}
Value P_stream_ref(Value *a, int) {
  size_t k = arg_index(a, 1, "stream-ref");
  Value s = a[0];
  for (size_t i = 0; i < k; ++i) {
    if (!is_pair(s)) bad_range(a[1], 2, "stream-ref");
    s = force_promise(cdr(s));
  }
  if (!is_pair(s)) bad_range(a[1], 2, "stream-ref");
  return car(s);
}
Value make_stream_from(const Value *items, size_t n) {
  Value s = Value::nil();
  for (size_t i = n; i-- > 0;)
    s = cons(items[i],
             Value::object(Tag::Promise, gc_new<Promise>(Promise{true, s, nullptr, nullptr})));
  return s;
}
Value P_stream(Value *a, int n) {
  return make_stream_from(a, static_cast<size_t>(n));
}
Value P_list_to_stream(Value *a, int) {
  require_list(a, 0, "list->stream");
  gcvec<Value> items = list_to_vector(a[0]);
  return make_stream_from(items.data(), items.size());
}
Value P_stream_to_list(Value *a, int n) {
  size_t limit = n > 1 ? arg_index(a, 1, "stream->list") : SIZE_MAX;
  gcvec<Value> items;
  Value s = a[0];
  while (is_pair(s) && items.size() < limit) {
    items.push_back(car(s));
    if (items.size() < limit) s = force_promise(cdr(s));
  }
  return list_from(items.data(), items.size());
}

} // namespace

void install_list_primitives() {
  define_primitive("cons", 2, 2, Stage::Pure, P_cons);
  define_primitive("car", 1, 1, Stage::Pure, P_car);
  define_primitive("cdr", 1, 1, Stage::Pure, P_cdr);
  define_primitive("set-car!", 2, 2, Stage::Effect, P_set_car);
  define_primitive("set-cdr!", 2, 2, Stage::Effect, P_set_cdr);
  define_primitive("caar", 1, 1, Stage::Pure, cxr<kCaar>);
  define_primitive("cadr", 1, 1, Stage::Pure, cxr<kCadr>);
  define_primitive("cdar", 1, 1, Stage::Pure, cxr<kCdar>);
  define_primitive("cddr", 1, 1, Stage::Pure, cxr<kCddr>);
  define_primitive("caaar", 1, 1, Stage::Pure, cxr<kCaaar>);
  define_primitive("caadr", 1, 1, Stage::Pure, cxr<kCaadr>);
  define_primitive("cadar", 1, 1, Stage::Pure, cxr<kCadar>);
  define_primitive("caddr", 1, 1, Stage::Pure, cxr<kCaddr>);
  define_primitive("cdaar", 1, 1, Stage::Pure, cxr<kCdaar>);
  define_primitive("cdadr", 1, 1, Stage::Pure, cxr<kCdadr>);
  define_primitive("cddar", 1, 1, Stage::Pure, cxr<kCddar>);
  define_primitive("cdddr", 1, 1, Stage::Pure, cxr<kCdddr>);
  define_primitive("cadddr", 1, 1, Stage::Pure, cxr<kCadddr>);
  define_primitive("cddddr", 1, 1, Stage::Pure, cxr<kCddddr>);
  define_primitive("pair?", 1, 1, Stage::Pure, P_pair_p);
  define_primitive("null?", 1, 1, Stage::Pure, P_null_p);
  define_primitive("list?", 1, 1, Stage::Pure, P_list_p);
  define_primitive("list", 0, kVariadic, Stage::Pure, P_list);
  define_primitive("cons*", 1, kVariadic, Stage::Pure, P_cons_star);
  define_primitive("list*", 1, kVariadic, Stage::Pure, P_cons_star);
  define_primitive("make-list", 1, 2, Stage::Pure, P_make_list);
  define_primitive("length", 1, 1, Stage::Pure, P_length);
  define_primitive("append", 0, kVariadic, Stage::Pure, P_append);
  define_primitive("append!", 0, kVariadic, Stage::Effect, P_append_bang);
  define_primitive("reverse", 1, 1, Stage::Pure, P_reverse);
  define_primitive("reverse!", 1, 1, Stage::Effect, P_reverse);
  define_primitive("list-tail", 2, 2, Stage::Pure, P_list_tail);
  define_primitive("list-head", 2, 2, Stage::Pure, P_list_head);
  define_primitive("sublist", 3, 3, Stage::Pure, P_sublist);
  define_primitive("list-ref", 2, 2, Stage::Pure, P_list_ref);
  define_primitive("last-pair", 1, 1, Stage::Pure, P_last_pair);
  define_primitive("last", 1, 1, Stage::Pure, P_last);
  define_primitive("except-last-pair!", 1, 1, Stage::Effect, P_except_last_pair);
  define_primitive("except-last-pair", 1, 1, Stage::Pure, P_except_last_pair);
  define_primitive("first", 1, 1, Stage::Pure, nth<0>);
  define_primitive("second", 1, 1, Stage::Pure, nth<1>);
  define_primitive("third", 1, 1, Stage::Pure, nth<2>);
  define_primitive("fourth", 1, 1, Stage::Pure, nth<3>);
  define_primitive("fifth", 1, 1, Stage::Pure, nth<4>);
  define_primitive("list-copy", 1, 1, Stage::Pure, P_list_copy);
  define_primitive("memq", 2, 2, Stage::Pure, P_memq);
  define_primitive("memv", 2, 2, Stage::Pure, P_memv);
  define_primitive("member", 2, 3, Stage::Pure, P_member);
  define_primitive("assq", 2, 2, Stage::Pure, P_assq);
  define_primitive("assv", 2, 2, Stage::Pure, P_assv);
  define_primitive("assoc", 2, 3, Stage::Pure, P_assoc);
  define_primitive("map", 2, kVariadic, Stage::Pure, P_map);
  define_primitive("for-each", 2, kVariadic, Stage::Pure, P_for_each);
  define_primitive("parallel-map", 2, kVariadic, Stage::RunTime, P_parallel_map);
  define_primitive("parallel-for-each", 2, kVariadic, Stage::RunTime, P_parallel_for_each);
  define_primitive("append-map", 2, kVariadic, Stage::Pure, P_append_map);
  define_primitive("filter", 2, 2, Stage::Pure, P_filter);
  define_primitive("remove", 2, 2, Stage::Pure, P_remove);
  define_primitive("partition", 2, 2, Stage::Pure, P_partition);
  define_primitive("delete", 2, 2, Stage::Pure, P_delete);
  define_primitive("delete!", 2, 2, Stage::Effect, P_delete);
  define_primitive("delete-duplicates", 1, 2, Stage::Pure, P_delete_duplicates);
  define_primitive("find", 2, 2, Stage::Pure, P_find);
  define_primitive("find-tail", 2, 2, Stage::Pure, P_find_tail);
  define_primitive("list-index", 2, 2, Stage::Pure, P_list_index);
  define_primitive("count", 2, 2, Stage::Pure, P_count);
  define_primitive("any", 2, kVariadic, Stage::Pure, P_any);
  define_primitive("every", 2, kVariadic, Stage::Pure, P_every);
  define_primitive("reduce", 3, 3, Stage::Pure, P_reduce);
  define_primitive("reduce-left", 3, 3, Stage::Pure, P_reduce_left);
  define_primitive("reduce-right", 3, 3, Stage::Pure, P_reduce_right);
  define_primitive("fold-left", 3, kVariadic, Stage::Pure, P_fold_left);
  define_primitive("fold-right", 3, kVariadic, Stage::Pure, P_fold_right);
  define_primitive("fold", 3, 3, Stage::Pure, P_fold);
  define_primitive("iota", 1, 3, Stage::Pure, P_iota);
  define_primitive("sort", 2, 2, Stage::Pure, P_sort);
  define_primitive("sort!", 2, 2, Stage::Effect, P_sort);
  define_primitive("stream-pair?", 1, 1, Stage::Pure, P_stream_pair_p);
  define_primitive("stream-car", 1, 1, Stage::Pure, P_stream_car);
  define_primitive("stream-cdr", 1, 1, Stage::Pure, P_stream_cdr);
  define_primitive("stream-rest", 1, 1, Stage::Pure, P_stream_cdr);
  define_primitive("stream-first", 1, 1, Stage::Pure, P_stream_car);
  define_primitive("stream-null?", 1, 1, Stage::Pure, P_null_p);
  define_primitive("empty-stream?", 1, 1, Stage::Pure, P_null_p);
  define_primitive("stream-tail", 2, 2, Stage::Pure, P_stream_tail);
  define_primitive("stream-head", 2, 2, Stage::Pure, P_stream_head);
  define_primitive("stream-ref", 2, 2, Stage::Pure, P_stream_ref);
  define_primitive("stream", 0, kVariadic, Stage::Pure, P_stream);
  define_primitive("list->stream", 1, 1, Stage::Pure, P_list_to_stream);
  define_primitive("stream->list", 1, 2, Stage::Pure, P_stream_to_list);
}

} // namespace sicm
