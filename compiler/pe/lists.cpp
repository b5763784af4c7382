// `sicm build`'s lists whose length is known only at run time: a variable
// that a procedure run at run time conses onto becomes one of the runtime's
// arrays, and the list primitives (car, cdr, length, map, for-each, apply,
// ...) take such lists apart at run time. Part of build mode (the design is
// in pe/build_mode.cpp; the shared declarations in pe/state.hpp).
#include <string>

#include "algebra/generic.hpp"
#include "base/number.hpp"
#include "base/primitive.hpp"
#include "codegen/state_shape.hpp"
#include "eval/procedure.hpp"
#include "pe/specialized.hpp"
#include "pe/state.hpp"

namespace sicm::build {

// ---- lists whose length is known only at run time ----------------------------------------
//
// A procedure run at run time (a monitor) that conses onto a variable it
// keeps from one call to the next, (set! l (cons x l)), makes the variable a
// list cell: the list becomes the runtime's array listN (sicm/program.h), to
// which each run-time call adds its element; like a cell, the variable is
// read again (its length) where a traced procedure begins and after every
// call that may have added to it. Every element must have one shape: a number
// or truth value, or a pair, structure or vector of them (static parts, a
// symbol say, are kept in the shape), so that an element is a fixed number of
// doubles. A list value is an RtList: a range of the array read in one
// direction, so that car, cdr, null?, length, list-ref and reverse are
// arithmetic on its ends; map and for-each become C loops over it, apply of
// min, max, + or * a runtime fold, and a named let whose arguments are such
// lists (walking them with null?, car and cdr) a C loop as for numbers (the
// ends are its variables: see result_leaves). Anything else done with such a
// list (print it, append to it, keep it in a list of lists) is a compile error.

namespace {

bool contains_rtlist(Value v) {
  if (as_rtlist(v)) return true;
  if (is_pair(v)) return contains_rtlist(car(v)) || contains_rtlist(cdr(v));
  size_t len;
  Value *items = container_items(v, &len);
  for (size_t i = 0; items && i < len; ++i)
    if (contains_rtlist(items[i])) return true;
  return false;
}

} // namespace

int list_cell_of(const Value *place) {
  for (size_t i = 0; i < g_build->list_cells.size(); ++i)
    if (g_build->list_cells[i].place == place) return static_cast<int>(i);
  return -1;
}

std::vector<Value *> list_cell_places() {
  std::vector<Value *> places;
  for (const ListCell &c : g_build->list_cells)
    places.push_back(c.place);
  return places;
}

bool is_whole_list(Value v) {
  RtList *r = as_rtlist(v);
  return r && r->whole;
}

// The leaves of a list element, or false if it cannot be one.
bool element_leaves(Value v, gcvec<Value> &out) {
  return !contains_rtlist(v) && !is_bottom(v) && result_leaves(v, out);
}

// The shape of an element (which may mention variables a retrace forgets):
// its leaves replaced by 0.
Value element_shape(Value element) {
  gcvec<Value> leaves;
  element_leaves(element, leaves);
  for (Value &leaf : leaves)
    leaf = Value::fixnum(0);
  const Value *p = leaves.data();
  return result_like(element, p);
}

namespace {

std::vector<RType> leaf_types(const gcvec<Value> &leaves) {
  std::vector<RType> types;
  for (Value leaf : leaves)
    types.push_back(scalar_type(leaf));
  return types;
}

} // namespace

int new_list(Value shape, const std::vector<RType> &types, const std::string &name) {
  int id = static_cast<int>(g_build->program.lists.size());
  g_build->program.lists.push_back(RList{static_cast<int>(types.size()), name});
  g_build->list_shapes.push_back(element_shape(shape));
  g_build->list_types.push_back(types);
  RStmt s{RKind::ListNew};
  s.list = id;
  emit(std::move(s));
  return id;
}

namespace {

void push_leaves(int list, const gcvec<Value> &leaves) {
  RStmt s{RKind::ListPush};
  s.list = list;
  for (Value leaf : leaves)
    s.args.push_back(expr_of(leaf, "cons"));
  emit(std::move(s));
}

Value count_plus(Value n, long k) {
  return k == 0 ? n : g_add(n, Value::fixnum(k));
}

// Evaluate again what added to a list that must first be started: the loop
// that conses onto it, or the numerical primitive whose procedure does.
[[noreturn]] void retry_for_list(bool in_loop) {
  if (in_loop) throw LoopRetry{};
  throw Retrace{};
}

} // namespace

// (set! l (cons element l)) in a procedure run at run time, or in a loop left
// for run time (in_loop): add the element to the run-time list l holds, or
// (l holding a list known at compile time) start a new one, tracing the
// primitive (evaluating the loop) again.
Value push_onto_list(Value *place, const std::string &name, Value element, SrcLoc loc,
                     bool may_create, Frame *frame, bool in_loop) {
  int cell = list_cell_of(place);
  RtList *r = as_rtlist(*place);
  gcvec<Value> leaves;
  if (!element_leaves(element, leaves))
    cannot_compile(loc, "set! of " + name + " to a list of " + describe(element) +
                            " inside a procedure that runs at run time (the elements of a list "
                            "of run-time length must be numbers, or pairs or structures of them)");
  if (cell >= 0 && r && r->whole && r->list == g_build->list_cells[cell].list) {
    int list = r->list;
    if (!same_shape(element, g_build->list_shapes[list]))
      cannot_compile(loc, "set! of " + name + " to a list whose elements have different shapes, " +
                              describe(element) + " and " + describe(g_build->list_shapes[list]));
    std::vector<RType> &types = g_build->list_types[list];
    for (size_t k = 0; k < leaves.size(); ++k) {
      RType t = scalar_type(leaves[k]);
      if (t == types[k]) continue;
      if (t == RType::Boolean || types[k] == RType::Boolean)
        cannot_compile(loc, "set! of " + name + " to a list of truth values and numbers");
      if (types[k] == RType::Integer) {
        types[k] = RType::Real; // counts widen to reals: trace again with real reads
        retry_for_list(in_loop);
      }
    }
    push_leaves(list, leaves);
    return make_rtlist(list, false, true, r->start, count_plus(r->end, 1));
  }
  if (r || list_length(*place) < 0 || contains_dynamic(*place))
    cannot_compile(loc, "set! of " + name + " to (cons " + describe(element) + " " +
                            describe(*place) +
                            ") inside a procedure that runs at run time: a run-time list can "
                            "only grow from the list the variable held before the primitive ran");
  for (Value x = *place; is_pair(x); x = cdr(x))
    if (!same_shape(car(x), element))
      cannot_compile(loc, "set! of " + name + " to a list whose elements have different shapes, " +
                              describe(element) + " and " + describe(car(x)));
  if (!may_create)
    cannot_compile(loc,
                   "set! of " + name + " inside a procedure run by another run-time procedure");
  if (cell < 0) {
    g_build->list_cells.push_back(ListCell{place, name, -1, true, {}});
    g_build->list_cell_elements.push_back(element);
    if (frame) g_build->cell_frames.push_back(frame);
    cell = static_cast<int>(g_build->list_cells.size()) - 1;
  }
  g_build->list_cells[cell].needs_init = true;
  g_build->list_cells[cell].types = leaf_types(leaves);
  g_build->list_cell_elements[cell] = element_shape(element);
  retry_for_list(in_loop);
}

// Start the lists that pushes asked for, from the values their variables
// hold (before the primitive that is traced again).
void init_list_cells() {
  for (size_t i = 0; i < g_build->list_cells.size(); ++i) {
    ListCell &c = g_build->list_cells[i];
    if (!c.needs_init) continue;
    c.needs_init = false;
    Value element = g_build->list_cell_elements[i];
    const std::vector<RType> &types = c.types;
    c.list = new_list(element, types, c.name);
    gcvec<Value> items = list_to_vector(*c.place);
    for (size_t k = items.size(); k-- > 0;) {
      gcvec<Value> xs;
      element_leaves(items[k], xs);
      if (leaf_types(xs) != types)
        cannot_compile(here(), "the list " + c.name + " holds " + describe(items[k]) +
                                   " and gets " + describe(element) +
                                   ", numbers of different kinds (exact and inexact)");
      push_leaves(c.list, xs);
    }
    *c.place = make_rtlist(c.list, false, true, Value::fixnum(0),
                           Value::fixnum(static_cast<long>(items.size())));
  }
}

// A list cell's variable holding its whole list gets the list's length now.
void read_list_cells() {
  for (ListCell &c : g_build->list_cells) {
    RtList *r = as_rtlist(*c.place);
    if (!r || !r->whole || r->list != c.list) continue;
    RStmt s{RKind::Let};
    s.compute = RCompute::ListLength;
    s.list = c.list;
    Value n = new_var(RType::Integer);
    s.var = var_of(n);
    current_block().push_back(std::move(s));
    *c.place = make_rtlist(c.list, false, true, Value::fixnum(0), n);
  }
}

namespace {

// The position in the array of element k (a count) of r.
Value list_position(const RtList *r, Value k) {
  if (r->reversed) return g_add(r->start, k);
  return g_sub(count_plus(r->end, -1), k);
}

// Element k of r, read at run time (who: for the error if there is none).
Value list_element(const RtList *r, Value k, const char *who) {
  Value position = list_position(r, k);
  const std::vector<RType> &types = g_build->list_types[r->list];
  gcvec<Value> leaves;
  for (size_t i = 0; i < types.size(); ++i) {
    RStmt s{RKind::Let};
    s.compute = RCompute::ListRef;
    s.list = r->list;
    s.leaf = static_cast<int>(i);
    s.text = who;
    s.args = {expr_of(position, who), expr_of(r->start, who), expr_of(r->end, who)};
    Value v = new_var(types[i]);
    s.var = var_of(v);
    emit(std::move(s));
    leaves.push_back(v);
  }
  const Value *p = leaves.data();
  return result_like(g_build->list_shapes[r->list], p);
}

// r without its first k elements.
Value list_tail(const RtList *r, Value k) {
  if (r->reversed) return make_rtlist(r->list, true, false, g_add(r->start, k), r->end);
  return make_rtlist(r->list, false, false, r->start, g_sub(r->end, k));
}

Value list_count(const RtList *r) {
  return g_sub(r->end, r->start);
}

Value list_is_empty(const RtList *r) {
  if (!is_dynamic_scalar(r->start) && !is_dynamic_scalar(r->end))
    return Value::boolean(to_double(r->start) == to_double(r->end));
  return let(RCompute::Equal, {expr_of(r->start, "null?"), expr_of(r->end, "null?")},
             RType::Boolean);
}

// A count argument: an exact integer or a run-time number.
Value count_arg(Value *a, int i, const char *who) {
  if (is_dynamic_scalar(a[i])) return a[i];
  if (!a[i].is(Tag::Fixnum) || a[i].i < 0) wrong_type(a[i], i + 1, who);
  return a[i];
}

// A list that ends in a run-time list after some pairs known at compile time.
bool has_rtlist_tail(Value v) {
  while (is_pair(v))
    v = cdr(v);
  return as_rtlist(v) != nullptr;
}

[[noreturn]] void refuse_list(Value v, const char *who) {
  cannot_compile(here(), std::string(who) + " of " + describe(v) +
                             ", a list whose length is known only at run time");
}

Value P_list_car(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, Value::fixnum(0), "car");
  return call_original("car", a, n);
}

Value P_list_cdr(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_tail(r, Value::fixnum(1));
  return call_original("cdr", a, n);
}

Value P_list_null(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_is_empty(r);
  return call_original("null?", a, n);
}

Value P_list_pair(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) {
    Value e = list_is_empty(r);
    if (e.is(Tag::Bool)) return Value::boolean(!e.truthy());
    return let(RCompute::Not, {expr_of(e, "pair?")}, RType::Boolean);
  }
  return call_original("pair?", a, n);
}

