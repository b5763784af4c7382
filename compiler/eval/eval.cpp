// The evaluator: walks analyzed Nodes with proper tail calls.
//
// eval() is a loop: forms in tail position (the chosen branch of an if, the
// last form of a body, the body of a called closure) replace the current
// node and environment instead of recursing, so a tail call costs no C++
// stack. Only the evaluation of sub-expressions (operands, tests, non-final
// body forms) recurses, and every recursion passes the stack guard, which
// turns runaway recursion into MIT's "Aborting!: maximum recursion depth
// exceeded" instead of a segfault; the recursion depth limit sets where the
// guard stands.
// Every iteration of the loop is one step for the step limit, whose counter
// also notices Ctrl-C in the REPL (base/limits.hpp).
#include <string>

#include "base/limits.hpp"
#include "base/primitive.hpp"
#include "eval/core.hpp"
#include "eval/effect_guard.hpp"
#include "eval/procedure.hpp"

namespace sicm {

namespace {
char *g_stack_limit = nullptr;
SrcLoc g_call_loc;
const void *g_apply_primitive = nullptr; // the `apply` primitive, called in tail position
uint32_t g_first_user_file = UINT32_MAX; // sources from here on are the user's, not the library's

// Evaluate operands into a buffer; small calls use the C++ stack.
constexpr int kSmallArgs = 8;

std::string plural(long n, const char *word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

[[noreturn]] void arity_error(Value proc, long given, long min, long max, SrcLoc loc) {
  std::string requires_;
  if (max == min)
    requires_ = "exactly " + plural(min, "argument");
  else if (max < 0)
    requires_ = "at least " + plural(min, "argument");
  else
    requires_ = "between " + std::to_string(min) + " and " + plural(max, "argument");
  runtime_error(loc, "The procedure " + written(proc) + " has been called with " +
                         plural(given, "argument") + "; it requires " + requires_ + ".");
}

[[noreturn]] void not_applicable(Value f, SrcLoc loc) {
  runtime_error(loc, "The object " + written(f) + " is not applicable.");
}

// Bind evaluated arguments into a new frame for closure c.
Frame *bind_arguments(Value proc, Closure *c, Value *args, long nargs, SrcLoc loc) {
  Lambda *lam = c->lambda;
  long req = lam->nrequired, opt = lam->noptional;
  if (nargs < req || (!lam->rest && nargs > req + opt))
    arity_error(proc, nargs, req, lam->rest ? -1 : req + opt, loc);
  Frame *f = make_frame(c->env, lam->frame_size);
  long fixed = req + opt;
  long i = 0;
  for (; i < nargs && i < fixed; ++i)
    f->slots[i] = args[i];
  for (; i < fixed; ++i)
    f->slots[i] = Value::default_object();
  if (lam->rest) {
    Value rest = Value::nil();
    for (long j = nargs; j-- > fixed;)
      rest = cons(args[j], rest);
    f->slots[fixed] = rest;
  }
  return f;
}

Value lookup_local(Node *n, Frame *env) {
  Frame *f = env;
  for (uint16_t d = n->depth; d > 0; --d)
    f = f->parent;
  Value v = f->slots[n->index];
  if (v.is(Tag::Unassigned)) runtime_error(n->loc, "Unassigned variable: " + symbol_name(n->value));
  return v;
}

Value lookup_global(Node *n) {
  Symbol *s = n->value.symbol();
  if (!s->bound) runtime_error(n->loc, "Unbound variable: " + s->name);
  if (s->global.is(Tag::Unassigned)) runtime_error(n->loc, "Unassigned variable: " + s->name);
  return s->global;
}

// Store into the variable that reference node `ref` names.
void assign(Node *ref, Frame *env, Value v) {
  if (ref->kind == NodeKind::LocalRef) {
    Frame *f = env;
    for (uint16_t d = ref->depth; d > 0; --d)
      f = f->parent;
    f->slots[ref->index] = v;
  } else {
    Symbol *s = ref->value.symbol();
    if (!s->bound) runtime_error(ref->loc, "Unbound variable: " + s->name);
    s->global = v;
  }
}

Value eval_fluid_let(Node *n, Frame *env) {
  uint32_t count = (n->nkids - 1) / 2;
  gcvec<Value> saved(count), fresh(count);
  for (uint32_t i = 0; i < count; ++i)
    fresh[i] = eval(n->kids[count + i], env);
  for (uint32_t i = 0; i < count; ++i) {
    saved[i] = n->kids[i]->kind == NodeKind::LocalRef ? lookup_local(n->kids[i], env)
                                                      : lookup_global(n->kids[i]);
    assign(n->kids[i], env, fresh[i]);
  }
  try {
    Value result = eval(n->kids[2 * count], env);
    for (uint32_t i = 0; i < count; ++i)
      assign(n->kids[i], env, saved[i]);
    return result;
  } catch (...) {
    for (uint32_t i = 0; i < count; ++i)
      assign(n->kids[i], env, saved[i]);
    throw;
  }
}

Value call_primitive(Value f, Value *args, long nargs, SrcLoc loc) {
  Primitive *p = f.as<Primitive>();
  if (nargs < p->min_args || (p->max_args >= 0 && nargs > p->max_args))
    arity_error(f, nargs, p->min_args, p->max_args, loc);
  g_call_loc = loc;
  return p->fn(args, static_cast<int>(nargs));
}

// A structure of procedures applies componentwise, as in scmutils:
// ((up sin cos) t) is (up (sin t) (cos t)).
Value apply_structure(Value s, Value *args, int nargs) {
  Structure *st = s.as<Structure>();
  Structure *out = gc_new<Structure>(Structure{st->up, nullptr, st->len});
  out->items = static_cast<Value *>(GC_MALLOC(sizeof(Value) * (st->len ? st->len : 1)));
  for (size_t i = 0; i < st->len; ++i)
    out->items[i] = apply_procedure(st->items[i], args, nargs);
  return Value::object(Tag::Structure, out);
}

// A matrix of procedures applies entry by entry as well (scmutils'
// matrices are applicable as its structures are): ((Euler->M angles) t)
// for angles an up of functions of time.
Value apply_matrix(Value m, Value *args, int nargs) {
  Matrix *mt = m.as<Matrix>();
  size_t n = mt->rows * mt->cols;
  Matrix *out = gc_new<Matrix>(Matrix{mt->rows, mt->cols, nullptr});
  out->items = static_cast<Value *>(GC_MALLOC(sizeof(Value) * (n ? n : 1)));
  for (size_t k = 0; k < n; ++k)
    out->items[k] = apply_procedure(mt->items[k], args, nargs);
  return Value::object(Tag::Matrix, out);
}

} // namespace

Frame *make_frame(Frame *parent, uint32_t size) {
  size_t bytes = sizeof(Frame) + sizeof(Value) * (size ? size - 1 : 0);
  Frame *f = static_cast<Frame *>(GC_MALLOC(bytes));
  if (!f) throw std::bad_alloc();
  f->parent = parent;
  f->size = size;
  f->serial = ++g_frame_serial;
  for (uint32_t i = 0; i < size; ++i)
    f->slots[i].tag = Tag::Unassigned;
  return f;
}

void set_first_user_file(uint32_t file) {
  g_first_user_file = file;
}

bool is_library_loc(SrcLoc loc) {
  return loc.known() && loc.file < g_first_user_file;
}

SrcLoc user_call_loc() {
  SrcLoc call = current_call_loc();
  return call.known() && !is_library_loc(call) ? call : current_toplevel_loc();
}

void register_apply_primitive(Value apply) {
  g_apply_primitive = apply.p;
}

SrcLoc current_call_loc() {
  return g_call_loc;
}

void reset_call_loc(SrcLoc where) {
  g_call_loc = where;
}

void set_stack_limit(char *stack_base, size_t usable_bytes) {
  g_stack_limit = stack_base - usable_bytes;
}

void check_stack(SrcLoc where) {
  char probe;
  if (g_stack_limit && &probe < g_stack_limit) [[unlikely]]
    stack_exhausted(where.known() ? where : g_call_loc);
}

Value apply_procedure(Value proc, Value *args, int nargs) {
  if (proc.is(Tag::Primitive)) return call_primitive(proc, args, nargs, g_call_loc);
  if (!proc.is(Tag::Closure)) {
    if (is_continuation(proc)) throw_to_continuation(proc, args, nargs);
    if (is_applicable_opaque(proc)) {
      Opaque *o = proc.as<Opaque>();
      return o->kind->apply(o->obj, args, nargs);
    }
    if (proc.is(Tag::Structure)) return apply_structure(proc, args, nargs);
    if (proc.is(Tag::Matrix)) return apply_matrix(proc, args, nargs);
    not_applicable(proc, g_call_loc);
  }
  Closure *c = proc.as<Closure>();
  Frame *f = bind_arguments(proc, c, args, nargs, g_call_loc);
  return eval(c->lambda->body, f);
}

// The slower call paths live in their own functions, so that eval's own
// stack frame stays small: its size is what deep recursion pays per level.
// Evaluate the operands of call node n into small (or big, when they do not
// fit); returns where they are.
Value *evaluate_operands(Node *n, Frame *env, Value (&small)[kSmallArgs], gcvec<Value> &big) {
  long nargs = n->nkids - 1;
  Value *args = small;
  if (nargs > kSmallArgs) {
    big.resize(nargs);
    args = big.data();
  }
  for (long i = 0; i < nargs; ++i)
    args[i] = eval(n->kids[i + 1], env);
  return args;
}

[[gnu::noinline]] Frame *bind_evaluated(Value f, Closure *c, Node *n, Frame *env) {
  Value small[kSmallArgs];
  gcvec<Value> big;
  Value *args = evaluate_operands(n, env, small, big);
  return bind_arguments(f, c, args, n->nkids - 1, n->loc);
}

[[gnu::noinline]] Value call_evaluated(Value f, Node *n, Frame *env) {
  long nargs = n->nkids - 1;
  Value small[kSmallArgs];
  gcvec<Value> big;
  Value *args = evaluate_operands(n, env, small, big);
  if (is_applicable_opaque(f)) {
    g_call_loc = n->loc;
    Opaque *o = f.as<Opaque>();
    return o->kind->apply(o->obj, args, static_cast<int>(nargs));
  }
  if (f.is(Tag::Structure)) {
    g_call_loc = n->loc;
    return apply_structure(f, args, static_cast<int>(nargs));
  }
  if (f.is(Tag::Matrix)) {
    g_call_loc = n->loc;
    return apply_matrix(f, args, static_cast<int>(nargs));
  }
  if (!f.is(Tag::Primitive)) throw_to_continuation(f, args, static_cast<int>(nargs));
  return call_primitive(f, args, nargs, n->loc);
}

// (apply f a ... list) must be a proper tail call: when f is a closure,
// eval continues with its body instead of recursing.
struct TailApply {
  Value result;         // when the call is complete
  Node *body = nullptr; // else: continue with body in env
  Frame *env = nullptr;
};

[[gnu::noinline]] TailApply eval_apply(Value apply, Node *n, Frame *env) {
  long nargs = n->nkids - 1;
  if (nargs < 1) arity_error(apply, nargs, 1, -1, n->loc);
  gcvec<Value> args;
  Value target = eval(n->kids[1], env);
  for (long i = 2; i < nargs; ++i)
    args.push_back(eval(n->kids[i], env));
  if (nargs > 1) {
    Value last = eval(n->kids[nargs], env);
    if (list_length(last) < 0) {
      g_call_loc = n->loc;
      TailApply t;
      args.push_back(last);
      if (g_dynamic_branch_hooks &&
          g_dynamic_branch_hooks->apply_to_other(target, args.data(),
                                                 static_cast<long>(args.size()), &t.result))
        return t;
      wrong_type(last, static_cast<int>(nargs), "apply");
    }
    for (; is_pair(last); last = cdr(last))
      args.push_back(car(last));
  }
  TailApply t;
  if (target.is(Tag::Closure)) {
    Closure *c = target.as<Closure>();
    t.env = bind_arguments(target, c, args.data(), static_cast<long>(args.size()), n->loc);
    t.body = c->lambda->body;
    return t;
  }
  g_call_loc = n->loc;
  t.result = apply_procedure(target, args.data(), static_cast<int>(args.size()));
  return t;
}

const DynamicBranchHooks *g_dynamic_branch_hooks = nullptr;
uint32_t g_frame_serial = 0;

Value eval_logic_from(Node *n, uint32_t from, Frame *env) {
  bool is_and = n->kind == NodeKind::And;
  for (uint32_t i = from; i < n->nkids; ++i) {
    Value v = eval(n->kids[i], env);
    if (i + 1 == n->nkids) return v;
    if (g_dynamic_branch_hooks && g_dynamic_branch_hooks->dynamic_test(v))
      return g_dynamic_branch_hooks->logic(v, n, i + 1, is_and, env);
    if (is_and ? v.is_false() : v.truthy()) return v;
  }
  return Value::boolean(is_and);
}

Value eval(Node *n, Frame *env) {
  check_stack(n->loc);
  for (;;) {
    count_step(n->loc);
    switch (n->kind) {
    case NodeKind::Const: return n->value;
    case NodeKind::LocalRef: return lookup_local(n, env);
    case NodeKind::GlobalRef: return lookup_global(n);
    case NodeKind::SetLocal: {
      Value v = eval(n->kids[0], env);
      Frame *f = env;
      for (uint16_t d = n->depth; d > 0; --d)
        f = f->parent;
      refuse_set_local(f->serial, n->loc);
      if (g_dynamic_branch_hooks) v = g_dynamic_branch_hooks->set_local(f, n->index, v, n->loc);
      f->slots[n->index] = v;
      return Value::unspecified();
    }
    case NodeKind::SetGlobal: {
      Value v = eval(n->kids[0], env);
      Symbol *s = n->value.symbol();
      if (!s->bound) runtime_error(n->loc, "Unbound variable: " + s->name);
      refuse_set_global(s, n->loc);
      if (g_dynamic_branch_hooks) v = g_dynamic_branch_hooks->set_global(s, v, n->loc);
      s->global = v;
      return Value::unspecified();
    }
    case NodeKind::DefineGlobal: {
      Value v = eval(n->kids[0], env);
      Symbol *s = n->value.symbol();
      s->global = v;
      s->bound = true;
      return n->value;
    }
    case NodeKind::If: {
      Value test = eval(n->kids[0], env);
      if (g_dynamic_branch_hooks && g_dynamic_branch_hooks->dynamic_test(test))
        return g_dynamic_branch_hooks->branch(test, n->kids[1], n->nkids > 2 ? n->kids[2] : nullptr,
                                              env);
      if (test.truthy()) {
        n = n->kids[1];
      } else if (n->nkids > 2) {
        n = n->kids[2];
      } else {
        return Value::unspecified();
      }
      continue;
    }
    case NodeKind::Lambda:
      return Value::object(Tag::Closure, gc_new<Closure>(Closure{n->lambda, env}));
    case NodeKind::Seq: {
      for (uint32_t i = 0; i + 1 < n->nkids; ++i)
        eval(n->kids[i], env);
      n = n->kids[n->nkids - 1];
      continue;
    }
    case NodeKind::And:
    case NodeKind::Or: {
      bool is_and = n->kind == NodeKind::And;
      uint32_t i = 0;
      for (; i + 1 < n->nkids; ++i) {
        Value v = eval(n->kids[i], env);
        if (g_dynamic_branch_hooks && g_dynamic_branch_hooks->dynamic_test(v))
          return g_dynamic_branch_hooks->logic(v, n, i + 1, is_and, env);
        if (is_and ? v.is_false() : v.truthy()) return v;
      }
      n = n->kids[i];
      continue;
    }
    case NodeKind::Let: {
      Frame *f = make_frame(env, n->index);
      uint32_t nb = n->nkids - 1;
      for (uint32_t i = 0; i < nb; ++i)
        f->slots[i] = eval(n->kids[i], env);
      env = f;
      n = n->kids[nb];
      continue;
    }
    case NodeKind::Letrec: {
      Frame *f = make_frame(env, n->index);
      uint32_t nb = n->nkids - 1;
      for (uint32_t i = 0; i < nb; ++i)
        f->slots[i] = eval(n->kids[i], f);
      env = f;
      n = n->kids[nb];
      continue;
    }
    case NodeKind::Delay: {
      Promise *p = gc_new<Promise>(Promise{false, Value(), n->kids[0], env});
      return Value::object(Tag::Promise, p);
    }
    case NodeKind::FluidLet: return eval_fluid_let(n, env);
    case NodeKind::Call: {
      Value f = eval(n->kids[0], env);
      long nargs = n->nkids - 1;
      if (f.is(Tag::Closure)) {
        Closure *c = f.as<Closure>();
        Lambda *lam = c->lambda;
        if (!lam->rest && lam->noptional == 0 && nargs == lam->nrequired) {
          // The common case: evaluate operands straight into the new frame.
          Frame *fr = make_frame(c->env, lam->frame_size);
          for (long i = 0; i < nargs; ++i)
            fr->slots[i] = eval(n->kids[i + 1], env);
          if (g_dynamic_branch_hooks) {
            Value result;
            if (g_dynamic_branch_hooks->call_closure(f, fr->slots, nargs, &result)) return result;
          }
          env = fr;
        } else {
          env = bind_evaluated(f, c, n, env);
        }
        n = lam->body;
        continue;
      }
      if (!f.is(Tag::Primitive) && !is_continuation(f) && !is_applicable_opaque(f) &&
          !f.is(Tag::Structure) && !f.is(Tag::Matrix))
        not_applicable(f, n->loc);
      if (f.p == g_apply_primitive) {
        TailApply t = eval_apply(f, n, env);
        if (!t.body) return t.result;
        n = t.body;
        env = t.env;
        continue;
      }
      return call_evaluated(f, n, env);
    }
    }
    internal_failure(__FILE__, __LINE__, "unknown node kind");
  }
}

// Force a promise: evaluate its expression once and remember the value.
Value force_promise(Value v) {
  if (!v.is(Tag::Promise)) return v;
  Promise *p = v.as<Promise>();
  if (!p->forced) {
    if (g_dynamic_branch_hooks && g_dynamic_branch_hooks->forcing)
      g_dynamic_branch_hooks->forcing(v);
    Value r = eval(p->expr, p->env);
    if (!p->forced) { // not forced re-entrantly meanwhile
      p->forced = true;
      p->value = r;
      p->expr = nullptr;
      p->env = nullptr;
    }
  }
  return p->value;
}

} // namespace sicm
