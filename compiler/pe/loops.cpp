// `sicm build`'s loops: a named procedure that calls itself with run-time
// arguments becomes a C loop of the residual program, and loops that would
// be unrolled past the named limits (base/limits.hpp) are generalized into
// C loops instead: map and for-each over long lists known at compile time,
// and loops that start from known values. Part of build mode (the design is
// in pe/build_mode.cpp; the shared declarations in pe/state.hpp).
#include <algorithm>
#include <string>
#include <unordered_set>

#include "algebra/structure.hpp"
#include "base/limits.hpp"
#include "codegen/state_shape.hpp"
#include "eval/core.hpp"
#include "eval/procedure.hpp"
#include "pe/state.hpp"

namespace sicm::build {

// ---- loops: named procedures called again with run-time arguments ------------------------
//
// A call of a named procedure with a run-time number among its arguments is
// evaluated as a loop candidate: its parameters that get run-time values
// become loop variables, and a call of the same procedure (closure) while its
// body is being evaluated records "continue with these values" and gives
// Bottom, a value that never reaches a result: a test on a run-time value
// whose alternative is Bottom selects the other one. If the body never calls
// itself, its statements are spliced in place (it was an ordinary call);
// else they become a C loop whose result is the value the body gives on the
// paths that do not call it again. A parameter that gets a different known
// number in the recursive call becomes a loop variable too (the body is
// evaluated again); anything else (a list that shrinks, a result used by the
// caller as in (* n (fact (- n 1))), a structure as argument) abandons the
// loop, and the call is evaluated as it always is.

namespace {

struct LoopAbort {}; // not a loop: evaluate the call as usual

// Is v a container (a structure or vector)?
bool container_items_of(Value v) {
  size_t len;
  return container_items(v, &len) != nullptr;
}

void write_bottom(std::string &out, const void *, bool) {
  out += "#[the value of a recursive call]";
}

} // namespace

void throw_not_a_loop() {
  throw LoopAbort{};
}

const OpaqueKind kBottomKind = {"run-time-loop-continuation", write_bottom, nullptr};

bool is_bottom(Value v) {
  return v.is(Tag::Opaque) && v.as<Opaque>()->kind == &kBottomKind;
}

// The scalar leaves of a loop's result (a number or truth value, or a proper
// list, structure or vector of them); false if it has others.
bool result_leaves(Value v, gcvec<Value> &out) {
  if (is_bottom(v)) return false;
  if (RtList *r = as_rtlist(v)) { // a run-time list: its ends
    out.push_back(r->start);
    out.push_back(r->end);
    return true;
  }
  if (is_scalar(v)) {
    out.push_back(v);
    return true;
  }
  if (!contains_dynamic(v) && !is_pair(v) && !container_items_of(v)) return true; // kept as is
  if (is_pair(v)) return result_leaves(car(v), out) && result_leaves(cdr(v), out);
  size_t len;
  Value *items = container_items(v, &len);
  if (!items) return false;
  for (size_t i = 0; i < len; ++i)
    if (!result_leaves(items[i], out)) return false;
  return true;
}

// A value shaped like `shape` (as result_leaves walks it) with new leaves.
Value result_like(Value shape, const Value *&leaves) {
  if (is_scalar(shape)) return *leaves++;
  if (RtList *r = as_rtlist(shape)) {
    Value start = *leaves++;
    return make_rtlist(r->list, r->reversed, false, start, *leaves++);
  }
  if (!contains_dynamic(shape) && !is_pair(shape) && !container_items_of(shape)) return shape;
  if (is_pair(shape)) {
    Value a = result_like(car(shape), leaves);
    return cons(a, result_like(cdr(shape), leaves));
  }
  return state_like(shape, leaves, result_like);
}

// Do a and b have the same shape as loop values: both scalars, or lists,
// structures or vectors of the same lengths with the same shapes inside?
bool same_shape(Value a, Value b) {
  if (is_scalar(a) || is_scalar(b)) return is_scalar(a) && is_scalar(b);
  if (as_rtlist(a) || as_rtlist(b))
    return as_rtlist(a) && as_rtlist(b) && as_rtlist(a)->list == as_rtlist(b)->list &&
           as_rtlist(a)->reversed == as_rtlist(b)->reversed;
  if (!is_pair(a) && !container_items_of(a) && !contains_dynamic(a)) return eqv(a, b);
  if (is_pair(a) || is_pair(b))
    return is_pair(a) && is_pair(b) && same_shape(car(a), car(b)) && same_shape(cdr(a), cdr(b));
  size_t la = 0, lb = 0;
  Value *x = container_items(a, &la), *y = container_items(b, &lb);
  if (!x || !y || la != lb || a.tag != b.tag) return false;
  if (is_structure(a) && as_structure(a)->up != as_structure(b)->up) return false;
  for (size_t i = 0; i < la; ++i)
    if (!same_shape(x[i], y[i])) return false;
  return true;
}

// A parameter of a loop: known (the first call's argument, which every
// call must repeat) or a loop variable: a number, a truth value, or a
// list, structure or vector of them, one C variable per leaf.
struct LoopParam {
  bool variable = false;
  Value shape;              // the first call's argument
  std::vector<RType> types; // of the leaves
  std::vector<int> vars;    // the leaves' variables in the current attempt
};

struct ActiveLoop {
  Closure *closure;
  size_t depth = 0;        // g_build->open.size(): the function the loop is in
  uint32_t serial = 0;     // g_frame_serial when the current attempt began
  bool watching = false;   // evaluated as an ordinary call until it calls itself
  gcvec<LoopParam> params; // holds Values: collected memory
  bool continued = false;
  bool from_known = false; // every argument of the first call was known (see StaticWatch)
};

namespace {

struct BecomeLoop { // a watched call called itself: evaluate it as a loop
  Closure *closure;
};

// Make parameter p a loop variable shaped like v (a retry follows).
void make_variable(LoopParam &p, Value v) {
  gcvec<Value> leaves;
  if (!result_leaves(v, leaves)) throw LoopAbort{};
  p.variable = true;
  p.types.clear();
  for (Value leaf : leaves)
    p.types.push_back(scalar_type(leaf));
}

// A known value a loop started from known values may turn into a loop
// variable: a truth value, an inexact number, or an exact integer that a
// double holds exactly (an exact fraction prints differently from a double).
bool is_loop_number(Value v) {
  if (v.is(Tag::Flonum) || v.is(Tag::Bool) || is_dynamic_scalar(v)) return true;
  return v.is(Tag::Fixnum) && v.i <= (int64_t(1) << 53) && v.i >= -(int64_t(1) << 53);
}

Value record_continue(ActiveLoop &loop, Value *a, long n) {
  RStmt s{RKind::Continue};
  for (long i = 0; i < n; ++i) {
    LoopParam &p = loop.params[i];
    if (!p.variable) {
      if (eqv(a[i], p.shape)) continue;
      gcvec<Value> leaves;
      if (!result_leaves(a[i], leaves) || !same_shape(a[i], p.shape))
        throw LoopAbort{}; // a list that shrinks, ...
      if (loop.from_known)
        for (Value leaf : leaves)
          if (!is_loop_number(leaf)) throw LoopAbort{};
      make_variable(p, a[i]); // known numbers that change: loop variables
      throw LoopRetry{};
    }
    gcvec<Value> leaves;
    if (!same_shape(a[i], p.shape) || !result_leaves(a[i], leaves)) throw LoopAbort{};
    for (size_t k = 0; k < leaves.size(); ++k) {
      RType t = scalar_type(leaves[k]);
      if (t != p.types[k]) {
        if (t == RType::Boolean || p.types[k] == RType::Boolean) throw LoopAbort{};
        p.types[k] = RType::Real; // counts that become reals
        throw LoopRetry{};
      }
      s.outs.push_back(p.vars[k]);
      s.args.push_back(expr_of(leaves[k], "loop"));
    }
  }
  emit(std::move(s));
  loop.continued = true;
  return g_build->bottom;
}

// Restores the builder's stacks when a loop attempt ends, by return or by
// exception; roll_back forgets what it made.
class LoopAttempt {
public:
  LoopAttempt(ActiveLoop *loop, std::vector<RStmt> *block)
      : nloops_(g_build->loops.size()), nblocks_(g_build->blocks.size()),
        nundo_(g_build->undo.size()) {
    g_build->loops.push_back(loop);
    g_build->blocks.push_back(block);
    g_build->undo.push_back(&log_);
    g_build->undo_serials.push_back(g_frame_serial);
  }
  ~LoopAttempt() {
    g_build->loops.resize(nloops_);
    g_build->blocks.resize(nblocks_);
    g_build->undo.resize(nundo_);
    g_build->undo_serials.resize(nundo_);
  }
  // Forget everything the attempt made.
  void roll_back() {
    for (auto a = log_.rbegin(); a != log_.rend(); ++a)
      *a->place = a->before;
    checkpoint_.restore();
  }
  const gcvec<Assignment> &log() const { return log_; }

private:
  Checkpoint checkpoint_; // first: taken before the attempt's block is pushed
  size_t nloops_, nblocks_, nundo_;
  gcvec<Assignment> log_;
};

bool evaluate_as_loop(Value f, Value *slots, long n, Value *out, bool from_known);
bool watch_known_call(Value f, Value *slots, long n, Value *out);
bool count_known_call(Closure *c);

} // namespace

// Is a variable of `frame` (null: a global) kept from one iteration to the
// next of the loop being evaluated for run time, in the same function?
bool grows_in_loop(Frame *frame) {
  if (g_build->loops.empty()) return false;
  const ActiveLoop *loop = g_build->loops.back();
  return !loop->watching && loop->depth == g_build->open.size() &&
         (!frame || frame->serial <= loop->serial);
}

bool hook_call_closure(Value f, Value *slots, long n, Value *out) {
  Closure *c = f.as<Closure>();
  for (auto l = g_build->loops.rbegin(); l != g_build->loops.rend(); ++l)
    if ((*l)->closure == c) {
      if ((*l)->watching) throw BecomeLoop{c};
      *out = record_continue(**l, slots, n);
      return true;
    }
  if (!c->lambda->name) return false;
  bool any = false;
  for (long i = 0; i < n; ++i)
    any = any || contains_dynamic(slots[i]) || is_dynamic_boolean(slots[i]);
  if (!any) {
    if (count_known_call(c)) return false; // an iteration of a watched call
    return watch_known_call(f, slots, n, out);
  }

  // First as an ordinary call, watched: most calls never call themselves.
  {
    std::vector<RStmt> body;
    Value v;
    gcvec<Assignment> assigned;
    bool recursive = false;
    {
      ActiveLoop watch;
      watch.closure = c;
      watch.watching = true;
      LoopAttempt attempt(&watch, &body);
      gcvec<Value> args(slots, slots + n);
      try {
        v = apply_procedure(f, args.data(), static_cast<int>(n));
        assigned = attempt.log();
      } catch (const BecomeLoop &b) {
        attempt.roll_back();
        if (b.closure != c) throw;
        recursive = true;
      }
    }
    if (!recursive) {
      if (!g_build->undo.empty()) // an enclosing alternative undoes these assignments too
        for (const Assignment &a : assigned)
          log_assignment(a);
      for (RStmt &x : body)
        current_block().push_back(std::move(x));
      *out = v;
      return true;
    }
  }

  return evaluate_as_loop(f, slots, n, out, false);
}

namespace {

// The call of closure f with arguments slots as a loop (see above);
// from_known: all of them are known (see StaticWatch). False if it is not one.
bool evaluate_as_loop(Value f, Value *slots, long n, Value *out, bool from_known) {
  Closure *c = f.as<Closure>();
  ActiveLoop loop;
  loop.closure = c;
  loop.from_known = from_known;
  for (long i = 0; i < n; ++i) {
    LoopParam p;
    p.shape = slots[i];
    if (contains_dynamic(slots[i]) || is_dynamic_boolean(slots[i])) {
      gcvec<Value> leaves;
      if (!result_leaves(slots[i], leaves)) return false; // a procedure, ...: not a loop
      make_variable(p, slots[i]);
    }
    loop.params.push_back(std::move(p));
  }
  for (;;) {
    std::vector<RStmt> body;
    Value v;
    bool retry = false;
    gcvec<Value> saved_lists;
    for (Value *place : list_cell_places())
      saved_lists.push_back(*place);
    gcvec<Assignment> assigned;
    {
      LoopAttempt attempt(&loop, &body);
      loop.continued = false;
      loop.depth = g_build->open.size();
      loop.serial = g_frame_serial;
      read_list_cells(); // their lengths as each iteration begins
      gcvec<Value> args(slots, slots + n);
      for (long i = 0; i < n; ++i) {
        LoopParam &p = loop.params[i];
        if (!p.variable) continue;
        gcvec<Value> leaves;
        p.vars.clear();
        for (RType t : p.types) {
          leaves.push_back(new_var(t));
          p.vars.push_back(var_of(leaves.back()));
        }
        const Value *lp = leaves.data();
        args[i] = result_like(p.shape, lp);
      }
      try {
        v = apply_procedure(f, args.data(), static_cast<int>(n));
        gcvec<Value> leaves;
        if (loop.continued && !result_leaves(v, leaves)) throw LoopAbort{};
        for (const Assignment &a : attempt.log())
          if (loop.continued && cell_of(a.place) < 0 &&
              !(list_cell_of(a.place) >= 0 && is_whole_list(a.after)))
            throw LoopAbort{};
        assigned = attempt.log();
      } catch (const LoopRetry &) {
        attempt.roll_back();
        retry = true;
      } catch (const LoopAbort &) {
        attempt.roll_back();
        return false;
      } catch (const Error &) {
        attempt.roll_back();
        return false; // evaluated again as usual: the error, if real, comes again
      }
    } // the stacks are the caller's again
    for (size_t i = 0; i < saved_lists.size(); ++i)
      *list_cell_places()[i] = saved_lists[i]; // read again after the loop if it added to them
    if (retry) {
      init_list_cells(); // lists the body conses onto start before the loop
      continue;
    }
    if (!g_build->undo.empty()) // an enclosing alternative undoes these assignments too
      for (const Assignment &a : assigned)
        log_assignment(a);
    bool calls = block_calls(body);
    RStmt s{loop.continued ? RKind::Loop : RKind::If};
    for (const LoopParam &p : loop.params) {
      if (!p.variable) continue;
      gcvec<Value> inits;
      result_leaves(p.shape, inits);
      for (size_t k = 0; k < inits.size(); ++k) {
        s.outs.push_back(p.vars[k]);
        s.args.push_back(expr_of(inits[k], "loop"));
      }
    }
    if (!loop.continued) {
      // An ordinary call: its variables get their values, its statements
      // follow in place.
      for (size_t i = 0; i < s.outs.size(); ++i) {
        RStmt l{RKind::Let};
        l.var = s.outs[i];
        l.args = {s.args[i]};
        emit(std::move(l));
      }
      for (RStmt &x : body)
        current_block().push_back(std::move(x));
      if (calls) read_cells();
      *out = v;
      return true;
    }
    gcvec<Value> leaves, results;
    result_leaves(v, leaves);
    RStmt brk{RKind::Break};
    for (Value leaf : leaves) {
      results.push_back(new_var(scalar_type(leaf)));
      brk.results.push_back(var_of(results.back()));
      brk.args.push_back(expr_of(leaf, "loop"));
    }
    s.results = brk.results;
    body.push_back(std::move(brk));
    s.then_body = std::move(body);
    current_block().push_back(std::move(s));
    if (calls) read_cells();
    const Value *p = results.data();
    *out = result_like(v, p);
    return true;
  }
}

} // namespace

// ---- generalization: loops left for run time past the unroll limits ----------------------
//
// Evaluating a loop at compile time unrolls it: each iteration's run-time
// work (a state advancer's call, a plot mark) is a statement of its own, so
// the residual program grows with the iteration count. Past two named
// limits (limits.hpp; flags of sicm build) the partial evaluator
// generalizes instead, leaving the loop for run time (as Chez Scheme's cp0
// residualizes past its effort limits). Hitting a limit is never an error:
// if the generalized loop cannot be compiled (its body needs a value it now
// gets only at run time), the loop is unrolled as before.
//
//   kMaxUnrolledElements    map or for-each over lists known at compile time
//                           that are longer, of inexact numbers (or pairs or
//                           structures of them, all of one shape), whose
//                           procedure does run-time work on the first
//                           elements (an evaluation that is then forgotten
//                           records statements other than output text, or
//                           gives a run-time value): the lists become
//                           constant tables (RTable) copied into run-time
//                           lists, and the map a C loop over them
//                           (map_over_lists). Exact numbers stay known: they
//                           print differently from doubles.
//   kMaxUnrolledIterations  see "loops that start from known values" below.

namespace {

// Undoes what evaluating something tentatively made: the statements go to
// `block`, assignments to older variables are logged, and roll_back undoes
// them and forgets the rest (a Checkpoint).
class Trial {
public:
  explicit Trial(std::vector<RStmt> *block)
      : nblocks_(g_build->blocks.size()), nundo_(g_build->undo.size()) {
    g_build->blocks.push_back(block);
    g_build->undo.push_back(&log_);
    g_build->undo_serials.push_back(g_frame_serial);
  }
  ~Trial() {
    g_build->blocks.resize(nblocks_);
    g_build->undo.resize(nundo_);
    g_build->undo_serials.resize(nundo_);
  }
  Trial(const Trial &) = delete;
  Trial &operator=(const Trial &) = delete;