Value P_list_list_p(Value *a, int n) {
  if (has_rtlist_tail(a[0])) return Value::boolean(true);
  return call_original("list?", a, n);
}

Value P_list_length(Value *a, int n) {
  long prefix = 0;
  Value v = a[0];
  for (; is_pair(v); v = cdr(v))
    ++prefix;
  if (RtList *r = as_rtlist(v)) return count_plus(list_count(r), prefix);
  return call_original("length", a, n);
}

Value P_list_reverse(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0]))
    return make_rtlist(r->list, !r->reversed, false, r->start, r->end);
  if (has_rtlist_tail(a[0])) refuse_list(a[0], "reverse");
  return call_original("reverse", a, n);
}

Value P_list_ref(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, count_arg(a, 1, "list-ref"), "list-ref");
  if (is_dynamic_scalar(a[1]))
    cannot_compile(here(), "list-ref of a list known at compile time at an index known only at "
                           "run time");
  return call_original("list-ref", a, n);
}

Value P_list_tail(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_tail(r, count_arg(a, 1, "list-tail"));
  return call_original("list-tail", a, n);
}

Value P_list_last(Value *a, int n) {
  if (RtList *r = as_rtlist(a[0])) return list_element(r, count_plus(list_count(r), -1), "last");
  if (has_rtlist_tail(a[0])) refuse_list(a[0], "last");
  return call_original("last", a, n);
}

// c[ad]+r and first ... fifth: car and cdr one at a time, so that a run-time
// list met on the way is taken apart at run time.
template <const char *Name> Value P_list_cxr(Value *a, int n) {
  std::string_view name = Name;
  std::string ops; // applied right to left
  if (name[0] == 'c') {
    ops = std::string(name.substr(1, name.size() - 2));
  } else {
    static const char *const nth[] = {"first", "second", "third", "fourth", "fifth"};
    for (int k = 0; k < 5; ++k)
      if (name == nth[k]) ops = "a" + std::string(static_cast<size_t>(k), 'd');
  }
  // Only the cells on the path matter: (cadr l) of a long static list
  // walked all of l for run-time lists before, once per call, which made a
  // loop over the list quadratic (stdlib/stability.sicm's manifolds).
  Value v = a[0];
  bool run_time = as_rtlist(v) != nullptr;
  for (size_t i = ops.size(); i-- > 0 && !run_time && is_pair(v);) {
    v = ops[i] == 'a' ? car(v) : cdr(v);
    run_time = as_rtlist(v) != nullptr;
  }
  if (!run_time) return call_original(Name, a, n);
  v = a[0];
  for (size_t i = ops.size(); i-- > 0;) {
    Value arg[1] = {v};
    v = ops[i] == 'a' ? P_list_car(arg, 1) : P_list_cdr(arg, 1);
  }
  return v;
}