  void roll_back() {
    for (auto a = log_.rbegin(); a != log_.rend(); ++a)
      *a->place = a->before;
    checkpoint_.restore();
  }
  size_t nfunctions() const { return checkpoint_.nfunctions(); }
  const gcvec<Assignment> &log() const { return log_; }

private:
  Checkpoint checkpoint_; // first: taken before the trial's block is pushed
  size_t nblocks_, nundo_;
  gcvec<Assignment> log_;
};

// Keep what a Trial made, once it has ended: its statements follow in the
// current block, and an enclosing alternative or loop undoes its
// assignments too.
void keep_trial(std::vector<RStmt> &block, const gcvec<Assignment> &assigned) {
  if (!g_build->undo.empty())
    for (const Assignment &a : assigned)
      log_assignment(a);
  std::vector<RStmt> &to = current_block();
  for (RStmt &x : block) {
    if (x.kind == RKind::Text && !to.empty() && to.back().kind == RKind::Text)
      to.back().text += x.text;
    else
      to.push_back(std::move(x));
  }
}

} // namespace

// Does applying f to args record run-time work (statements other than
// output text, or a run-time result)? Evaluated and forgotten; false if it
// fails (it fails again, where the caller evaluates it for real).
bool does_run_time_work(Value f, gcvec<Value> args) {
  std::vector<RStmt> block;
  bool work = false;
  Trial trial(&block);
  try {
    Value r = apply_procedure(f, args.data(), static_cast<int>(args.size()));
    work = contains_dynamic(r) || g_build->program.functions.size() > trial.nfunctions();
    for (const RStmt &s : block)
      work = work || s.kind != RKind::Text;
  } catch (const Error &) {
    work = false;
  } catch (...) {
    trial.roll_back();
    throw;
  }
  trial.roll_back();
  return work;
}

bool tentatively(const std::function<bool()> &body) {
  std::vector<RStmt> block;
  gcvec<Assignment> assigned;
  {
    Trial trial(&block);
    try {
      if (!body()) {
        trial.roll_back();
        return false;
      }
      assigned = trial.log();
    } catch (const Error &) {
      trial.roll_back();
      return false;
    } catch (...) {
      trial.roll_back();
      throw;
    }
  }
  keep_trial(block, assigned);
  return true;
}

namespace {

// An element a constant table can hold: an inexact number, or a pair or
// up/down structure of such elements (a list of them ends in ()).
bool inexact_tree(Value v, bool nil_ok) {
  if (v.is(Tag::Flonum)) return true;
  if (v.is(Tag::Nil)) return nil_ok;
  if (is_pair(v)) return inexact_tree(car(v), false) && inexact_tree(cdr(v), true);
  if (is_structure(v)) {
    Structure *st = as_structure(v);
    for (size_t i = 0; i < st->len; ++i)
      if (!inexact_tree(st->items[i], false)) return false;
    return st->len > 0;
  }
  return false;
}

// The first `count` elements of a list known at compile time as a table:
// their leaves in order, and the first element (the shape of all). False if
// they are not all inexact and of one shape.
bool table_of(Value list, long count, Value *shape, std::vector<double> &data) {
  Value x = list;
  for (long k = 0; k < count; ++k, x = cdr(x)) {
    Value e = car(x);
    if (!inexact_tree(e, false)) return false;
    if (k == 0) *shape = e;
    if (k > 0 && !same_shape(e, *shape)) return false;
    gcvec<Value> leaves;
    element_leaves(e, leaves);
    for (Value leaf : leaves)
      data.push_back(leaf.d);
  }
  return true;
}

// A run-time list holding a table's elements (shaped like `shape`), copied
// in where this statement runs.
Value constant_list(Value shape, std::vector<double> data, long count, const char *who) {
  gcvec<Value> leaves;
  element_leaves(shape, leaves);
  int width = static_cast<int>(leaves.size());
  int table = -1;
  for (size_t t = 0; t < g_build->program.tables.size(); ++t)
    if (g_build->program.tables[t].width == width && g_build->program.tables[t].data == data)
      table = static_cast<int>(t);
  if (table < 0) {
    table = static_cast<int>(g_build->program.tables.size());
    g_build->program.tables.push_back(RTable{width, std::move(data)});
  }
  int id = static_cast<int>(g_build->program.lists.size());
  g_build->program.lists.push_back(RList{width, std::string("constant list for ") + who});
  g_build->list_shapes.push_back(element_shape(shape));
  g_build->list_types.push_back(std::vector<RType>(leaves.size(), RType::Real));
  RStmt s{RKind::ListConst};
  s.list = id;
  s.leaf = table;
  emit(std::move(s));
  return make_rtlist(id, true, false, Value::fixnum(0), Value::fixnum(count));
}

} // namespace

// (map f l ...) or (for-each f l ...) over lists known at compile time, as
// a C loop over constant tables when the lists are longer than
// --max-unrolled-elements and f does run-time work (see above); false to
// unroll it.
bool map_over_static_lists(Value *a, int n, bool collect, const char *who, Value *out) {
  uint64_t limit = current_limits().max_unrolled_elements;
  if (n < 2 || !is_procedure(a[0]) || limit == kUnlimited) return false;
  long count = -1;
  for (int k = 1; k < n; ++k) {
    long len = list_length(a[k]);
    if (len < 0) return false;
    count = count < 0 ? len : std::min(count, len);
  }
  if (count <= static_cast<long>(limit)) return false;
  gcvec<Value> shapes, firsts;
  std::vector<std::vector<double>> tables;
  for (int k = 1; k < n; ++k) {
    Value shape;
    tables.emplace_back();
    if (!table_of(a[k], count, &shape, tables.back())) return false;
    shapes.push_back(shape);
    firsts.push_back(car(a[k]));
  }
  if (!does_run_time_work(a[0], firsts)) return false;
  // If it cannot be compiled as a loop it is unrolled: the error, if real, comes again.
  return tentatively([&] {
    gcvec<Value> views;
    for (size_t k = 0; k < shapes.size(); ++k)
      views.push_back(constant_list(shapes[k], std::move(tables[k]), count, who));
    *out = map_over_lists(a[0], views.data(), n - 1, collect, who);
    return true;
  });
}

// ---- loops that start from known values -------------------------------------------------
//
// A named procedure called with known arguments runs at compile time, as in
// sicm run: a loop of 500 iterations that plots a point in each leaves 500
// plot statements. The outermost such call of a closure is watched (a
// Trial): if the closure calls itself with known arguments more than
// --max-unrolled-iterations (kMaxUnrolledIterations) times, and its calls
// recorded run-time work (statements other than output text) within the
// last half of that many calls, what the call did is forgotten and it is
// evaluated again as a loop from the first call (evaluate_as_loop with
// from_known): the known numbers that change from call to call become loop
// variables. A loop that computes only known values runs at compile time
// however long it is. If the call cannot be a loop (its recursive call is not
// in tail position, a count is used where a known value is needed, ...) it
// is evaluated as usual, unrolled, and no closure of its lambda is watched
// again.

struct StaticWatch {
  Closure *closure;
  uint64_t calls = 0;     // calls of the closure with known arguments while watched
  uint64_t work_mark = 0; // g_build->work when the current window of calls began
  int branch_depth = 0;   // g_build->branch_depth when the watch began
};

namespace {

// A watched loop whose known calls nest this deep under tests on run-time
// values is left for run time at once: each iteration's test is one more
// level of alternatives, so unrolling it would end at kMaxBranchDepth (a
// Poincare-section refinement that halves its step 50 times, keeping its
// known state in the branch that halves and a run-time one in the other).
constexpr int kMaxWatchedBranchDepth = kMaxBranchDepth / 2;
struct UnrollLimit { // thrown to the watched call of `closure`
  Closure *closure;
};

// A call of c with known arguments: if c is watched, count it (and throw
// UnrollLimit past the limit) and say so.
bool count_known_call(Closure *c) {
  for (auto w = g_build->watches.rbegin(); w != g_build->watches.rend(); ++w) {
    StaticWatch &watch = **w;
    if (watch.closure != c) continue;
    if (g_build->branch_depth - watch.branch_depth >= kMaxWatchedBranchDepth) throw UnrollLimit{c};
    uint64_t limit = current_limits().max_unrolled_iterations;
    uint64_t window = std::max<uint64_t>(1, limit / 2);
    if (++watch.calls % window == 0) {
      if (watch.calls >= limit && g_build->work > watch.work_mark) throw UnrollLimit{c};
      watch.work_mark = g_build->work;
    }
    return true;
  }
  return false;
}

bool watch_known_call(Value f, Value *slots, long n, Value *out) {
  Closure *c = f.as<Closure>();
  if (current_limits().max_unrolled_iterations == kUnlimited ||
      g_build->unrolled_lambdas.count(c->lambda))
    return false;
  StaticWatch watch{c, 0, g_build->work, g_build->branch_depth};
  std::vector<RStmt> block;
  Value v;
  gcvec<Assignment> assigned;
  bool limit_hit = false;
  {
    Trial trial(&block);
    g_build->watches.push_back(&watch);
    struct Pop {
      ~Pop() { g_build->watches.pop_back(); }
    } pop;
    gcvec<Value> args(slots, slots + n);
    try {
      v = apply_procedure(f, args.data(), static_cast<int>(n));
      assigned = trial.log();
    } catch (const UnrollLimit &u) {
      trial.roll_back();
      if (u.closure != c) throw;
      limit_hit = true;
    } catch (...) {
      trial.roll_back();
      throw;
    }
  }
  if (!limit_hit) {
    keep_trial(block, assigned);
    *out = v;
    return true;
  }
  if (evaluate_as_loop(f, slots, n, out, true)) return true;
  g_build->unrolled_lambdas.insert(c->lambda);
  return false;
}

} // namespace

} // namespace sicm::build