template <const char *Name, bool Collect> Value P_list_map(Value *a, int n) {
  bool any = false, all = true;
  for (int k = 1; k < n; ++k) {
    bool rt = as_rtlist(a[k]) != nullptr;
    any = any || has_rtlist_tail(a[k]);
    all = all && rt;
  }
  if (!any) {
    Value v;
    if (map_over_static_lists(a, n, Collect, Name, &v)) return v;
    return call_original(Name, a, n);
  }
  if (!all)
    cannot_compile(here(), std::string(Name) + " over a list whose length is known only at run "
                                               "time together with other lists");
  if (!is_procedure(a[0])) wrong_type(a[0], 1, Name);
  return map_over_lists(a[0], a + 1, n - 1, Collect, Name);
}
constexpr char kMap[] = "map";
constexpr char kForEach[] = "for-each";

// (apply f x ... l) with l a run-time list (a holds f, x ... l): a fold when
// f is min, max, + or *.
Value apply_to_rtlist(Value *a, int n) {
  RtList *r = as_rtlist(a[n - 1]);
  static const char *const folds[] = {"min", "max", "+", "*"};
  int op = -1;
  for (int k = 0; k < 4; ++k) {
    Symbol *s = intern(folds[k]).symbol();
    if (s->bound && eq(s->global, a[0])) op = k;
  }
  if (op < 0 || !r || (n > 2 && op >= 2))
    cannot_compile(here(), "apply of " + describe(a[0]) +
                               " to a list whose length is known only at run time (only min, "
                               "max, + and * are compiled)");
  const std::vector<RType> &types = g_build->list_types[r->list];
  if (types.size() != 1 || types[0] == RType::Boolean || !is_scalar(g_build->list_shapes[r->list]))
    cannot_compile(here(), std::string("apply of ") + folds[op] + " to a list of " +
                               describe(g_build->list_shapes[r->list]) + ", not of numbers");
  Value v = new_var(types[0]);
  RStmt s{RKind::Let};
  s.compute = RCompute::ListFold;
  s.list = r->list;
  s.leaf = op;
  s.backward = !r->reversed;
  s.args = {expr_of(r->start, "apply"), expr_of(r->end, "apply")};
  s.var = var_of(v);
  emit(std::move(s));
  if (n == 2) return v;
  gcvec<Value> args(a + 1, a + n - 1);
  args.push_back(v);
  return apply_procedure(a[0], args.data(), static_cast<int>(args.size()));
}

// List procedures not compiled for run-time lists: a clear error.
template <const char *Name> Value P_list_refused(Value *a, int n) {
  for (int k = 0; k < n; ++k)
    if (contains_rtlist(a[k])) refuse_list(a[k], Name);
  return call_original(Name, a, n);
}

constexpr char kCaar[] = "caar", kCadr[] = "cadr", kCdar[] = "cdar", kCddr[] = "cddr",
               kCaddr[] = "caddr", kCdddr[] = "cdddr", kCadddr[] = "cadddr", kFirst[] = "first",
               kSecond[] = "second", kThird[] = "third", kFourth[] = "fourth", kFifth[] = "fifth";

constexpr char kAppend[] = "append", kListCopy[] = "list-copy", kListToVector[] = "list->vector",
               kSort[] = "sort", kFilter[] = "filter", kReduce[] = "reduce",
               kFoldLeft[] = "fold-left", kFoldRight[] = "fold-right", kListHead[] = "list-head",
               kSublist[] = "sublist", kLastPair[] = "last-pair", kMember[] = "member",
               kMemv[] = "memv", kAssoc[] = "assoc", kAppendMap[] = "append-map";

} // namespace

// (map f l ...) or (for-each f l ...) over run-time lists: a C loop over the
// positions, in which f is traced once on the elements (its statements run
// for each); map adds f's results to a new list.
Value map_over_lists(Value f, Value *lists, int nlists, bool collect, const char *who) {
  gcvec<Value> views(lists, lists + nlists);
  Value n = list_count(as_rtlist(views[0]));
  for (int k = 1; k < nlists; ++k) // the shortest list, as MIT's map
    n = let(RCompute::Min, {expr_of(n, who), expr_of(list_count(as_rtlist(views[k])), who)},
            RType::Integer);
  Value i = new_var(RType::Integer);
  RStmt loop{RKind::Loop};
  loop.outs = {var_of(i)};
  loop.args = {expr_integer(0)};
  std::vector<RStmt> body;
  gcvec<Assignment> log;
  Value result;
  {
    struct Scope { // the loop's body receives the statements
      Scope(std::vector<RStmt> *body, gcvec<Assignment> *log) {
        g_build->blocks.push_back(body);
        g_build->undo.push_back(log);
        g_build->undo_serials.push_back(g_frame_serial);
      }
      ~Scope() {
        g_build->blocks.pop_back();
        g_build->undo.pop_back();
        g_build->undo_serials.pop_back();
      }
    } scope(&body, &log);
    Value done = let(RCompute::LessEq, {expr_of(n, who), expr_of(i, who)}, RType::Boolean);
    RStmt stop{RKind::If};
    stop.args = {expr_of(done, who)};
    stop.then_body.emplace_back(RKind::Break);
    emit(std::move(stop));
    gcvec<Value> elements;
    for (Value v : views)
      elements.push_back(list_element(as_rtlist(v), i, who));
    result = apply_procedure(f, elements.data(), nlists);
  }
  if (!log.empty())
    cannot_compile(here(), std::string("set! inside the procedure given to ") + who +
                               " over a list whose length is known only at run time");
  int out = -1;
  if (collect) {
    gcvec<Value> leaves;
    if (!element_leaves(result, leaves))
      cannot_compile(here(), std::string("the procedure given to ") + who + " returns " +
                                 describe(result) +
                                 ", which cannot be an element of a list of run-time length");
    out = new_list(result, leaf_types(leaves), who);
    RStmt push{RKind::ListPush};
    push.list = out;
    for (Value leaf : leaves)
      push.args.push_back(expr_of(leaf, who));
    body.push_back(std::move(push));
  }
  RStmt next{RKind::Continue};
  next.outs = {var_of(i)};
  next.args = {expr_of(count_plus(i, 1), who)};
  body.push_back(std::move(next));
  loop.then_body = std::move(body);
  bool calls = block_calls(loop.then_body);
  current_block().push_back(std::move(loop));
  if (calls) read_cells();
  if (!collect) return Value::unspecified();
  return make_rtlist(out, true, false, Value::fixnum(0), n);
}

bool hook_apply_to_other(Value f, Value *args, long nargs, Value *out) {
  if (nargs < 1 || !has_rtlist_tail(args[nargs - 1])) return false;
  gcvec<Value> a{f};
  a.insert(a.end(), args, args + nargs);
  *out = apply_to_rtlist(a.data(), static_cast<int>(a.size()));
  return true;
}

// What this file specializes (the table is pe/specialized.cpp).
const PrimFn p_car = P_list_car, p_cdr = P_list_cdr, p_null_p = P_list_null, p_pair_p = P_list_pair,
             p_list_p = P_list_list_p, p_length = P_list_length, p_reverse = P_list_reverse,
             p_list_ref = P_list_ref, p_list_tail = P_list_tail, p_last = P_list_last,
             p_map = P_list_map<kMap, true>, p_for_each = P_list_map<kForEach, false>;
const PrimFn p_caar = P_list_cxr<kCaar>, p_cadr = P_list_cxr<kCadr>, p_cdar = P_list_cxr<kCdar>,
             p_cddr = P_list_cxr<kCddr>, p_caddr = P_list_cxr<kCaddr>, p_cdddr = P_list_cxr<kCdddr>,
             p_cadddr = P_list_cxr<kCadddr>, p_first = P_list_cxr<kFirst>,
             p_second = P_list_cxr<kSecond>, p_third = P_list_cxr<kThird>,
             p_fourth = P_list_cxr<kFourth>, p_fifth = P_list_cxr<kFifth>;
const PrimFn p_append = P_list_refused<kAppend>, p_list_copy = P_list_refused<kListCopy>,
             p_list_to_vector = P_list_refused<kListToVector>, p_sort = P_list_refused<kSort>,
             p_filter = P_list_refused<kFilter>, p_reduce = P_list_refused<kReduce>,
             p_fold_left = P_list_refused<kFoldLeft>, p_fold_right = P_list_refused<kFoldRight>,
             p_list_head = P_list_refused<kListHead>, p_sublist = P_list_refused<kSublist>,
             p_last_pair = P_list_refused<kLastPair>, p_member = P_list_refused<kMember>,
             p_memv = P_list_refused<kMemv>, p_assoc = P_list_refused<kAssoc>,
             p_append_map = P_list_refused<kAppendMap>;

} // namespace sicm::build
